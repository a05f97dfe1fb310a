//! Continuation through the traits alone: a structured (diagonal) Jacobian with its own
//! solver against the dense one, a state scale against continuing the rescaled problem, and
//! a problem's own error ending the branch with it.

mod common;

use common::branches::*;
use faer::Mat;
use semismooth::continuation::{
    Continuation, ContinuationError, ContinuationOptions, ContinuationTermination, CorrectorFailure,
};
use semismooth::linalg::{FaerDenseLu, LinearSolveError};
use semismooth::{EvaluationError, GeneralizedJacobian, ParameterDependent, Residual};

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
