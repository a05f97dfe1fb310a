//! Pseudo-arclength continuation on problems whose branches are known independently:
//! closed forms (circle, S-curve, piecewise-linear kink, plateau), an implicit frequency
//! response (Duffing first-harmonic balance) whose folds are located by the cubic's
//! discriminant, and a natural-parameter sweep that jumps where the arclength follows.

use faer::Mat;
use semismooth::continuation::{
    natural_sweep, Branch, Continuation, ContinuationError, ContinuationEvent, ContinuationOptions,
    ContinuationTermination, CorrectorFailure, Direction, Predictor, RestartPolicy,
};
use semismooth::linalg::{FaerDenseLu, LinearSolveError};
use semismooth::newton::{Globalization, NewtonOptions, NewtonSolver};
use semismooth::polyalgorithm::{self, PolyalgorithmOptions};
use semismooth::{EvaluationError, GeneralizedJacobian, ParameterDependent, Residual};

type ResidualFn = Box<dyn Fn(&[f64], f64, &mut [f64])>;
type JacobianFn = Box<dyn Fn(&[f64], f64, &mut Mat<f64>)>;

/// A test problem `F(x, p)` from closures, with an analytic `F_p` when given (the trait's
/// central difference otherwise), counting `set_parameter` calls.
struct Closure {
    n: usize,
    p: f64,
    f: ResidualFn,
    j: JacobianFn,
    fp: Option<ResidualFn>,
}

impl Residual for Closure {
    fn dim(&self) -> usize {
        self.n
    }
    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        (self.f)(x, self.p, out);
        Ok(())
    }
}

impl GeneralizedJacobian for Closure {
    type Jacobian = Mat<f64>;
    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(self.n, self.n)
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        (self.j)(x, self.p, jac);
        Ok(())
    }
}

impl ParameterDependent for Closure {
    fn parameter(&self) -> f64 {
        self.p
    }
    fn set_parameter(&mut self, p: f64) {
        self.p = p;
    }
    fn residual_parameter_derivative(
        &mut self,
        x: &[f64],
        out: &mut [f64],
        minus: &mut [f64],
    ) -> Result<(), EvaluationError> {
        match &self.fp {
            Some(fp) => fp(x, self.p, out),
            None => {
                let p = self.p;
                let h = 1e-7 * (1.0 + p.abs());
                (self.f)(x, p + h, out);
                (self.f)(x, p - h, minus);
                for (o, m) in out.iter_mut().zip(minus.iter()) {
                    *o = (*o - m) / (2.0 * h);
                }
            }
        }
        Ok(())
    }
}

/// `x^3 - x - p = 0`: folds at `x = ±1/√3`, `p = ∓2/(3√3)`.
fn s_curve() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0].powi(3) - x[0] - p),
        j: Box::new(|x, _, jac| jac[(0, 0)] = 3.0 * x[0] * x[0] - 1.0),
        fp: Some(Box::new(|_, _, out| out[0] = -1.0)),
    }
}

/// `x^2 + p^2 - 1 = 0`: folds at `p = ±1`.
fn circle() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0] * x[0] + p * p - 1.0),
        j: Box::new(|x, _, jac| jac[(0, 0)] = 2.0 * x[0]),
        fp: Some(Box::new(|_, p, out| out[0] = 2.0 * p)),
    }
}

/// Duffing `u'' + 2 ζ u' + u + γ u^3 = f cos(ω t)`, one harmonic `u = a cos + b sin`,
/// parameter `ω`; `F_p` by the trait's central difference.
const ZETA: f64 = 0.05;
const GAMMA: f64 = 1.0;
const FORCE: f64 = 0.1;
fn duffing() -> Closure {
    Closure {
        n: 2,
        p: 0.0,
        f: Box::new(|x, w, out| {
            let k = 1.0 - w * w + 0.75 * GAMMA * (x[0] * x[0] + x[1] * x[1]);
            out[0] = k * x[0] + 2.0 * ZETA * w * x[1] - FORCE;
            out[1] = -2.0 * ZETA * w * x[0] + k * x[1];
        }),
        j: Box::new(|x, w, jac| {
            let (a, b) = (x[0], x[1]);
            let k = 1.0 - w * w + 0.75 * GAMMA * (a * a + b * b);
            let c = 1.5 * GAMMA;
            jac[(0, 0)] = k + c * a * a;
            jac[(0, 1)] = c * a * b + 2.0 * ZETA * w;
            jac[(1, 0)] = c * a * b - 2.0 * ZETA * w;
            jac[(1, 1)] = k + c * b * b;
        }),
        fp: None,
    }
}

/// `x + k max(0, x - 1) - p = 0`: slope 1 below the kink at `x = 1`, `1/(1+k)` above.
const KINK: f64 = 4.0;
fn kink() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0] + KINK * (x[0] - 1.0).max(0.0) - p),
        j: Box::new(|x, _, jac| jac[(0, 0)] = 1.0 + if x[0] > 1.0 { KINK } else { 0.0 }),
        fp: Some(Box::new(|_, _, out| out[0] = -1.0)),
    }
}

fn kink_closed_form(p: f64) -> f64 {
    if p <= 1.0 {
        p
    } else {
        1.0 + (p - 1.0) / (1.0 + KINK)
    }
}

/// `p - min(max(x, 0), 1) = 0`: `x = p` on `(0, 1)`, then the vertical segment `p = 1`,
/// `x > 1`, where the Jacobian is exactly zero (singular) and only the bordered system is
/// regular.
fn plateau() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = p - x[0].clamp(0.0, 1.0)),
        j: Box::new(|x, _, jac| jac[(0, 0)] = if x[0] > 0.0 && x[0] < 1.0 { -1.0 } else { 0.0 }),
        fp: Some(Box::new(|_, _, out| out[0] = 1.0)),
    }
}

/// `x - p = 0`, but the residual is NaN for `p > 1` (a model outside its domain).
fn ends_at_one() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = if p > 1.0 { f64::NAN } else { x[0] - p }),
        j: Box::new(|_, _, jac| jac[(0, 0)] = 1.0),
        fp: Some(Box::new(|_, _, out| out[0] = -1.0)),
    }
}

fn fold_count(branch: &Branch) -> usize {
    branch
        .events
        .iter()
        .filter(|e| matches!(e, ContinuationEvent::Fold { .. }))
        .count()
}

/// The counters identity of the block elimination: one Jacobian and one factorization per
/// corrector iteration, two solves (`J a = F_p`, `J b = F`) per factorization.
fn assert_one_factorization_per_iteration(branch: &Branch) {
    let c = branch.counters;
    let accepted: u64 = branch.points.iter().map(|q| q.iterations as u64).sum();
    assert_eq!(c.corrector_iterations, accepted + c.rejected_iterations);
    assert_eq!(c.work.factorizations, c.corrector_iterations);
    assert_eq!(c.work.jacobian_evaluations, c.corrector_iterations);
    assert_eq!(c.parameter_derivative_evaluations, c.corrector_iterations);
    assert_eq!(c.work.linear_solves, 2 * c.work.factorizations);
    // Without line search: one residual per iteration plus the final convergence check of
    // each attempt that did not stop on a non-finite value.
    assert!(c.work.residual_evaluations >= c.corrector_iterations);
    assert_eq!(c.dense_bordered_factorizations, 0);
}

const FOLD_S: f64 = 0.384_900_179_459_750_5; // 2 / (3 √3)

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
    let mut problem = s_curve();
    let mut solver = FaerDenseLu::new();
    let options = ContinuationOptions {
        parameter_min: -1.0,
        parameter_max: 1.0,
        direction: Direction::Decreasing,
        ..Default::default()
    };
    let branch = Continuation::new(&mut problem, &mut solver, &[1.3], 1.0, options)
        .unwrap()
        .run();
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
    let mut problem = s_curve();
    let options = ContinuationOptions {
        parameter_min: -1.0,
        direction: Direction::Decreasing,
        ..Default::default()
    };
    let branch = Continuation::new(&mut problem, &mut solver, &[-1.3], -1.0, options)
        .unwrap()
        .run();
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
    let mut problem = s_curve();
    let mut solver = FaerDenseLu::new();
    let options = ContinuationOptions {
        parameter_min: -1.0,
        parameter_max: 1.0,
        ..Default::default()
    };
    Continuation::new(&mut problem, &mut solver, &[-1.3], -1.0, options)
        .unwrap()
        .run()
}

fn duffing_branch() -> Branch {
    let mut problem = duffing();
    let mut solver = FaerDenseLu::new();
    let options = ContinuationOptions {
        parameter_min: 0.5,
        parameter_max: 2.0,
        ..Default::default()
    };
    Continuation::new(&mut problem, &mut solver, &[0.13, 0.0], 0.5, options)
        .unwrap()
        .run()
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
    let mut problem = kink();
    let mut solver = FaerDenseLu::new();
    let options = ContinuationOptions {
        parameter_min: 0.0,
        parameter_max: 3.0,
        ..Default::default()
    };
    let branch = Continuation::new(&mut problem, &mut solver, &[0.2], 0.2, options)
        .unwrap()
        .run();
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
        absolute_tolerance: 1e-12,
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

/// A structured (diagonal) Jacobian that cannot be assembled densely, with its own solver:
/// the continuation must work through `LinearSolve` alone.
struct Diagonal(Vec<f64>);

struct DiagonalSolver {
    diagonal: Vec<f64>,
}

impl semismooth::Factorize<Diagonal> for DiagonalSolver {
    fn factor(&mut self, jac: &Diagonal) -> Result<(), LinearSolveError> {
        let max_pivot = jac.0.iter().fold(0.0_f64, |m, d| m.max(d.abs()));
        if let Some(index) = jac.0.iter().position(|d| *d == 0.0 || !d.is_finite()) {
            return Err(LinearSolveError::Singular {
                index,
                pivot: jac.0[index].abs(),
                max_pivot,
            });
        }
        self.diagonal.clone_from(&jac.0);
        Ok(())
    }
}

impl semismooth::LinearSolve for DiagonalSolver {
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        for (r, d) in rhs.iter_mut().zip(&self.diagonal) {
            *r /= d;
        }
        Ok(())
    }
}

/// `F_0 = x_0^3 - x_0 - p` (the S-curve, which makes the folds) and, for `i >= 1`,
/// `F_i = x_i^3 + (1 + i/n) x_i - p` (monotone in `x_i`, one root for every `p`).
struct DecoupledCurves {
    n: usize,
    p: f64,
}

impl DecoupledCurves {
    fn coefficient(&self, i: usize) -> f64 {
        if i == 0 {
            -1.0
        } else {
            1.0 + i as f64 / self.n as f64
        }
    }
}

impl Residual for DecoupledCurves {
    fn dim(&self) -> usize {
        self.n
    }
    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        for (i, (o, xi)) in out.iter_mut().zip(x).enumerate() {
            *o = xi.powi(3) + self.coefficient(i) * xi - self.p;
        }
        Ok(())
    }
}

impl ParameterDependent for DecoupledCurves {
    fn parameter(&self) -> f64 {
        self.p
    }
    fn set_parameter(&mut self, p: f64) {
        self.p = p;
    }
}

impl GeneralizedJacobian for DecoupledCurves {
    type Jacobian = Diagonal;
    fn new_jacobian(&self) -> Diagonal {
        Diagonal(vec![0.0; self.n])
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut Diagonal) -> Result<(), EvaluationError> {
        for (i, (d, xi)) in jac.0.iter_mut().zip(x).enumerate() {
            *d = 3.0 * xi * xi + self.coefficient(i);
        }
        Ok(())
    }
}

/// The same problem with a dense Jacobian, to solve with the dense LU.
struct DenseDecoupled(DecoupledCurves);

impl Residual for DenseDecoupled {
    fn dim(&self) -> usize {
        self.0.n
    }
    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        self.0.residual(x, out)
    }
}

impl ParameterDependent for DenseDecoupled {
    fn parameter(&self) -> f64 {
        self.0.p
    }
    fn set_parameter(&mut self, p: f64) {
        self.0.p = p;
    }
}

impl GeneralizedJacobian for DenseDecoupled {
    type Jacobian = Mat<f64>;
    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(self.0.n, self.0.n)
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        let mut d = self.0.new_jacobian();
        self.0.jacobian(x, &mut d).unwrap();
        for i in 0..self.0.n {
            for j in 0..self.0.n {
                jac[(i, j)] = if i == j { d.0[i] } else { 0.0 };
            }
        }
        Ok(())
    }
}

#[test]
fn structured_jacobian_branch_equals_the_dense_one_and_passes_the_folds() {
    let n = 40;
    let options = ContinuationOptions {
        parameter_min: -1.0,
        parameter_max: 1.0,
        ..Default::default()
    };
    // Start at p = -1: x_0 on the lower branch; x_i (i >= 1) from Newton-free bisection.
    let root = |c: f64, p: f64| {
        let (mut lo, mut hi) = (-2.0_f64, 2.0_f64);
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if mid.powi(3) + c * mid - p > 0.0 {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        0.5 * (lo + hi)
    };
    let mut structured = DecoupledCurves { n, p: -1.0 };
    let x0: Vec<f64> = (0..n)
        .map(|i| {
            if i == 0 {
                -1.3
            } else {
                root(structured.coefficient(i), -1.0)
            }
        })
        .collect();
    let mut diagonal_solver = DiagonalSolver {
        diagonal: Vec::new(),
    };
    let branch = Continuation::new(
        &mut structured,
        &mut diagonal_solver,
        &x0,
        -1.0,
        options.clone(),
    )
    .unwrap()
    .run();
    let mut dense = DenseDecoupled(DecoupledCurves { n, p: -1.0 });
    let mut lu = FaerDenseLu::new();
    let reference = Continuation::new(&mut dense, &mut lu, &x0, -1.0, options)
        .unwrap()
        .run();
    // Same arithmetic up to the LU's rounding on a diagonal matrix: the branches agree
    // point by point to 1e-12 (on O(1) values).
    assert_eq!(branch.points.len(), reference.points.len());
    for (a, b) in branch.points.iter().zip(&reference.points) {
        assert!((a.parameter - b.parameter).abs() < 1e-12);
        for (u, v) in a.state.iter().zip(&b.state) {
            assert!((u - v).abs() < 1e-12);
        }
    }
    // Components i >= 1 are the unique real roots of their cubics (bisection, 1e-12 after
    // 200 halvings of [-2, 2]; corrector residual 1e-10 over slope >= 1 gives 1e-10).
    let probe = DecoupledCurves { n, p: 0.0 };
    for q in &branch.points {
        for i in 1..n {
            let exact = root(probe.coefficient(i), q.parameter);
            assert!((q.state[i] - exact).abs() < 1e-9);
        }
    }
    let folds = branch.fold_parameters();
    println!(
        "structured n = {n}: {} points, folds {folds:?}",
        branch.points.len()
    );
    assert_eq!(folds.len(), 2);
    // Fold tolerance as for the scalar S-curve (the x_0 component dominates p(s) there).
    assert!((folds[0] - FOLD_S).abs() < 1e-4 && (folds[1] + FOLD_S).abs() < 1e-4);
    assert_one_factorization_per_iteration(&branch);
}

#[test]
fn state_scale_equals_continuing_the_rescaled_problem() {
    // With x = S z, the θ-product Σ a_i b_i / s_i^2 on x is the plain product on z: the
    // branch of F with state_scale S must be the branch of G(z, ω) = F(S z, ω) without
    // scale, mapped by x = S z. S = (0.3, 3) makes the two unknowns differ by 100 in
    // weight, so a wrong weighting would change the steps and the points.
    let scale = [0.3, 3.0];
    let residual = duffing().f;
    let jacobian = duffing().j;
    let mut rescaled = Closure {
        n: 2,
        p: 0.0,
        f: Box::new(move |z, w, out| residual(&[scale[0] * z[0], scale[1] * z[1]], w, out)),
        j: Box::new(move |z, w, jac| {
            jacobian(&[scale[0] * z[0], scale[1] * z[1]], w, jac);
            for i in 0..2 {
                for (j, s) in scale.iter().enumerate() {
                    jac[(i, j)] *= s;
                }
            }
        }),
        fp: None,
    };
    let options = ContinuationOptions {
        parameter_min: 0.5,
        parameter_max: 2.0,
        ..Default::default()
    };
    let mut solver = FaerDenseLu::new();
    let x0 = [0.13, 0.0];
    let z0 = [x0[0] / scale[0], x0[1] / scale[1]];
    let reference = Continuation::new(&mut rescaled, &mut solver, &z0, 0.5, options.clone())
        .unwrap()
        .run();
    let mut problem = duffing();
    let branch = Continuation::new(
        &mut problem,
        &mut solver,
        &x0,
        0.5,
        ContinuationOptions {
            state_scale: Some(scale.to_vec()),
            ..options
        },
    )
    .unwrap()
    .run();
    assert_eq!(branch.points.len(), reference.points.len());
    // The same Newton iterates in both coordinates up to the rounding of S z: the points
    // (of size O(1)) agree to rounding, accumulated over the 95 steps: measured 1.3e-14,
    // asserted at 1e-12. A wrong weighting changes the steps, and the points by a fraction
    // of a step (1e-3 or more).
    let mut worst = 0.0_f64;
    for (a, b) in branch.points.iter().zip(&reference.points) {
        worst = worst.max((a.parameter - b.parameter).abs());
        for ((x, z), s) in a.state.iter().zip(&b.state).zip(&scale) {
            worst = worst.max((x - s * z).abs());
        }
    }
    println!(
        "scaled vs rescaled: {} points, largest difference {worst:e}",
        branch.points.len()
    );
    assert!(worst < 1e-12, "{worst:e}");
    println!("{}", branch.termination);
    assert_eq!(branch.fold_parameters().len(), 2);
    // A scale of the wrong length is refused with the numbers.
    let mut problem = duffing();
    assert!(matches!(
        Continuation::new(
            &mut problem,
            &mut solver,
            &x0,
            0.5,
            ContinuationOptions {
                state_scale: Some(vec![1.0; 3]),
                ..Default::default()
            }
        )
        .err(),
        Some(ContinuationError::InvalidOption { name: "state_scale", value, .. }) if value == 3.0
    ));
}

/// `p + |x| = 0`: the branch `p = -|x|` turns back at a corner (`x = 0`, `p = 0`), where
/// the generalized Jacobian jumps from `-1` to `1` and no tangent exists.
fn roof() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = p + x[0].abs()),
        j: Box::new(|x, _, jac| jac[(0, 0)] = if x[0] >= 0.0 { 1.0 } else { -1.0 }),
        fp: Some(Box::new(|_, _, out| out[0] = 1.0)),
    }
}

/// Slope of [`steep_corner`]'s two pieces.
const STEEP: f64 = 20.0;

/// `x + STEEP |p| = 0`: a graph over `p` (so no fold) with a corner at `p = 0` where the
/// branch turns by nearly 180° in the `(x, p)` plane.
fn steep_corner() -> Closure {
    Closure {
        n: 1,
        p: 0.0,
        f: Box::new(|x, p, out| out[0] = x[0] + STEEP * p.abs()),
        j: Box::new(|_, _, jac| jac[(0, 0)] = 1.0),
        fp: Some(Box::new(|_, p, out| out[0] = STEEP * p.signum())),
    }
}

#[test]
fn corner_fold_of_a_piecewise_linear_branch_is_reported_within_one_step_of_the_corner() {
    let mut problem = roof();
    let mut solver = FaerDenseLu::new();
    let options = ContinuationOptions {
        parameter_min: -1.0,
        parameter_max: 1.0,
        ..Default::default()
    };
    let branch = Continuation::new(&mut problem, &mut solver, &[-1.0], -1.0, options.clone())
        .unwrap()
        .run();
    // Up the left side, over the corner, down the right side to the bound p = -1 at x = 1.
    let last = branch.points.last().unwrap();
    assert_eq!(
        branch.termination,
        ContinuationTermination::ReachedBound {
            parameter: -1.0,
            bound: -1.0
        }
    );
    assert!((last.state[0] - 1.0).abs() < 1e-12, "{}", last.state[0]);
    for point in &branch.points {
        assert!((point.parameter + point.state[0].abs()).abs() < 1e-10);
    }
    let folds = branch.fold_parameters();
    println!(
        "roof: {} points, folds {folds:?}, corner passes {}, rejected steps {}",
        branch.points.len(),
        branch.counters.corner_passes,
        branch.counters.rejected_steps
    );
    assert_eq!(folds.len(), 1, "{folds:?}");
    // The fold is at p = 0; the neighbouring points are within one (θ-norm) step, i.e.
    // |Δp| <= max_step / sqrt(1 - θ), of it, and the report is never past the corner.
    let reach = options.max_step / (1.0 - options.theta).sqrt();
    assert!(folds[0] <= 1e-12 && folds[0] > -reach, "{}", folds[0]);
    let ContinuationEvent::Fold { index, .. } = branch.events[0] else {
        unreachable!()
    };
    // The highest point of the branch is the fold's extreme point or its neighbour.
    let top = branch
        .points
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.parameter.total_cmp(&b.1.parameter))
        .unwrap()
        .0;
    assert!(index.abs_diff(top) <= 1, "fold at {index}, top at {top}");
    assert!(branch.counters.corner_passes >= 1);
}

#[test]
fn sharp_corner_of_a_graph_over_the_parameter_is_passed_without_a_fold() {
    for predictor in [Predictor::Secant, Predictor::Tangent] {
        let mut problem = steep_corner();
        let mut solver = FaerDenseLu::new();
        let options = ContinuationOptions {
            parameter_min: -1.0,
            parameter_max: 1.0,
            predictor,
            ..Default::default()
        };
        let branch = Continuation::new(&mut problem, &mut solver, &[-STEEP], -1.0, options)
            .unwrap()
            .run();
        let parameters = branch.parameters();
        println!(
            "{predictor:?}: {} points, corner passes {}, rejected steps {}",
            parameters.len(),
            branch.counters.corner_passes,
            branch.counters.rejected_steps
        );
        // The branch is a graph over p: p increases at every point, to the bound p = 1.
        assert!(parameters.windows(2).all(|w| w[1] > w[0]));
        assert_eq!(
            branch.termination,
            ContinuationTermination::ReachedBound {
                parameter: 1.0,
                bound: 1.0
            }
        );
        assert!((branch.points.last().unwrap().state[0] + STEEP).abs() < 1e-10);
        assert_eq!(fold_count(&branch), 0, "{:?}", branch.events);
        assert!(branch.counters.corner_passes >= 1);
    }
    // Pseudo-arclength alone cannot cut the far side of a corner turning by more than 90°
    // in the θ-norm: without the corner passes the run stops there.
    let mut problem = steep_corner();
    let mut solver = FaerDenseLu::new();
    let options = ContinuationOptions {
        parameter_min: -1.0,
        parameter_max: 1.0,
        pass_corners: false,
        ..Default::default()
    };
    let branch = Continuation::new(&mut problem, &mut solver, &[-STEEP], -1.0, options)
        .unwrap()
        .run();
    let end = branch.points.last().unwrap().parameter;
    assert!(end < 0.0 && end > -0.01, "{:?}", branch.termination);
    assert!(matches!(
        branch.termination,
        ContinuationTermination::TooManyFailures { .. }
            | ContinuationTermination::StepTooSmall { .. }
    ));
}

#[test]
fn fold_detector_confirms_reversals_and_ignores_unconfirmed_tangent_flips() {
    use semismooth::continuation::FoldDetector;
    // p = sin(s) sampled every 0.3 with exact tangents: one fold at p = 1 (s = π/2).
    let mut detector = FoldDetector::new(true);
    let mut events = Vec::new();
    for k in 0..12 {
        let s = 0.3 * k as f64;
        events.extend(detector.push(s.sin(), s.cos(), 0.3));
    }
    assert_eq!(events.len(), 1, "{events:?}");
    let ContinuationEvent::Fold { index, parameter } = events[0] else {
        unreachable!()
    };
    // Between s = 1.5 (k = 5) and 1.8 (k = 6); Hermite error over h = 0.3 ~ h^4/384.
    assert_eq!(index, 6);
    assert!((parameter - 1.0).abs() < 1e-4, "{parameter}");
    // A tangent that flips sign without the parameter turning back is no fold; a reversal
    // with no sign change of the tangent (a corner) is a fold at the extreme point.
    let mut detector = FoldDetector::new(true);
    let pushed: Vec<_> = [(0.0, 1.0), (0.1, -1.0), (0.2, 1.0), (0.3, 1.0), (0.25, 1.0)]
        .iter()
        .filter_map(|&(p, t)| detector.push(p, t, 0.1))
        .collect();
    assert_eq!(
        pushed,
        vec![ContinuationEvent::Fold {
            index: 3,
            parameter: 0.3
        }]
    );
}

/// The problem's own failure, met beyond a parameter.
#[derive(Debug)]
struct FailsBeyond(f64);

impl std::fmt::Display for FailsBeyond {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cannot evaluate at p = {}", self.0)
    }
}

impl std::error::Error for FailsBeyond {}

/// `x - p = 0`, whose evaluation fails with the problem's own error beyond `p = 0.5`, or
/// with a domain error when `domain` is set.
struct Line {
    p: f64,
    domain: bool,
}

impl Residual for Line {
    fn dim(&self) -> usize {
        1
    }
    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        if self.p > 0.5 {
            return Err(if self.domain {
                EvaluationError::OutsideDomain {
                    what: "p",
                    value: self.p,
                }
            } else {
                EvaluationError::problem(FailsBeyond(self.p))
            });
        }
        out[0] = x[0] - self.p;
        Ok(())
    }
}

impl GeneralizedJacobian for Line {
    type Jacobian = Mat<f64>;
    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(1, 1)
    }
    fn jacobian(&mut self, _: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        jac[(0, 0)] = 1.0;
        Ok(())
    }
}

impl ParameterDependent for Line {
    fn parameter(&self) -> f64 {
        self.p
    }
    fn set_parameter(&mut self, p: f64) {
        self.p = p;
    }
}

/// Past `p = 0.5` a domain error only shortens the steps (the run ends after failed steps
/// just below 0.5), while the problem's own error ends the run at the first attempt that
/// meets it, with the error in the termination.
#[test]
fn the_problems_own_error_ends_the_branch_with_it() {
    let options = ContinuationOptions {
        initial_step: 0.1,
        max_step: 0.1,
        min_step: 1e-3,
        theta: 0.999,
        parameter_max: 1.0,
        ..Default::default()
    };
    let mut solver = FaerDenseLu::new();
    let mut line = Line {
        p: 0.0,
        domain: true,
    };
    let branch = Continuation::new(&mut line, &mut solver, &[0.0], 0.0, options.clone())
        .unwrap()
        .run();
    assert!(
        matches!(
            branch.termination,
            ContinuationTermination::StepTooSmall {
                failure: CorrectorFailure::Evaluation { .. },
                ..
            } | ContinuationTermination::TooManyFailures {
                failure: CorrectorFailure::Evaluation { .. },
                ..
            }
        ),
        "{:?}",
        branch.termination
    );
    assert!(branch.counters.rejected_steps >= 3);
    let mut line = Line {
        p: 0.0,
        domain: false,
    };
    let branch = Continuation::new(&mut line, &mut solver, &[0.0], 0.0, options)
        .unwrap()
        .run();
    let last = branch.points.last().unwrap().parameter;
    let ContinuationTermination::ProblemFailed { parameter, error } = &branch.termination else {
        panic!("{:?}", branch.termination);
    };
    assert_eq!(*parameter, last);
    assert!(error.downcast_ref::<FailsBeyond>().unwrap().0 > 0.5);
    assert!(last <= 0.5 && last > 0.3, "{last}");
    // Nothing after the failed attempt: one rejected step.
    assert_eq!(branch.counters.rejected_steps, 1);
    assert_eq!(line.p, last);
}
