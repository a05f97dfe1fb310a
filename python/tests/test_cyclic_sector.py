"""Per-blade recovery of a cyclic sector's solve: the blade amplitudes and any blade's time
series from the sector's solution, against the full disk solved whole under the same
engine order (its state evaluated at the same times with numpy, independently of the
package's recovery)."""

import numpy as np
import pytest

import ssn
from conftest import SCENES, assert_same_document

SECTOR = SCENES / "bladed_disk_sector.toml"
BLADES = 8
HARMONICS = 5
#: The shipped sector at 8 sectors, near nodal diameter 3's resonance, where every casing contact closes on
#: part of the period; 64 samples, a multiple of N: the sector poses the full disk's
#: equations.
SECTOR_VALUES = {
    "cyclic.sectors": BLADES,
    "forcing.omega": 0.9,
    "solver.time_samples": 64,
    "solver.tolerance": 1e-13,
}


def full_disk_scene():
    """The whole tuned disk of 8 blades with the casing on every pad, the same damping,
    load, frequency and solver, the load of blade s delayed by 2 pi EO s / N."""
    return ssn.Scene.from_toml(
        f"""
[bladed_disk]
blades = {BLADES}

[contact]
gap = 1.0

[damping]
alpha = 0.0
beta = 0.03236067977499790

[forcing]
amplitude = 0.06
omega = 0.9
engine_order = 3

[solver]
method = "ssn-hb"
harmonics = {HARMONICS}
time_samples = 64
c = 5.0
tolerance = 1e-13
"""
    )


def tip_series(state, dofs, dof, phases):
    """One dof's displacement at the phases omega t from harmonic-major coefficients."""
    u = np.full_like(phases, state[dof])
    for k in range(1, HARMONICS + 1):
        a, b = state[(2 * k - 1) * dofs + dof], state[2 * k * dofs + dof]
        u += a * np.cos(k * phases) + b * np.sin(k * phases)
    return u


def test_a_sectors_blades_are_the_full_disks_blade_tips(cli):
    sector = ssn.solve(ssn.Scene.from_file(SECTOR).with_values(SECTOR_VALUES))
    full = ssn.solve(full_disk_scene())
    assert sector.converged and full.converged
    assert all(0.0 < c["contact_fraction"] < 1.0 for c in full.contacts)
    # The document is the command line's, blade amplitudes included.
    args = [a for k, v in SECTOR_VALUES.items() for a in ("--set", f"{k}={v}")]
    assert_same_document(sector.to_dict(), cli("solve", SECTOR, *args))
    amplitudes = sector.blade_amplitudes
    assert amplitudes.shape == (BLADES,)
    assert np.array_equal(amplitudes, np.array(sector.to_dict()["blade_amplitudes"]))
    # Blade 0 is the sector itself: its series is the observed displacement.
    scale = np.abs(sector.displacement).max()
    assert np.abs(sector.blade_displacement(0) - sector.displacement).max() < 1e-12 * scale
    phases = sector.omega * sector.times
    dofs = 3 * BLADES
    for blade in range(BLADES):
        # The full disk's blade tip (dof 3 j + 1) from its own state: both runs converged
        # below 1e-13 on the same discrete equations (the library's tests find 1e-13).
        reference = tip_series(full.state, dofs, 3 * blade + 1, phases)
        recovered = sector.blade_displacement(blade)
        assert np.abs(recovered - reference).max() < 1e-10 * scale, blade
        # The amplitude is max |u| over the 64 AFT samples of the period.
        samples = tip_series(full.state, dofs, 3 * blade + 1, 2 * np.pi * np.arange(64) / 64)
        assert abs(np.abs(samples).max() - amplitudes[blade]) < 1e-10 * scale, blade


def test_blade_recovery_is_refused_outside_a_sector_and_past_the_last_blade():
    sector = ssn.solve(ssn.Scene.from_file(SECTOR).with_values(SECTOR_VALUES))
    with pytest.raises(ValueError, match="blade 8: allowed 0..8"):
        sector.blade_displacement(BLADES)
    full = ssn.solve(full_disk_scene())
    assert full.blade_amplitudes is None
    with pytest.raises(ValueError, match=r"not a \[cyclic\] sector"):
        full.blade_displacement(0)
