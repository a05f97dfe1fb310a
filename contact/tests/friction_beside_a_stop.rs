//! Friction beside a stop, solved from zero with the default globalization: the two-dof
//! chain with a friction point on its free mass and a stop on the same mass, over a grid of
//! normal loads and frequencies, with the stop far away (gap 100: it closes only near the
//! resonance) and close (gap 0.5). Every case converges (the smoothing path blurs a far
//! stop only over the linear motion, not over its whole gap); each answer is checked on
//! its own (its residual evaluated again by a fresh problem) and against the Armijo line
//! search's answer where that converges too.

#[path = "common/chain.rs"]
mod chain;

use semismooth::Residual;
use semismooth_contact::hb::{HbOptions, SsnHb};
use semismooth_contact::model::{ContactRow, FrictionPoint, Structure};
use semismooth_contact::settings::{GlobalizationChoice, SolverSettings};
use semismooth_contact::solve::{solve, Solution};

/// The chain (unit masses and springs, `zeta = 0.005`, unit force on the free mass) with a
/// stop at `gap` and Coulomb friction `mu = 0.5` under the normal load `normal_load` on the
/// free mass.
fn chain_with_friction(gap: f64, normal_load: f64) -> Structure {
    let mut chain = chain::chain(gap, 0.005, [0.0, 1.0]);
    chain.model.friction = vec![FrictionPoint::prescribed(
        ContactRow::unit(1, 1.0),
        0.5,
        normal_load,
    )];
    chain
}

const NORMAL_LOADS: [f64; 6] = [0.001, 0.003, 0.01, 0.03, 0.1, 0.3];
const OMEGA_RATIOS: [f64; 8] = [0.4, 0.6, 0.8, 0.9, 1.0, 1.1, 1.3, 1.6];

/// The solve of `chain` at `omega_ratio omega_1` from zero with `globalization` (no error
/// estimate: only the solve is under test).
fn solve_with(chain: &Structure, omega_ratio: f64, globalization: GlobalizationChoice) -> Solution {
    let settings = SolverSettings {
        globalization,
        estimate_error: false,
        ..SolverSettings::default()
    };
    solve(chain, omega_ratio * chain.omega_1, &settings, None).expect("the solve runs")
}

/// `|F|` of the SSN-HB residual at `solution`'s state, evaluated by a new problem posed with
/// the solution's own `c`.
fn residual_again(chain: &Structure, solution: &Solution) -> f64 {
    let options = HbOptions {
        c: solution.c,
        ..HbOptions::default()
    };
    let mut problem = SsnHb::new(&chain.model, solution.omega, &options).expect("a problem");
    let mut f = vec![0.0; problem.dim()];
    problem.residual(&solution.state, &mut f).expect("F");
    f.iter().map(|v| v * v).sum::<f64>().sqrt()
}

#[test]
fn the_friction_with_stop_grid_converges_from_zero_in_all_96_cases() {
    let mut failed = Vec::new();
    let mut compared = 0;
    for gap in [100.0, 0.5] {
        for normal_load in NORMAL_LOADS {
            for omega_ratio in OMEGA_RATIOS {
                let chain = chain_with_friction(gap, normal_load);
                let case = format!("gap {gap}, N = {normal_load}, omega = {omega_ratio} omega_1");
                let solution = solve_with(&chain, omega_ratio, GlobalizationChoice::Auto);
                if !solution.converged() {
                    let attempts: Vec<String> = solution
                        .attempts
                        .iter()
                        .map(|a| format!("{:?} {} {}", a.strategy, a.iterations, a.outcome))
                        .collect();
                    failed.push(format!("{case}: {}", attempts.join("; ")));
                    continue;
                }
                // The residual again, from a problem that shares nothing with the solve: at
                // the run's tolerance (1e-10 absolute, forces of order 1), 10 x for the
                // summation order of a new evaluation.
                let tolerance = solution.effective_tolerance.expect("a Newton method");
                let again = residual_again(&chain, &solution);
                assert!(again <= 10.0 * tolerance, "{case}: |F| = {again:e}");
                // Where the Armijo line search converges too and neither answer touches the
                // stop, the two agree: the chain with Coulomb friction alone has one periodic
                // solution (the friction law is monotone, the damping strictly so). They
                // differ by the solves' tolerance times the condition number of the Newton
                // matrix: 1e-6 relative leaves room for a condition number of 1e4. (Where
                // the stop is touched, orbits may coexist: at gap 0.5, N = 0.1, 0.6 omega_1
                // the two searches find two, contact fractions 0.13 and 0.18, both with
                // |F| < 1e-15.)
                let armijo = solve_with(&chain, omega_ratio, GlobalizationChoice::Armijo);
                let open = |s: &Solution| s.contacts[0].contact_fraction == 0.0;
                if armijo.converged() && open(&solution) && open(&armijo) {
                    compared += 1;
                    let scale = solution.observed.iter().fold(1.0f64, |m, v| m.max(v.abs()));
                    let difference = solution
                        .observed
                        .iter()
                        .zip(&armijo.observed)
                        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
                    assert!(difference <= 1e-6 * scale, "{case}: {difference:e}");
                }
            }
        }
    }
    assert!(
        failed.is_empty(),
        "{} of 96 failed:\n{}",
        failed.len(),
        failed.join("\n")
    );
    // The comparison is not vacuous.
    assert!(compared >= 24, "compared with Armijo on {compared} cases");
}

/// The same grid at `H = 20` (AFT samples by the default rule): every case converges from
/// zero, and its residual evaluated again by a fresh problem at `H = 20` meets the run's
/// tolerance (10 x for the summation order of a new evaluation).
#[test]
fn the_friction_with_stop_grid_converges_from_zero_at_twenty_harmonics() {
    const HARMONICS: usize = 20;
    let mut failed = Vec::new();
    for gap in [100.0, 0.5] {
        for normal_load in NORMAL_LOADS {
            for omega_ratio in OMEGA_RATIOS {
                let chain = chain_with_friction(gap, normal_load);
                let settings = SolverSettings {
                    estimate_error: false,
                    ..SolverSettings::with_harmonics(HARMONICS)
                };
                let omega = omega_ratio * chain.omega_1;
                let solution = solve(&chain, omega, &settings, None).expect("the solve runs");
                let case = format!("gap {gap}, N = {normal_load}, omega = {omega_ratio} omega_1");
                if !solution.converged() {
                    failed.push(case);
                    continue;
                }
                let options = HbOptions {
                    c: solution.c,
                    harmonics: HARMONICS,
                    time_samples: Some(settings.time_samples),
                };
                let mut problem = SsnHb::new(&chain.model, omega, &options).expect("a problem");
                let mut f = vec![0.0; problem.dim()];
                problem.residual(&solution.state, &mut f).expect("F");
                let again = f.iter().map(|v| v * v).sum::<f64>().sqrt();
                let tolerance = solution.effective_tolerance.expect("a Newton method");
                assert!(again <= 10.0 * tolerance, "{case}: |F| = {again:e}");
            }
        }
    }
    assert!(
        failed.is_empty(),
        "{} of 96 failed:\n{}",
        failed.len(),
        failed.join("\n")
    );
}
