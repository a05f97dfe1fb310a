//! What the cyclic-sector tests share: the tuned disk, the settings under which a sector and
//! its full disk pose the same equations, a solve asserted converged, the full disk under an
//! engine-order load, the resonance a sector's engine order excites and the gap between a
//! sector's recovered response and the full disk's.

#![allow(dead_code)]

use semismooth_contact::cyclic::CyclicSector;
use semismooth_contact::model::Structure;
use semismooth_contact::rod::natural_frequencies;
use semismooth_contact::settings::{LinearSolverChoice, SolverSettings};
use semismooth_contact::solve::{solve, Solution};
use semismooth_contact::structures::{BladedDisk, DiskLoading};

/// Blades of the tuned disk.
pub const BLADES: usize = 8;

/// The tuned disk of [`BLADES`] blades.
pub fn tuned_disk() -> BladedDisk {
    BladedDisk::tuned(BLADES)
}

/// `harmonics` and `linear_solver` with the settings that make the sector's equations the
/// full disk's.
pub fn settings(harmonics: usize, linear_solver: LinearSolverChoice) -> SolverSettings {
    SolverSettings {
        harmonics,
        // A multiple of N: the sector delay EO T / N is a whole number of samples, so the
        // full disk's AFT is exactly equivariant and the sector poses the same equations.
        time_samples: 64,
        tolerance: 1e-13,
        // One complementarity constant for both: the AFT-projected equations depend on it.
        c: Some(5.0),
        linear_solver,
        estimate_error: false,
        ..SolverSettings::default()
    }
}

/// The solve of `structure` at `omega` with `s`, asserted converged.
pub fn converged(structure: &Structure, omega: f64, s: &SolverSettings) -> Solution {
    let solution = solve(structure, omega, s, None).unwrap();
    assert!(solution.converged(), "{:?}", solution.termination);
    solution
}

/// The full `disk` under `loading` with the engine-order load: the load of sector `s`
/// delayed by `s EO T / N`.
pub fn engine_order_disk(
    disk: &BladedDisk,
    loading: &DiskLoading,
    engine_order: usize,
) -> Structure {
    let mut structure = disk.structure(loading).unwrap();
    let load = structure.model.load.clone();
    structure.model.load = load
        .delayed_by_sector(&disk.sector_dofs(), engine_order)
        .unwrap();
    structure
}

/// The first natural frequency of the nodal diameter on which the sector's first harmonic
/// lives (the resonance its engine order excites).
pub fn nodal_diameter_resonance(sector: &CyclicSector) -> f64 {
    let nd = sector.nodal_diameter(1);
    natural_frequencies(&sector.nodal_diameter_model(nd), 1).unwrap()[0]
}

/// The largest difference between the sector's state `reduced` (its first `3 (2H + 1)`
/// coefficients are the sector's displacements) recovered on every sector of the tuned disk
/// and the full disk's state `full`, relative to the full disk's largest displacement
/// coefficient.
pub fn relative_recovery_gap(
    sector: &CyclicSector,
    reduced: &[f64],
    full: &[f64],
    harmonics: usize,
) -> f64 {
    let len = 2 * harmonics + 1;
    let recovered = tuned_disk().recover(sector, &reduced[..3 * len], harmonics);
    let full = &full[..3 * BLADES * len];
    let scale = full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let gap = (recovered.iter().zip(full)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    gap / scale
}
