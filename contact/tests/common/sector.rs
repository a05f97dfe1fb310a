//! What the cyclic-sector tests share: the settings under which a sector and its full disk
//! pose the same equations, a solve asserted converged, the full disk under an engine-order
//! load and the resonance a sector's engine order excites.

#![allow(dead_code)]

use semismooth_contact::cyclic::CyclicSector;
use semismooth_contact::model::Structure;
use semismooth_contact::rod::natural_frequencies;
use semismooth_contact::settings::{LinearSolverChoice, SolverSettings};
use semismooth_contact::solve::{solve, Solution};
use semismooth_contact::structures::{BladedDisk, DiskLoading};

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
