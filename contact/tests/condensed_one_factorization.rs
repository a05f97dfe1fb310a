//! The exact SSN-HB solve that holds one per-harmonic factorization at a time
//! (`solve::solve_condensed`) against the structured solve that holds all `H + 1`: the same
//! equations, so the same answer up to the Newton tolerance.

use semismooth_contact::model::Structure;
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::settings::{default_hb_time_samples, Method, SolverSettings};
use semismooth_contact::solve::{solve_condensed, Solution};

/// The largest difference of `a` and `b` relative to the largest `|a|`.
fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let scale = a.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let difference = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    difference / scale
}

fn rod_at_h5() -> (Structure, f64, SolverSettings) {
    let mut spec = RodSpec::canonical();
    spec.mass = MassModel::Modified; // massless contact node: a well-posed periodic problem
    let rod = build_rod(&spec).unwrap();
    let omega = rod.omega();
    let structure = Structure::new(rod.model.clone(), rod.tip_dof()).unwrap();
    let settings = SolverSettings {
        method: Method::SsnHb,
        harmonics: 5,
        time_samples: default_hb_time_samples(5),
        ..SolverSettings::default()
    };
    (structure, omega, settings)
}

#[test]
fn one_factorization_at_a_time_gives_the_structured_solve_answer() {
    let (structure, omega, settings) = rod_at_h5();
    let structured: Solution =
        semismooth_contact::solve(&structure, omega, &settings, None).unwrap();
    let one_at_a_time = solve_condensed(&structure, omega, &settings, None).unwrap();
    assert!(structured.converged() && one_at_a_time.converged());
    assert_eq!(structured.c, one_at_a_time.c);
    // The contact closes: the answer is not the linear response.
    let force = one_at_a_time.contacts[0].force_mean;
    assert!(force < 0.0, "mean contact force {force}");
    // Both solve the same equations (the same `A(w)`, `G`, `c`) to the Newton tolerance
    // (1e-10 on residuals of order 1) from the same start; the condensed one eliminates `U`
    // exactly, so the answers differ by the two runs' final residuals times the
    // conditioning of the contact problem (measured: 1e-13): 1e-10 of the largest
    // coefficient is the Newton tolerance's level, far below any change of active set.
    let state = relative_difference(&structured.state, &one_at_a_time.state);
    let observed = relative_difference(&structured.observed, &one_at_a_time.observed);
    eprintln!("relative differences: state {state:.2e}, observed dof {observed:.2e}");
    assert!(state < 1e-10, "state differs by {state:.2e}");
    assert!(observed < 1e-10, "observed dof differs by {observed:.2e}");
}

#[test]
fn the_condensed_solve_refuses_another_method() {
    let (structure, omega, mut settings) = rod_at_h5();
    settings.method = Method::PenaltyHb;
    assert!(solve_condensed(&structure, omega, &settings, None).is_err());
}
