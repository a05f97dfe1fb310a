"""``Model.reduce`` through the library (not the ``ssn`` program): the reduced model's natural
frequencies against the full model's below the cut-off, on the CalculiX cantilever (216
dofs, the tip's y in contact) of the application's fixtures."""

import pytest

import ssn
from conftest import REPO

CANTILEVER = REPO / "ssn" / "tests" / "fixtures" / "calculix_cantilever" / "cantilever.toml"


@pytest.fixture(scope="module")
def model():
    return ssn.Model.from_scene(ssn.Scene.from_file(CANTILEVER))


def test_massless_boundary_keeps_the_full_frequencies_below_the_cutoff(model):
    assert model.dofs == 216
    full = model.frequencies(6)
    assert full == sorted(full) and model.omega_1 == pytest.approx(full[0], rel=1e-10)
    reduced = model.reduce("massless-boundary", cutoff=4 * full[5])
    assert reduced.dofs < 40
    # Condensing MacNeal's massless boundary returns the free-interface modes kept: below
    # the cut-off the frequencies are the full model's up to the two eigensolvers'
    # tolerances (about 1e-12 relative); 1e-9 leaves room.
    for w, r in zip(full, reduced.frequencies(6)):
        assert abs(r - w) <= 1e-9 * w


def test_craig_bampton_bounds_the_frequencies_from_above_and_converges_with_modes(model):
    full = model.frequencies(6)
    errors = []
    for modes in (8, 32):
        reduced = model.reduce("craig-bampton", modes=modes)
        assert reduced.dofs == modes + 1  # one boundary dof: the tip's y
        ritz = reduced.frequencies(6)
        # Rayleigh-Ritz: never below the full model's (to round-off).
        assert all(r >= w * (1 - 1e-12) for w, r in zip(full, ritz))
        errors.append(max((r - w) / w for w, r in zip(full, ritz)))
    # 8 modes: a few 1e-3 on the sixth frequency; 32: below 1e-4 (the application's table).
    assert errors[1] < 1e-4 and errors[1] < errors[0] / 10


def test_a_bad_method_or_mode_choice_is_refused(model):
    with pytest.raises(ValueError, match="craig-bampton"):
        model.reduce("guyan", modes=4)
    with pytest.raises(ValueError, match="one of them"):
        model.reduce(modes=4, cutoff=1.0)
    with pytest.raises(ValueError, match="one of them"):
        model.reduce()


def test_a_bad_reduction_method_or_mode_count_is_a_scene_error():
    model = ssn.Model.from_scene(ssn.Scene.rod(elements=4))
    with pytest.raises(ssn.SceneError, match="method \"guyan\": allowed"):
        model.reduce("guyan", modes=2)
    with pytest.raises(ssn.SceneError, match="allowed one of them"):
        model.reduce(modes=2, cutoff=1.0)
