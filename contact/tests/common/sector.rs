//! What the cyclic-sector tests share: the settings under which a sector and its full disk
//! pose the same equations, and a solve asserted converged.

use semismooth_contact::model::Structure;
use semismooth_contact::settings::{LinearSolverChoice, SolverSettings};
use semismooth_contact::solve::{solve, Solution};

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
