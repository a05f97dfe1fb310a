//! SSN-HB condensed onto the contact forces, continued in frequency by the core's
//! continuation: its frequency derivative against central differences, and its branch
//! against the full (displacements and forces) problem and a direct solve.

use semismooth::continuation::{Continuation, ContinuationOptions};
use semismooth::linalg::FaerDenseLu;
use semismooth::newton::NewtonReport;
use semismooth::polyalgorithm::{solve, PolyalgorithmOptions};
use semismooth::{ParameterDependent, Residual};
use semismooth_contact::hb::{CondensedSsnHb, HbOptions, SsnHb};
use semismooth_contact::rod::{build_rod, MassModel, RodModel, RodSpec};

fn rod() -> RodModel {
    build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })
    .unwrap()
}

fn options(h: usize) -> HbOptions {
    HbOptions {
        harmonics: h,
        ..HbOptions::default()
    }
}

/// At the contact solution at omega_1 (active samples on both sides), the analytic
/// `dR/dw` equals the central difference of residuals rebuilt at `w +- h`: the residual is
/// smooth in `w` at fixed active set, so the difference is exact to `O(h^2)` (h = 1e-6 w,
/// the resonance scale zeta w = 1.6e-2: truncation ~ 1e-8 relative) plus rounding
/// `eps |R| / h ~ 1e-10`.
/// The condensed SSN-HB problem of `rod` at `h` harmonics solved from zero by the
/// polyalgorithm (converged): the problem, the force coefficients and the report.
fn solved_from_zero(rod: &RodModel, h: usize) -> (CondensedSsnHb, Vec<f64>, NewtonReport) {
    let mut problem = CondensedSsnHb::new(&rod.model, rod.omega(), &options(h)).unwrap();
    let mut lambda = vec![0.0; problem.dim()];
    let report = solve(
        &mut problem,
        &mut FaerDenseLu::new(),
        &mut lambda,
        &PolyalgorithmOptions::default(),
    )
    .unwrap();
    assert!(report.converged(), "{:?}", report.termination);
    (problem, lambda, report)
}

#[test]
fn condensed_frequency_derivative_matches_central_differences() {
    let rod = rod();
    let (mut problem, lambda, report) = solved_from_zero(&rod, 10);
    assert!(report.iterations > 1, "contact: more than one Newton step");
    let omega = problem.parameter();
    let mut analytic = vec![0.0; problem.dim()];
    problem
        .residual_parameter_derivative(&lambda, &mut analytic, &mut vec![0.0; problem.dim()])
        .unwrap();
    let h = 1e-6 * omega;
    let (mut plus, mut minus) = (vec![0.0; problem.dim()], vec![0.0; problem.dim()]);
    problem.set_parameter(omega + h);
    problem.residual(&lambda, &mut plus).unwrap();
    problem.set_parameter(omega - h);
    problem.residual(&lambda, &mut minus).unwrap();
    let scale = analytic.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    assert!(scale > 1e-3, "the forces depend on omega: {scale:e}");
    for (i, a) in analytic.iter().enumerate() {
        let fd = (plus[i] - minus[i]) / (2.0 * h);
        assert!((fd - a).abs() <= 1e-6 * scale, "{i}: {fd} vs {a}");
    }
}

/// The condensed problem continued in frequency from below the contact onset (0.9 omega_1)
/// to omega_1 (dense LU of its `m (2H + 1)` Jacobian, the core's continuation): every
/// point expanded to `[U; Lambda]` is a root of the full SSN-HB residual (to 1e-8: the
/// corrector tolerance 1e-11 amplified by the receptance), the branch passes the onset
/// (the mean contact force leaves 0), and its last point, landed on omega_1, is the direct
/// Newton solution at omega_1 (to 1e-8 of the forces: both are converged to 1e-10 or
/// better on a problem with condition number below 1e3).
#[test]
fn condensed_branch_points_are_full_solutions_and_end_at_the_direct_solution() {
    let rod = rod();
    let h = 5;
    let omega_1 = rod.omega_1;
    let n = 2 * h + 1;
    let omega_from = 0.9 * omega_1;
    let steps = ContinuationOptions {
        parameter_min: omega_from,
        parameter_max: omega_1,
        corrector_tolerance: 1e-11,
        max_points: 5000,
        state_scale: Some(vec![1e-2 * (0.5 * n as f64).sqrt(); n]),
        parameter_scale: 0.5f64.sqrt() * omega_1,
        ..ContinuationOptions::with_step(1e-2)
    };
    let mut condensed = CondensedSsnHb::new(&rod.model, rod.omega(), &options(h)).unwrap();
    condensed.set_parameter(omega_from);
    let start = vec![0.0; condensed.dim()];
    let mut dense = FaerDenseLu::new();
    let branch = Continuation::new(&mut condensed, &mut dense, &start, omega_from, steps)
        .unwrap()
        .run();
    let last = branch.points.last().unwrap();
    assert_eq!(last.parameter, omega_1, "{}", branch.termination);
    let onset = branch.points.iter().position(|p| p.state[0] < 0.0).unwrap();
    assert!(onset > 1 && branch.points[onset - 1].state[0] == 0.0);

    let mut full = SsnHb::new(&rod.model, rod.omega(), &options(h)).unwrap();
    let mut residual = vec![0.0; full.dim()];
    let mut worst = 0.0f64;
    for point in &branch.points {
        condensed.set_parameter(point.parameter);
        let x = condensed.expand(&point.state).unwrap();
        full.set_parameter(point.parameter);
        full.residual(&x, &mut residual).unwrap();
        worst = worst.max(residual.iter().fold(0.0f64, |a, v| a.max(v.abs())));
    }
    assert!(worst < 1e-8, "full residual at condensed points {worst:e}");

    let (_, lambda, _) = solved_from_zero(&rod, h);
    let scale = lambda.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    for (a, b) in last.state.iter().zip(&lambda) {
        assert!((a - b).abs() <= 1e-8 * scale, "{a} vs {b}");
    }
}
