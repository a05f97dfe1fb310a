//! Pseudo-arclength continuation on problems whose branches are known independently:
//! closed forms (circle, S-curve, piecewise-linear kink, plateau), an implicit frequency
//! response (Duffing first-harmonic balance) whose folds are located by the cubic's
//! discriminant, and a natural-parameter sweep that jumps where the arclength follows.

mod common;

use common::branches::*;
use semismooth::continuation::{
    natural_sweep, Branch, Continuation, ContinuationError, ContinuationEvent, ContinuationOptions,
    ContinuationTermination, CorrectorFailure, Direction, Predictor, RestartPolicy,
};
use semismooth::linalg::{FaerDenseLu, LinearSolveError};
use semismooth::newton::{Globalization, NewtonOptions, NewtonSolver, Tolerances};
use semismooth::polyalgorithm::{self, PolyalgorithmOptions};
use semismooth::ParameterDependent;

#[test]
fn s_curve_branch_passes_both_folds_located_within_the_interpolation_error() {
    let branch = s_curve_branch();
    // Every point is on the curve (the corrector's tolerance on |F|).
    for q in &branch.points {
        let x = q.state[0];
        assert!((x.powi(3) - x - q.parameter).abs() <= 1e-10);
    }
    // Two folds, first the upper one (p = +2/(3√3)), then the lower one. The cubic Hermite
    // interpolant of p(σ) over one chord (θ = 1/2, n = 1: |y|_θ = |y|/√2, so a Euclidean
    // chord σ <= √2 max_step ≈ 0.07) has error
    // ~ σ^4 |p''''| / 384 with |p''''| ~ 10 κ^3 at a fold of curvature κ = 6/√3 ≈ 3.5:
    // about 3e-5; 1e-4 bounds it (measured 1.4e-5).
    let folds = branch.fold_parameters();
    println!("S-curve folds {folds:?}, {} points", branch.points.len());
    assert_eq!(folds.len(), 2);
    assert!((folds[0] - FOLD_S).abs() < 1e-4, "{}", folds[0] - FOLD_S);
    assert!((folds[1] + FOLD_S).abs() < 1e-4, "{}", folds[1] + FOLD_S);
    // The fold event sits between the two points whose tangents have opposite signs.
    for e in &branch.events {
        let ContinuationEvent::Fold { index, .. } = e else {
            continue;
        };
        let (a, b) = (&branch.points[index - 1], &branch.points[*index]);
        assert!(a.tangent_parameter * b.tangent_parameter < 0.0);
    }
    // The run ends on the bound p = 1, at the real root of x^3 - x - 1 (the plastic number,
    // Cardano: ((9 + √69)/18)^(1/3) + ((9 - √69)/18)^(1/3)).
    let s69 = 69f64.sqrt();
    let plastic = ((9.0 + s69) / 18.0).cbrt() + ((9.0 - s69) / 18.0).cbrt();
    let last = branch.points.last().unwrap();
    assert_eq!(
        branch.termination,
        ContinuationTermination::ReachedBound {
            parameter: 1.0,
            bound: 1.0
        }
    );
    assert!((last.state[0] - plastic).abs() < 1e-10);
    assert_one_factorization_per_iteration(&branch);
    // Without refinement the fold is reported at the extreme point of the branch, which is
    // within one step of the fold in the parameter.
    let mut problem = s_curve();
    let mut solver = FaerDenseLu::new();
    let coarse = Continuation::new(
        &mut problem,
        &mut solver,
        &[-1.3],
        -1.0,
        ContinuationOptions {
            parameter_min: -1.0,
            parameter_max: 1.0,
            refine_folds: false,
            ..Default::default()
        },
    )
    .unwrap()
    .run();
    let folds = coarse.fold_parameters();
    assert_eq!(folds.len(), 2);
    assert!((folds[0] - FOLD_S).abs() < 0.05 && (folds[1] + FOLD_S).abs() < 0.05);
}

#[test]
fn s_curve_followed_downwards_ends_at_the_lower_root() {
    let options = ContinuationOptions {
        direction: Direction::Decreasing,
        ..between(-1.0, 1.0)
    };
    let mut problem = s_curve();
    let branch = follow(&mut problem, &[1.3], 1.0, options);
    let folds = branch.fold_parameters();
    assert_eq!(folds.len(), 2);
    // Same interpolation bound as upwards.
    assert!((folds[0] + FOLD_S).abs() < 1e-4 && (folds[1] - FOLD_S).abs() < 1e-4);
    let last = branch.points.last().unwrap();
    assert_eq!(last.parameter, -1.0);
    let s69 = 69f64.sqrt();
    let plastic = ((9.0 + s69) / 18.0).cbrt() + ((9.0 - s69) / 18.0).cbrt();
    // x^3 - x + 1 = 0 has the root -plastic.
    assert!((last.state[0] + plastic).abs() < 1e-10);
    assert_eq!(problem.parameter(), -1.0);

    // Started on the lower bound heading down: the start is the whole branch.
    let options = ContinuationOptions {
        parameter_min: -1.0,
        direction: Direction::Decreasing,
        ..Default::default()
    };
    let branch = follow(&mut s_curve(), &[-1.3], -1.0, options);
    assert_eq!(branch.points.len(), 1);
    assert_eq!(
        branch.termination,
        ContinuationTermination::ReachedBound {
            parameter: -1.0,
            bound: -1.0
        }
    );
}

/// Follows the circle from (x, p) = (1, 0) once around (unwrapped polar angle 2π), using
/// the iterator directly.
fn once_around_the_circle(predictor: Predictor) -> (Vec<(f64, f64)>, Vec<f64>) {
    let mut problem = circle();
    let mut solver = FaerDenseLu::new();
    let options = ContinuationOptions {
        predictor,
        ..Default::default()
    };
    let mut continuation =
        Continuation::new(&mut problem, &mut solver, &[1.05], 0.0, options).unwrap();
    let mut points = Vec::new();
    let mut angle = 0.0_f64;
    for q in continuation.by_ref() {
        let phi = q.parameter.atan2(q.state[0]);
        // Unwrap: the increment between consecutive points is small and positive.
        let mut d = phi - angle.rem_euclid(2.0 * std::f64::consts::PI);
        if d < -std::f64::consts::PI {
            d += 2.0 * std::f64::consts::PI;
        }
        assert!((0.0..0.2).contains(&d), "angle increment {d}");
        angle += d;
        points.push((q.state[0], q.parameter));
        if angle > 2.0 * std::f64::consts::PI {
            break;
        }
    }
    let folds = continuation
        .events()
        .iter()
        .map(|e| match e {
            ContinuationEvent::Fold { parameter, .. } => *parameter,
            _ => f64::NAN,
        })
        .collect();
    (points, folds)
}

#[test]
fn circle_branch_goes_once_around_through_both_folds() {
    for predictor in [Predictor::Secant, Predictor::Tangent] {
        let (points, folds) = once_around_the_circle(predictor);
        // On the unit circle: the radius is 1 to the corrector's tolerance (|F| <= 1e-10
        // and F = r^2 - 1, so |r - 1| <= 1e-10 / 2).
        for (x, p) in &points {
            assert!((x.hypot(*p) - 1.0).abs() <= 1e-10);
        }
        // Folds at p = +1 then p = -1. Hermite interpolation of p = sin(σ) over a chord of
        // Euclidean length <= 0.05/√0.5: error <= h^4/384 ≈ 7e-8.
        println!("{predictor:?}: {} points, folds {folds:?}", points.len());
        assert_eq!(folds.len(), 2);
        assert!((folds[0] - 1.0).abs() < 1e-6 && (folds[1] + 1.0).abs() < 1e-6);
    }
}

/// Discriminant of the cubic in `u = A^2` whose positive roots are the Duffing response
/// amplitudes at `ω`: `c^2 u^3 + 2 c (1 - ω^2) u^2 + ((1 - ω^2)^2 + 4 ζ^2 ω^2) u - f^2`.
/// Positive: three real roots (inside the overhang); negative: one.
fn duffing_discriminant(w: f64) -> f64 {
    let c = 0.75 * GAMMA;
    let s = 1.0 - w * w;
    let (a, b, cc, d) = (
        c * c,
        2.0 * c * s,
        s * s + 4.0 * ZETA * ZETA * w * w,
        -FORCE * FORCE,
    );
    18.0 * a * b * cc * d - 4.0 * b.powi(3) * d + b * b * cc * cc
        - 4.0 * a * cc.powi(3)
        - 27.0 * a * a * d * d
}

/// Frequencies where the discriminant changes sign (the folds), by a grid scan and bisection.
fn duffing_folds_by_discriminant() -> Vec<f64> {
    let mut folds = Vec::new();
    let grid: Vec<f64> = (0..=3000).map(|i| 0.5 + 1.5 * i as f64 / 3000.0).collect();
    for pair in grid.windows(2) {
        let (mut lo, mut hi) = (pair[0], pair[1]);
        if duffing_discriminant(lo).signum() == duffing_discriminant(hi).signum() {
            continue;
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if duffing_discriminant(mid).signum() == duffing_discriminant(lo).signum() {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        folds.push(0.5 * (lo + hi));
    }
    folds
}

fn s_curve_branch() -> Branch {
    follow(&mut s_curve(), &[-1.3], -1.0, between(-1.0, 1.0))
}

fn duffing_branch() -> Branch {
    follow(&mut duffing(), &[0.13, 0.0], 0.5, between(0.5, 2.0))
}

#[test]
fn duffing_frequency_response_satisfies_the_implicit_amplitude_equation_through_two_folds() {
    let branch = duffing_branch();
    // Every point satisfies A^2 [(1 - ω^2 + 3/4 γ A^2)^2 + (2 ζ ω)^2] = f^2: this is
    // |M(A, ω) (a, b)|^2 = f^2 for the residual F = M (a, b) - (f, 0), so it holds to about
    // 2 f |F| <= 2e-11 absolute; relative to f^2 = 1e-2 that is 2e-9.
    for q in &branch.points {
        let (a, b, w) = (q.state[0], q.state[1], q.parameter);
        let u = a * a + b * b;
        let k = 1.0 - w * w + 0.75 * GAMMA * u;
        let lhs = u * (k * k + 4.0 * ZETA * ZETA * w * w);
        assert!(
            ((lhs - FORCE * FORCE) / (FORCE * FORCE)).abs() < 1e-8,
            "ω = {w}: {lhs}"
        );
    }
    // The branch overhangs: ω increases to the jump-down fold, decreases to the jump-up
    // fold, then increases to the bound.
    let reference = duffing_folds_by_discriminant();
    let folds = branch.fold_parameters();
    println!(
        "Duffing: {} points, folds {folds:?}, discriminant {reference:?}, counters {:?}",
        branch.points.len(),
        branch.counters
    );
    assert_eq!(reference.len(), 2);
    assert_eq!(folds.len(), 2);
    // First fold met is the upper (jump-down) frequency. Tolerance: Hermite interpolation
    // error over steps <= 0.05 (θ-norm), p'''' of order 10^2 at a sharp fold: < 1e-4.
    assert!(
        (folds[0] - reference[1]).abs() < 1e-4,
        "{}",
        folds[0] - reference[1]
    );
    assert!(
        (folds[1] - reference[0]).abs() < 1e-4,
        "{}",
        folds[1] - reference[0]
    );
    assert_eq!(
        branch.termination,
        ContinuationTermination::ReachedBound {
            parameter: 2.0,
            bound: 2.0
        }
    );
    assert_one_factorization_per_iteration(&branch);
    assert!(branch.counters.rejected_steps == 0);
    // Peak amplitude on the backbone ω^2 = 1 + 3/4 γ A^2 with A = f/(2ζω): the maximum of
    // the computed amplitudes is within a few percent of it (the sampled branch may miss
    // the exact peak by one step).
    let amplitudes = branch.measure(|q| q.state[0].hypot(q.state[1]));
    let peak = amplitudes.iter().cloned().fold(0.0, f64::max);
    // Solve A = f / (2 ζ sqrt(1 + 3/4 γ A^2)) by fixed point.
    let mut a_peak = 1.0;
    for _ in 0..200 {
        a_peak = FORCE / (2.0 * ZETA * (1.0 + 0.75 * GAMMA * a_peak * a_peak).sqrt());
    }
    println!("peak amplitude {peak} vs backbone estimate {a_peak}");
    assert!((peak - a_peak).abs() / a_peak < 0.02);
}

#[test]
fn kinked_piecewise_linear_branch_is_followed_through_the_kink() {
    let branch = follow(&mut kink(), &[0.2], 0.2, between(0.0, 3.0));
    // Piecewise linear: Newton with the generalized Jacobian is exact on each piece, so
    // every point matches the closed form to rounding (1e-12 on O(1) values).
    for q in &branch.points {
        assert!((q.state[0] - kink_closed_form(q.parameter)).abs() < 1e-12);
    }
    assert!(branch.points.iter().any(|q| q.state[0] < 1.0));
    assert!(branch.points.iter().any(|q| q.state[0] > 1.0));
    assert_eq!(fold_count(&branch), 0);
    assert_eq!(branch.points.last().unwrap().parameter, 3.0);
    // The parameter increases monotonically along this branch.
    assert!(branch
        .points
        .windows(2)
        .all(|w| w[1].parameter > w[0].parameter));
    assert_one_factorization_per_iteration(&branch);
}

#[test]
fn singular_jacobian_plateau_needs_the_dense_bordered_fallback() {
    let options = ContinuationOptions {
        parameter_min: 0.0,
        parameter_max: 2.0,
        max_points: 80,
        ..Default::default()
    };
    // With the fallback the branch turns the corner (1, 1) and runs along p = 1, x > 1,
    // where J = 0 exactly and only the bordered matrix [[0, 1], [w_x, w_p]] is regular.
    let mut problem = plateau();
    let mut solver = FaerDenseLu::new();
    let branch = Continuation::new(&mut problem, &mut solver, &[0.5], 0.5, options.clone())
        .unwrap()
        .with_dense_fallback()
        .run();
    for q in &branch.points {
        assert!((q.parameter - q.state[0].clamp(0.0, 1.0)).abs() < 1e-12);
    }
    let last = branch.points.last().unwrap();
    assert!(last.state[0] > 2.0 && last.parameter == 1.0, "{last:?}");
    assert!(branch.counters.dense_bordered_factorizations > 0);
    // Each corrector iteration still calls `factor` once (it fails on the plateau, then the
    // dense bordered LU takes over).
    assert_eq!(
        branch.counters.work.factorizations,
        branch.counters.corrector_iterations
    );
    assert_eq!(
        branch.termination,
        ContinuationTermination::MaxPoints { points: 80 }
    );

    // Without it the factorization reports the singular Jacobian and the run stops at the
    // corner with the solver's error in the termination.
    let mut problem = plateau();
    let branch = Continuation::new(&mut problem, &mut solver, &[0.5], 0.5, options)
        .unwrap()
        .run();
    let last = branch.points.last().unwrap();
    println!("without fallback: {:?}", branch.termination);
    assert!(last.state[0] <= 1.0 + 1e-12 && last.state[0] > 0.9);
    let failure = match &branch.termination {
        ContinuationTermination::StepTooSmall { failure, .. }
        | ContinuationTermination::TooManyFailures { failure, .. } => failure.clone(),
        other => panic!("unexpected termination {other:?}"),
    };
    assert!(matches!(
        failure,
        CorrectorFailure::LinearSolve {
            error: LinearSolveError::Singular { .. },
            ..
        }
    ));
    assert_eq!(problem.parameter(), last.parameter);
}

#[test]
fn step_halving_ends_with_step_too_small_where_the_residual_turns_nan() {
    let mut problem = ends_at_one();
    let mut solver = FaerDenseLu::new();
    let options = ContinuationOptions {
        max_consecutive_failures: 100,
        ..Default::default()
    };
    let branch = Continuation::new(&mut problem, &mut solver, &[0.5], 0.5, options.clone())
        .unwrap()
        .run();
    println!("{}", branch.termination);
    assert!(branch.termination.to_string().contains("step too small"));
    let ContinuationTermination::StepTooSmall {
        parameter,
        step,
        residual_norm,
        failure,
    } = branch.termination.clone()
    else {
        panic!("{:?}", branch.termination);
    };
    // The last accepted point is below 1 and closer to it than one minimum step (measured
    // in the θ-norm: a parameter change of min_step/sqrt(θ (1 + 1)) per unit step along x = p).
    let last = branch.points.last().unwrap();
    assert_eq!(parameter, last.parameter);
    assert!(
        parameter <= 1.0 && parameter > 1.0 - options.min_step,
        "{parameter}"
    );
    assert_eq!(step, options.min_step);
    assert_eq!(residual_norm, f64::INFINITY);
    assert_eq!(failure, CorrectorFailure::NonFinite { iteration: 0 });
    assert!(branch.counters.rejected_steps > 0);
    // Rolled back: the problem's parameter is the last accepted one, not the rejected one.
    assert_eq!(problem.parameter(), last.parameter);
    for q in &branch.points {
        assert!((q.state[0] - q.parameter).abs() < 1e-12);
    }

    // Started exactly at the end of the domain, every step fails. Halving from the initial
    // 0.01: 0.005, 0.0025, then 0.00125 is clamped to min_step = 0.002; the attempt at
    // 0.002 fails too, and so do the two corner passes (state hyperplane, next parameter):
    // six rejected steps, StepTooSmall at 0.002.
    let mut problem = ends_at_one();
    let branch = Continuation::new(&mut problem, &mut solver, &[1.0], 1.0, options)
        .unwrap()
        .run();
    assert_eq!(branch.points.len(), 1);
    assert_eq!(branch.counters.rejected_steps, 6);
    assert_eq!(branch.counters.corner_passes, 0);
    assert!(matches!(
        branch.termination,
        ContinuationTermination::StepTooSmall { parameter, step, .. } if parameter == 1.0 && step == 0.002
    ));
    // With the default (NLvib) limit of 3 failures in a row: 0.01, 0.005, 0.0025 fail and
    // the run stops with TooManyFailures at step 0.0025.
    let mut problem = ends_at_one();
    let branch = Continuation::new(
        &mut problem,
        &mut solver,
        &[1.0],
        1.0,
        ContinuationOptions::default(),
    )
    .unwrap()
    .run();
    assert_eq!(
        branch.termination,
        ContinuationTermination::TooManyFailures {
            parameter: 1.0,
            step: 0.0025,
            failures: 3,
            residual_norm: f64::INFINITY,
            failure: CorrectorFailure::NonFinite { iteration: 0 },
        }
    );
    assert_eq!(problem.parameter(), 1.0);
}

#[test]
fn a_run_never_spends_more_corrector_iterations_than_its_budget() {
    // The unlimited S-curve branch is the reference: a budget only cuts it short, so its
    // points are a prefix of the reference's, and a budget at least the reference's total
    // changes nothing.
    let options = |budget: Option<usize>| ContinuationOptions {
        parameter_min: -1.0,
        parameter_max: 1.0,
        max_total_corrector_iterations: budget,
        ..Default::default()
    };
    let run = |budget: Option<usize>| {
        let mut problem = s_curve();
        let mut solver = FaerDenseLu::new();
        Continuation::new(&mut problem, &mut solver, &[-1.3], -1.0, options(budget))
            .unwrap()
            .run()
    };
    let reference = run(None);
    let total = reference.counters.corrector_iterations as usize;
    assert!(total > 20, "{total}");
    assert_eq!(run(Some(total)), reference);
    // The start takes its own iterations: a smaller budget is a start that did not
    // converge, a typed termination and no point.
    let start = reference.points[0].iterations;
    assert!(start > 1, "{start}");
    let mut problem = s_curve();
    let mut solver = FaerDenseLu::new();
    let branch = Continuation::new(&mut problem, &mut solver, &[-1.3], -1.0, options(Some(1)))
        .unwrap()
        .run();
    assert!(branch.points.is_empty());
    assert!(
        matches!(
            branch.termination,
            ContinuationTermination::StartFailed {
                failure: CorrectorFailure::MaxIterations { iterations: 1, .. },
                ..
            }
        ),
        "{:?}",
        branch.termination
    );
    for budget in [start, start + 1, start + 4, total / 3, total / 2, total - 1] {
        let branch = run(Some(budget));
        assert!(
            branch.counters.corrector_iterations as usize <= budget,
            "{budget}: {}",
            branch.counters.corrector_iterations
        );
        let last = branch.points.last().unwrap().parameter;
        match branch.termination {
            ContinuationTermination::IterationBudgetSpent {
                parameter,
                budget: b,
            } => {
                assert_eq!((parameter, b), (last, budget));
                assert!(branch.points.len() < reference.points.len());
            }
            // The budget ran out in the re-solve of the point past the bound: that point
            // is kept where the step put it (as when the re-solve fails for any reason).
            ContinuationTermination::ReachedBound { parameter, bound } => {
                assert_eq!(budget, total - 1);
                assert_eq!((parameter, bound), (last, 1.0));
                assert!(parameter > 1.0);
            }
            ref other => panic!("{budget}: {other:?}"),
        }
        let compared = branch.points.len().min(reference.points.len() - 1);
        for (cut, full) in branch.points[..compared].iter().zip(&reference.points) {
            assert_eq!(cut, full);
        }
    }

    // A run that fails for good and restarts: each failing attempt, corner pass and
    // segment start counts. Without a budget it spends far more than 30 iterations on the
    // restarts at the end of the branch (`x - p = 0` up to `p = 1`, no root beyond:
    // `x^2 + p = 0`); with one it stops at 30.
    let failing = |budget: Option<usize>| {
        let mut problem = Closure {
            n: 1,
            p: 0.0,
            f: Box::new(|x, p, out| out[0] = if p > 1.0 { x[0] * x[0] + p } else { x[0] - p }),
            j: Box::new(|x, p, jac| jac[(0, 0)] = if p > 1.0 { 2.0 * x[0] } else { 1.0 }),
            fp: Some(Box::new(|_, p, out| {
                out[0] = if p > 1.0 { 1.0 } else { -1.0 }
            })),
        };
        let mut solver = FaerDenseLu::new();
        let options = ContinuationOptions {
            max_consecutive_failures: 8,
            restarts: Some(RestartPolicy::default()),
            max_total_corrector_iterations: budget,
            ..Default::default()
        };
        Continuation::new(&mut problem, &mut solver, &[0.9], 0.9, options)
            .unwrap()
            .run()
    };
    let unlimited = failing(None);
    assert!(unlimited.counters.corrector_iterations > 60);
    let limited = failing(Some(30));
    assert!(limited.counters.corrector_iterations <= 30);
    assert!(matches!(
        limited.termination,
        ContinuationTermination::IterationBudgetSpent { budget: 30, .. }
    ));

    // No budget of zero iterations: the error names the field.
    let mut problem = s_curve();
    let mut solver = FaerDenseLu::new();
    let error = Continuation::new(&mut problem, &mut solver, &[-1.3], -1.0, options(Some(0)))
        .err()
        .unwrap();
    assert_eq!(
        error,
        ContinuationError::InvalidOption {
            name: "max_total_corrector_iterations",
            value: 0.0,
            allowed: ">= 1"
        }
    );
}

#[test]
fn natural_sweep_jumps_at_the_fold_where_arclength_follows_the_branch() {
    // Sweep p on the S-curve from the lower branch: past the fold p = 2/(3√3) the lower
    // branch no longer exists. Newton from the previous solution either stalls near the
    // local minimum of |F|^2 at the fold x = -1/√3 (the line search cannot leave it; full
    // steps cycle around it) or overshoots through the near-zero slope and lands on the
    // upper branch. Which one happens depends on rounding-level details of the previous
    // point (full-step Newton on a cubic is chaotic there), so both are accepted; neither
    // follows the branch around the fold.
    let parameters: Vec<f64> = (0..=40).map(|i| -1.0 + 0.05 * i as f64).collect();
    let mut solver = FaerDenseLu::new();
    let below = -1.0 / 3f64.sqrt();
    for globalization in [Globalization::None, Globalization::non_monotone()] {
        let mut problem = s_curve();
        let options = NewtonOptions {
            globalization,
            ..Default::default()
        };
        let mut newton = NewtonSolver::new(options).unwrap();
        let sweep = natural_sweep(&mut problem, &[-1.3], &parameters, |p, x| {
            newton.solve(p, &mut solver, x)
        })
        .unwrap();
        let xs: Vec<f64> = sweep.points.iter().map(|q| q.state[0]).collect();
        let jumps: Vec<usize> = (1..xs.len())
            .filter(|&i| (xs[i] - xs[i - 1]).abs() > 0.5)
            .collect();
        println!(
            "sweep ({globalization:?}): {} points, jumps at {jumps:?}, failure {:?}",
            xs.len(),
            sweep.failure
        );
        // Every solved point is a root (Newton's tolerance 1e-10 on |F|).
        for q in &sweep.points {
            let x = q.state[0];
            assert!((x.powi(3) - x - q.parameter).abs() <= 1e-10);
        }
        if let Some(f) = &sweep.failure {
            // Failed at the first grid parameter past the fold, after following the lower
            // branch up to the last one before it.
            assert!(jumps.is_empty());
            assert!(f.parameter > FOLD_S && f.parameter - 0.05 < FOLD_S, "{f:?}");
            assert!(xs.iter().all(|&x| x < below));
        } else {
            // Jumped exactly once, between the parameters that bracket the fold, from the
            // lower branch (x < -1/√3) to the upper one (x > 1/√3).
            assert_eq!(jumps.len(), 1);
            let i = jumps[0];
            assert!(parameters[i - 1] < FOLD_S && parameters[i] > FOLD_S);
            assert!(xs[i - 1] < below && xs[i] > -below);
        }
    }
    // The pseudo-arclength branch over the same range moves continuously: the predictor
    // moves at most max_step = 0.05 in the θ-norm (0.071 Euclidean for θ = 1/2, n = 1) and
    // the corrector moves orthogonally to it by much less, so 0.1 bounds the Euclidean
    // distance between consecutive points.
    let branch = s_curve_branch();
    for w in branch.points.windows(2) {
        let d = (w[1].state[0] - w[0].state[0]).hypot(w[1].parameter - w[0].parameter);
        assert!(d < 0.1, "{d}");
    }
    assert_eq!(fold_count(&branch), 2);
}

#[test]
fn every_continuation_point_resolved_by_plain_newton_stays_put() {
    // Re-solve each point at its own parameter, from itself, with the library's Newton
    // driver and a tolerance 100x tighter than the continuation's, so that a Newton step is
    // taken: the correction is about |J^{-1}| |F| <= 1e-10 / σ_min(J).
    let strict = PolyalgorithmOptions {
        tolerances: Tolerances::absolute(1e-12),
        ..Default::default()
    };
    let mut solver = FaerDenseLu::new();
    let mut worst = [0.0_f64; 2];
    for (k, (branch, mut problem)) in [(duffing_branch(), duffing()), (s_curve_branch(), s_curve())]
        .into_iter()
        .enumerate()
    {
        for q in &branch.points {
            let mut x = q.state.clone();
            problem.set_parameter(q.parameter);
            let report = polyalgorithm::solve(&mut problem, &mut solver, &mut x, &strict).unwrap();
            assert!(
                report.converged(),
                "p = {}: {:?}",
                q.parameter,
                report.termination
            );
            // A step is taken wherever the point's |F| exceeds 1e-12.
            assert!(report.iterations >= 1 || q.residual_norm <= 1e-12);
            let moved = x
                .iter()
                .zip(&q.state)
                .map(|(a, b)| (a - b).powi(2))
                .sum::<f64>()
                .sqrt();
            worst[k] = worst[k].max(moved);
            assert!(moved < 1e-8, "p = {}: moved {moved}", q.parameter);
        }
    }
    println!(
        "largest move under re-solve: Duffing {:e}, S-curve {:e}",
        worst[0], worst[1]
    );
}

/// `atan(x) - p = 0`: plain Newton from |x - tan p| large overshoots and diverges (the
/// classic example); the branch is x = tan(p).
fn arctangent() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0].atan() - p),
        j: Box::new(|x, _, jac| jac[(0, 0)] = 1.0 / (1.0 + x[0] * x[0])),
        fp: Some(Box::new(|_, _, out| out[0] = -1.0)),
    }
}

#[test]
fn corrector_line_search_rescues_a_far_start_that_full_steps_cannot() {
    let options = ContinuationOptions {
        parameter_min: 0.0,
        parameter_max: 1.0,
        ..Default::default()
    };
    let mut solver = FaerDenseLu::new();
    // Full Newton steps from x = 3 at p = 0 diverge (|x| grows each step and overflows).
    let mut problem = arctangent();
    let mut far =
        Continuation::new(&mut problem, &mut solver, &[3.0], 0.0, options.clone()).unwrap();
    assert_eq!(far.next(), None);
    assert!(
        matches!(
            far.termination(),
            Some(ContinuationTermination::StartFailed { .. })
        ),
        "{:?}",
        far.termination()
    );
    // With backtracking the start converges to x = 0 and the branch follows x = tan(p).
    let mut problem = arctangent();
    let branch = Continuation::new(
        &mut problem,
        &mut solver,
        &[3.0],
        0.0,
        ContinuationOptions {
            corrector_line_search: Some(Default::default()),
            ..options
        },
    )
    .unwrap()
    .run();
    // |F| <= 1e-10 and |dF/dx| = 1/(1 + x^2) >= 1/(1 + tan(1)^2) ≈ 0.29: |x - tan p| < 4e-10.
    for q in &branch.points {
        assert!((q.state[0] - q.parameter.tan()).abs() < 4e-10);
    }
    assert_eq!(branch.points.last().unwrap().parameter, 1.0);
    assert!(branch.counters.work.line_search_backtracks > 0);
    println!(
        "atan: {} points, counters {:?}",
        branch.points.len(),
        branch.counters
    );
}

#[test]
fn bad_input_is_a_typed_error_with_the_numbers() {
    let mut problem = s_curve();
    let mut solver = FaerDenseLu::new();
    let bad = |o: ContinuationOptions| o.validate().unwrap_err();
    assert!(matches!(
        bad(ContinuationOptions { theta: 1.0, ..Default::default() }),
        ContinuationError::InvalidOption { name: "theta", value, .. } if value == 1.0
    ));
    // Each case spoils the default options; the error names the field.
    type Spoil = fn(&mut ContinuationOptions);
    let cases: [(Spoil, &str); 4] = [
        (|o| o.initial_step = 1.0, "initial_step"),
        (|o| o.min_step = f64::NAN, "min_step"),
        (
            |o| (o.parameter_min, o.parameter_max) = (2.0, 1.0),
            "parameter_max",
        ),
        (|o| o.max_points = 0, "max_points"),
    ];
    for (spoil, field) in cases {
        let mut options = ContinuationOptions::default();
        spoil(&mut options);
        assert!(
            matches!(bad(options), ContinuationError::InvalidOption { name, .. } if name == field),
            "{field}"
        );
    }
    assert!(ContinuationOptions::with_step(0.1).validate().is_ok());
    assert!(matches!(
        Continuation::new(
            &mut problem,
            &mut solver,
            &[1.0, 2.0],
            0.0,
            Default::default()
        )
        .err(),
        Some(ContinuationError::DimensionMismatch {
            expected: 1,
            found: 2
        })
    ));
    let bounded = ContinuationOptions {
        parameter_min: 0.0,
        parameter_max: 1.0,
        ..Default::default()
    };
    assert!(matches!(
        Continuation::new(&mut problem, &mut solver, &[1.0], 1.5, bounded).err(),
        Some(ContinuationError::InvalidStart { parameter, .. }) if parameter == 1.5
    ));
    // x^2 + 1 + p^2 has no real root: the start cannot be corrected; the iterator yields
    // nothing and says why.
    let mut none = Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0] * x[0] + 1.0 + p * p),
        j: Box::new(|x, _, jac| jac[(0, 0)] = 2.0 * x[0]),
        fp: None,
    };
    let mut it =
        Continuation::new(&mut none, &mut solver, &[1.0], 0.0, Default::default()).unwrap();
    assert!(it.next().is_none());
    assert!(matches!(
        it.termination(),
        Some(ContinuationTermination::StartFailed { parameter, .. }) if *parameter == 0.0
    ));
    assert!(it.next().is_none());
}
