//! Stability asked of a solution alone: [`solution_stability`] decides from what the
//! solution carries (its settings, frequency and state) what [`hb_stability`] decides from
//! the parts carried by hand.

mod common;

use common::{canonical, solve_converged};
use semismooth_contact::rod::{build_rod, MassModel};
use semismooth_contact::settings::{Method, SolverSettings};
use semismooth_contact::stability::{hb_stability, solution_stability};

#[test]
fn a_solutions_stability_is_that_of_its_solved_settings_frequency_and_state() {
    // The paper's rod (tip gap 0.5, forced at omega_1, massless contact node), by both harmonic-balance
    // methods. The two paths run the same analysis on the same numbers, so they agree
    // exactly (no tolerance): what is checked is that the solution carries the settings
    // its equation was solved with (SSN-HB's `c` included) and its frequency and state.
    let rod = build_rod(&canonical(MassModel::Modified)).unwrap();
    for method in [Method::SsnHb, Method::PenaltyHb] {
        let settings = SolverSettings {
            estimate_error: false,
            ..SolverSettings::for_method(method)
        };
        let solution = solve_converged(&rod, &settings);
        let asked = solution_stability(&rod.model, &solution).unwrap();
        let by_hand = hb_stability(
            &rod.model,
            &solution.solved_settings(&settings),
            rod.omega(),
            &solution.state,
        )
        .unwrap();
        assert_eq!(asked, by_hand, "{}", method.name());
        assert_eq!(solution.settings.method, method);
        assert_eq!(solution.settings.harmonics, settings.harmonics);
    }
}
