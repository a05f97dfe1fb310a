//! The matrix-free condensed SSN-HB solve (GMRES with the contact-block preconditioner)
//! against the dense condensed LU on a mistuned bladed disk with 30 and 100 contacts.

use semismooth::{Factorize, GeneralizedJacobian, LinearSolve, Residual};
use semismooth_contact::hb::{
    CondensedSolve, HbOptions, SsnHb, KRYLOV_RELATIVE_TOLERANCE, KRYLOV_THRESHOLD,
};
use semismooth_contact::model::Structure;
use semismooth_contact::solve::{structured_solver, Solution};
use semismooth_contact::structures::{BladedDisk, DiskLoading, SHIPPED_MISTUNING};
use ssn::scene::{default_hb_time_samples, LinearSolverChoice, Scene};

mod common;

/// The shipped disk's 100 mistuned blades with stops on `count` of them, evenly spaced,
/// and the shipped load and damping; returned with the shipped forcing frequency.
fn disk_with_stops(count: usize) -> (Structure, f64) {
    let disk = BladedDisk {
        blades: 100,
        mistuning: SHIPPED_MISTUNING,
    };
    let loading = DiskLoading::shipped((0..count).map(|i| i * 100 / count).collect());
    let structure = disk.structure(&loading).unwrap();
    let omega = loading.omega(structure.omega_1);
    (structure, omega)
}

fn solve(
    structure: &Structure,
    omega: f64,
    choice: LinearSolverChoice,
    harmonics: usize,
) -> Solution {
    let mut settings = Scene::from_toml(
        "[rod]\nelements = 2\n[forcing]\namplitude = 0.1\n[contact]\ngap = 0.5\n",
        "t.toml",
    )
    .unwrap()
    .solver;
    settings.harmonics = harmonics;
    settings.time_samples = default_hb_time_samples(harmonics);
    settings.linear_solver = choice;
    settings.max_iterations = 200;
    semismooth_contact::solve(structure, omega, &settings, None).unwrap()
}

#[test]
fn krylov_path_gives_the_dense_answer_in_the_same_iterations() {
    // Measured with the default c: 38 and 38 iterations for 30 stops, 13 and 13 for 100
    // stops.
    for stops in [30, 100] {
        compare_paths(stops);
    }
}

fn compare_paths(stops: usize) {
    let (structure, omega) = disk_with_stops(stops);
    let dense = solve(&structure, omega, LinearSolverChoice::CondensedDense, 5);
    let krylov = solve(&structure, omega, LinearSolverChoice::CondensedKrylov, 5);
    for s in [&dense, &krylov] {
        assert!(s.converged(), "{} after {}", s.termination, s.iterations);
        // Both end below the Newton tolerance 1e-10 (or the round-off floor).
        assert!(s.residual_norm <= 1e-10, "{:e}", s.residual_norm);
    }
    assert_eq!(dense.iterations, krylov.iterations);
    assert_eq!(dense.strategy, krylov.strategy);
    // Every GMRES step meets |J d - r| <= max(1e-10 |r|, 1e-12); on the last step's piece
    // the residual is affine and both paths end on the same active set, so the answers
    // (of size O(1), gap 1) agree to round-off: measured at most 3.2e-13 (observed dof)
    // and 6.3e-13 (forces) over 30 and 100 stops, asserted at 1e-11. A GMRES that stopped
    // at its tolerance instead would move them by |J^-1| 1e-10.
    let amplitude = dense.observed.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(amplitude > 1.0, "the observed pad reaches the casing");
    let tip = common::max_abs_diff(&dense.observed, &krylov.observed);
    eprintln!(
        "{stops} stops: iterations {} / {}, tip difference {tip:e}",
        dense.iterations, krylov.iterations
    );
    assert!(tip <= 1e-11, "tip {tip:e}");
    for (a, b) in dense.contact_forces.iter().zip(&krylov.contact_forces) {
        let d = common::max_abs_diff(a, b);
        assert!(d <= 1e-11, "force {d:e}");
    }
    let active = krylov
        .contacts
        .iter()
        .filter(|c| c.force_mean < 0.0)
        .count();
    assert!(
        2 * active >= stops,
        "most stops are hit: {active} of {stops}"
    );
}

#[test]
fn one_matrix_free_step_solves_the_full_newton_system_to_its_tolerance() {
    // At the converged active set, one step with a generic right-hand side: the full
    // residual |J d - r| (structured product of the dense path's Jacobian, assembled here
    // densely) meets the GMRES tolerance, and the step matches the dense condensed LU's.
    let (structure, omega) = disk_with_stops(30);
    let solution = solve(&structure, omega, LinearSolverChoice::CondensedDense, 3);
    let options = HbOptions {
        harmonics: 3,
        time_samples: Some(default_hb_time_samples(3)),
        c: None,
    };
    let mut problem = SsnHb::new(&structure.model, omega, &options).unwrap();
    let mut jac = problem.new_jacobian();
    problem.jacobian(&solution.state, &mut jac).unwrap();
    let r: Vec<f64> = (0..problem.dim())
        .map(|i| ((i as f64) * 0.7).sin())
        .collect();
    let mut steps = Vec::new();
    for condensed in [CondensedSolve::Dense, CondensedSolve::Krylov] {
        let mut solver = structured_solver(condensed, 1e-10);
        solver.factor(&jac).unwrap();
        assert_eq!(solver.is_matrix_free(), condensed == CondensedSolve::Krylov);
        let mut d = r.clone();
        solver.solve_in_place(&mut d).unwrap();
        steps.push(d);
    }
    // Dense reference: the full Jacobian assembled and factored densely.
    let mut lu = semismooth::linalg::FaerDenseLu::new();
    lu.factor(&jac).unwrap();
    let mut exact = r.clone();
    lu.solve_in_place(&mut exact).unwrap();
    let r_norm = r.iter().map(|v| v * v).sum::<f64>().sqrt();
    let scale = exact.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    // GMRES stops at |S e| <= 1e-10 |r|: the step error is at most |S^-1| 1e-10 |r|.
    // Allow |S^-1| up to 100 (measured difference below).
    let bound = 100.0 * KRYLOV_RELATIVE_TOLERANCE * r_norm;
    for d in &steps {
        let diff = common::max_abs_diff(d, &exact);
        eprintln!("step difference {diff:e} (bound {bound:e}, step scale {scale:e})");
        assert!(diff <= bound.max(1e-12 * scale), "{diff:e} > {bound:e}");
    }
}

#[test]
fn the_automatic_choice_follows_the_documented_threshold() {
    let auto = CondensedSolve::Auto;
    // 30 contacts at H = 5: 330 unknowns, dense; 100 contacts at H = 20: 4,100, GMRES.
    assert!(!auto.uses_krylov(30, 5, true));
    assert!(auto.uses_krylov(100, 20, true));
    let h = 20;
    let largest_dense = KRYLOV_THRESHOLD / (2 * h + 1);
    assert!(!auto.uses_krylov(largest_dense, h, true));
    assert!(auto.uses_krylov(largest_dense + 1, h, true));
    // Penalty HB has no matrix-free path; forcing it keeps the dense condensed LU.
    assert!(!CondensedSolve::Krylov.uses_krylov(1000, 20, false));
    assert!(!CondensedSolve::Dense.uses_krylov(1000, 20, true));
}

/// Contacts close together on a fine rod (every second node of its last fifth, gaps shaped
/// like the first mode) are coupled through the structure far beyond the contact blocks:
/// after the first full step from zero (the linear response, deep in the obstacles) GMRES
/// with the blocks does not reach its tolerance within one restart cycle, and the
/// matrix-free solver takes the dense condensed matrix of that iterate as its
/// preconditioner. The step it returns is the dense LU's (the same bound as above), and the
/// dense preconditioner is kept for the next iterate.
#[test]
fn strongly_coupled_contacts_switch_to_the_dense_preconditioner_and_keep_the_dense_step() {
    use semismooth_contact::from_zero::many_contacts_rod;
    use semismooth_contact::rod::build_rod;
    let harmonics = 5;
    let rod = build_rod(&many_contacts_rod(100)).unwrap();
    let options = HbOptions {
        harmonics,
        time_samples: Some(default_hb_time_samples(harmonics)),
        c: None,
    };
    let mut problem = SsnHb::new(&rod.model, rod.omega(), &options).unwrap();
    let n = problem.dim();
    // x1 = -J(0)^-1 F(0): the first full step from zero.
    let mut x = vec![0.0; n];
    let mut f = vec![0.0; n];
    let mut jac = problem.new_jacobian();
    problem.residual(&x, &mut f).unwrap();
    problem.jacobian(&x, &mut jac).unwrap();
    let mut dense = structured_solver(CondensedSolve::Dense, 1e-10);
    dense.factor(&jac).unwrap();
    dense.solve_in_place(&mut f).unwrap();
    for (xi, di) in x.iter_mut().zip(&f) {
        *xi = -di;
    }
    problem.residual(&x, &mut f).unwrap();
    problem.jacobian(&x, &mut jac).unwrap();
    let mut exact = f.clone();
    dense.factor(&jac).unwrap();
    dense.solve_in_place(&mut exact).unwrap();
    let mut krylov = structured_solver(CondensedSolve::Krylov, 1e-10);
    krylov.factor(&jac).unwrap();
    let mut step = f.clone();
    krylov.solve_in_place(&mut step).unwrap();
    eprintln!(
        "GMRES iterations {}, dense preconditioner factorizations {}",
        krylov.krylov_iterations(),
        krylov.dense_preconditioner_factorizations()
    );
    assert_eq!(krylov.dense_preconditioner_factorizations(), 1);
    let r_norm = f.iter().map(|v| v * v).sum::<f64>().sqrt();
    let scale = exact.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let bound = 100.0 * KRYLOV_RELATIVE_TOLERANCE * r_norm;
    let diff = common::max_abs_diff(&step, &exact);
    eprintln!("step difference {diff:e} (bound {bound:e}, step scale {scale:e})");
    assert!(diff <= bound.max(1e-12 * scale), "{diff:e} > {bound:e}");
    // The next factorization keeps the dense preconditioner (no new dense factorization
    // at the same iterate, and GMRES converges with it at once).
    krylov.factor(&jac).unwrap();
    let before = krylov.krylov_iterations();
    let mut again = f.clone();
    krylov.solve_in_place(&mut again).unwrap();
    assert_eq!(krylov.dense_preconditioner_factorizations(), 1);
    assert!(krylov.krylov_iterations() - before <= 3);
    assert!(common::max_abs_diff(&again, &exact) <= bound.max(1e-12 * scale));
}
