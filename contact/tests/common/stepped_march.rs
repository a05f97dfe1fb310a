//! A frequency sweep by time marching: the frequency stepped slowly up or down, each step
//! marched from the last state of the previous one to its steady period, as a slow
//! experiment would see it; the jumps are where the amplitude changes most between steps.
//! Shared by a test and an example.

use semismooth_contact::march::{march_from_state, MarchError, MarchOptions, MarchState};
use semismooth_contact::model::{StructuralModel, Structure};
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::sweep::frequency_response;

/// The folds (in `omega_1`, in branch order) of the SSN-HB branch of `structure` at
/// `harmonics` over `[0.5, 2] omega_1`.
pub fn branch_folds(structure: &Structure, harmonics: usize) -> Vec<f64> {
    let r = frequency_response(
        structure,
        &SolverSettings::with_harmonics(harmonics),
        &SweepSettings::new(0.5, 2.0),
        None,
    )
    .expect("valid settings");
    assert!(r.converged(), "H = {harmonics}: {:?}", r.termination);
    r.folds.iter().map(|w| w / structure.omega_1).collect()
}

/// The amplitudes `max |u_obs|` over the steady period at each of `omegas` (in the order
/// given) of marching with `options`, each frequency started from the final state of the
/// previous one (the first from rest); a march that does not settle within
/// `options.max_periods` gives its last period.
pub fn stepped_amplitudes(
    model: &StructuralModel,
    omegas: &[f64],
    options: &MarchOptions,
    observed: usize,
) -> Vec<f64> {
    let mut state = MarchState::rest(model);
    omegas
        .iter()
        .map(|&omega| {
            let period = match march_from_state(model, omega, options, &[observed], &state) {
                Ok(p) => p,
                Err(MarchError::NotSteady { last_period, .. }) => *last_period,
                Err(e) => panic!("march at {omega}: {e}"),
            };
            state = period.final_state.clone();
            period.displacements[0]
                .iter()
                .fold(0.0f64, |a, u| a.max(u.abs()))
        })
        .collect()
}

/// The frequency midway between the two neighbouring steps whose amplitudes differ most
/// (the jump), and that difference.
pub fn jump(omegas: &[f64], amplitudes: &[f64]) -> (f64, f64) {
    (1..omegas.len())
        .map(|k| {
            (
                0.5 * (omegas[k - 1] + omegas[k]),
                (amplitudes[k] - amplitudes[k - 1]).abs(),
            )
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .expect("two frequencies at least")
}
