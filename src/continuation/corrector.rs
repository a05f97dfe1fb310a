//! The corrector: the crate's Newton kernel on the bordered system `[F(x, p); N(x, p)] = 0`
//! with its direction by block elimination (or a dense LU of the bordered matrix), and the
//! θ-weighted metric in which steps, tangents and the stall test are measured.

use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{Mat, MatMut};

use super::CorrectorFailure;
use crate::iteration::kernel::{norm2, Kernel, KernelRules, NewtonSystem, Stop};
use crate::linalg::{
    check_finite_dense, check_pivots, BorderedError, BorderedSolver, LinearSolveError,
    SolveAccuracy, DEFAULT_PIVOT_THRESHOLD,
};
use crate::newton::WorkCounters;
use crate::{EvaluationError, Factorize, GeneralizedJacobian, ParameterDependent};

/// Writes a Jacobian as a dense matrix (the dense-fallback capability).
pub(super) type DenseAssembler<J> = fn(&J, MatMut<'_, f64>);

/// The θ-weighted inner product of the module documentation on `(x, p)` pairs:
/// `<(a, α), (b, β)>_θ = (θ/n) Σ a_i b_i / s_i² + (1 - θ) α β / s_p²`.
#[derive(Clone, Debug)]
pub(super) struct Metric {
    pub n: usize,
    pub theta: f64,
    /// `1 / s_i²` (empty: all ones).
    pub weights: Vec<f64>,
    /// `1 / s_p²`.
    pub parameter_weight: f64,
}

impl Metric {
    pub fn new(n: usize, theta: f64, state_scale: Option<&[f64]>, parameter_scale: f64) -> Self {
        Self {
            n,
            theta,
            weights: state_scale
                .map(|s| s.iter().map(|v| 1.0 / (v * v)).collect())
                .unwrap_or_default(),
            parameter_weight: 1.0 / (parameter_scale * parameter_scale),
        }
    }

    /// The state part `(θ/n) Σ a_i b_i / s_i²`.
    pub fn state_dot(&self, a: &[f64], b: &[f64]) -> f64 {
        let s: f64 = if self.weights.is_empty() {
            a.iter().zip(b).map(|(u, v)| u * v).sum()
        } else {
            a.iter()
                .zip(b)
                .zip(&self.weights)
                .map(|((u, v), w)| u * v * w)
                .sum()
        };
        self.theta / self.n as f64 * s
    }

    /// The parameter part `(1 - θ) α β / s_p²`.
    pub fn parameter_dot(&self, a: f64, b: f64) -> f64 {
        (1.0 - self.theta) * self.parameter_weight * a * b
    }

    /// `<(ax, ap), (bx, bp)>_θ`.
    pub fn dot(&self, ax: &[f64], ap: f64, bx: &[f64], bp: f64) -> f64 {
        self.state_dot(ax, bx) + self.parameter_dot(ap, bp)
    }

    /// `|(x, p)|_θ`.
    pub fn norm(&self, x: &[f64], p: f64) -> f64 {
        self.dot(x, p, x, p).sqrt()
    }

    /// `|y|_θ` for `y = (x, p)` stored contiguously.
    pub fn norm_joined(&self, y: &[f64]) -> f64 {
        self.norm(&y[..self.n], y[self.n])
    }

    /// θ-distance between two joined points.
    pub fn distance(&self, a: &[f64], b: &[f64]) -> f64 {
        let n = self.n;
        let dx: f64 = if self.weights.is_empty() {
            a[..n].iter().zip(b).map(|(u, v)| (u - v) * (u - v)).sum()
        } else {
            a[..n]
                .iter()
                .zip(b)
                .zip(&self.weights)
                .map(|((u, v), w)| (u - v) * (u - v) * w)
                .sum()
        };
        let dp = a[n] - b[n];
        (self.theta / n as f64 * dx + self.parameter_dot(dp, dp)).sqrt()
    }

    /// The state part of the normal of `<d, y>_θ`: `out_i = (θ/n) d_i / s_i²`.
    pub fn state_normal(&self, d: &[f64], out: &mut [f64]) {
        let theta_x = self.theta / self.n as f64;
        for (i, (o, di)) in out.iter_mut().zip(d).enumerate() {
            *o = theta_x * di * self.weights.get(i).copied().unwrap_or(1.0);
        }
    }
}

/// The extra equation `N(y) = w_x·x + w_p p - target` (with `w_x = 0` when `arclength` is
/// false: the parameter is then fixed at `target / w_p`). `w_x` lives in
/// [`Bordered::w`].
#[derive(Clone, Copy, Debug)]
pub(super) struct Constraint {
    pub arclength: bool,
    pub w_p: f64,
    pub target: f64,
}

/// A ball of the θ-metric outside which the corrector may not evaluate.
#[derive(Clone, Debug, Default)]
pub(super) struct TrustBall {
    /// Joined center `(x, p)`; empty: no ball.
    pub center: Vec<f64>,
    pub radius: f64,
}

/// A converged correction.
#[derive(Clone, Copy, Debug)]
pub(super) struct Corrected {
    pub iterations: usize,
    /// `|F(x, p)|` at the point.
    pub residual_norm: f64,
}

/// Buffers of the bordered direction, reused by every corrector iteration.
pub(super) struct Bordered<J> {
    pub jac: J,
    fp: Vec<f64>,
    /// Workspace of `F_p` (the default central difference's second residual).
    fp_scratch: Vec<f64>,
    /// The block elimination of `[[J, F_p], [w_x^T, w_p]]` (k = 1).
    border: BorderedSolver,
    /// θ-weighted constraint row `w_x`.
    pub w: Vec<f64>,
    /// The constraint row of the fixed-parameter correction (`w_x = 0`).
    zeros: Vec<f64>,
    /// Raw (unnormalised) tangent from the last iteration, length `n + 1`, with positive
    /// inner product with the constraint row.
    pub tangent: Vec<f64>,
    /// Dense bordered matrix (allocated on first fallback).
    dense: Option<Mat<f64>>,
    kernel: Kernel,
}

impl<J> Bordered<J> {
    pub fn new(n: usize, jac: J) -> Self {
        Self {
            jac,
            fp: vec![0.0; n],
            fp_scratch: vec![0.0; n],
            border: BorderedSolver::new(n, 1),
            w: vec![0.0; n],
            zeros: vec![0.0; n],
            tangent: vec![0.0; n + 1],
            dense: None,
            kernel: Kernel::default(),
        }
    }
}

/// Counts of the corrector beyond the Newton work counters.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct CorrectorCounts {
    pub parameter_derivatives: u64,
    pub dense_factorizations: u64,
    pub iterations: u64,
}

/// Why a bordered direction could not be computed.
enum BorderedFailure {
    Linear(LinearSolveError),
    SingularBorder(f64),
    Evaluation(EvaluationError),
    NonFinite,
}

impl BorderedFailure {
    /// The corrector's failure for this one at `iteration`.
    fn at(self, iteration: usize) -> CorrectorFailure {
        match self {
            Self::Linear(error) => CorrectorFailure::LinearSolve { iteration, error },
            Self::SingularBorder(pivot) => CorrectorFailure::SingularBorder { iteration, pivot },
            Self::Evaluation(error) => CorrectorFailure::Evaluation { iteration, error },
            Self::NonFinite => CorrectorFailure::NonFinite { iteration },
        }
    }
}

/// The bordered system seen by the kernel: unknowns `y = (x, p)`.
struct BorderedSystem<'a, P: GeneralizedJacobian + ?Sized, S: ?Sized> {
    problem: &'a mut P,
    solver: &'a mut S,
    ws: &'a mut Bordered<P::Jacobian>,
    fallback: Option<DenseAssembler<P::Jacobian>>,
    metric: &'a Metric,
    constraint: Constraint,
    /// The ball and the metric it is measured in.
    trust: Option<(&'a TrustBall, &'a Metric)>,
    counts: &'a mut CorrectorCounts,
}

impl<P, S> NewtonSystem for BorderedSystem<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    type Failure = BorderedFailure;

    fn evaluate(&mut self, y: &[f64], g: &mut [f64]) -> Result<(), EvaluationError> {
        let n = self.metric.n;
        if let Some((ball, metric)) = self.trust.filter(|(b, _)| b.center.len() == n + 1) {
            let distance = metric.distance(y, &ball.center);
            if distance.is_nan() || distance > ball.radius {
                return Err(EvaluationError::OutsideDomain {
                    what: "distance from the last branch point beyond the trust radius",
                    value: distance,
                });
            }
        }
        let (x, p) = (&y[..n], y[n]);
        self.problem.set_parameter(p);
        self.problem.residual(x, &mut g[..n])?;
        g[n] = self.constraint_value(x, p);
        Ok(())
    }

    fn direction(
        &mut self,
        y: &[f64],
        g: &[f64],
        d: &mut [f64],
        // The bordered solve is exact: its tangent is reused by the predictor.
        _accuracy: SolveAccuracy,
        counters: &mut WorkCounters,
    ) -> Result<(), BorderedFailure> {
        let n = self.metric.n;
        let (x, p) = (&y[..n], y[n]);
        self.problem.set_parameter(p);
        counters.jacobian_evaluations += 1;
        self.problem
            .jacobian(x, &mut self.ws.jac)
            .map_err(BorderedFailure::Evaluation)?;
        self.counts.parameter_derivatives += 1;
        let fp =
            self.problem
                .residual_parameter_derivative(x, &mut self.ws.fp, &mut self.ws.fp_scratch);
        // The default F_p moves the parameter and restores it; make sure it is ours.
        self.problem.set_parameter(p);
        fp.map_err(BorderedFailure::Evaluation)?;
        if !all_finite(&self.ws.fp) {
            return Err(BorderedFailure::NonFinite);
        }
        self.counts.iterations += 1;
        counters.factorizations += 1;
        let n_value = g[n];
        let block = self.block_elimination(&g[..n], n_value, d, counters);
        match (block, self.fallback) {
            (Ok(()), _) => {}
            (Err(BorderedFailure::Linear(_) | BorderedFailure::SingularBorder(_)), Some(a)) => {
                self.counts.dense_factorizations += 1;
                self.dense_bordered(a, &g[..n], n_value, d)
                    .map_err(BorderedFailure::Linear)?;
            }
            (Err(failure), _) => return Err(failure),
        }
        if !all_finite(&self.ws.tangent) {
            return Err(BorderedFailure::NonFinite);
        }
        Ok(())
    }

    fn step_norm(&self, v: &[f64]) -> f64 {
        self.metric.norm_joined(v)
    }
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|u| u.is_finite())
}

impl<P, S> BorderedSystem<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    fn constraint_value(&self, x: &[f64], p: f64) -> f64 {
        let c = self.constraint;
        let w_x_dot_x: f64 = if c.arclength {
            self.ws.w.iter().zip(x).map(|(u, v)| u * v).sum()
        } else {
            0.0
        };
        w_x_dot_x + c.w_p * p - c.target
    }

    /// Block elimination by the core's [`BorderedSolver`]: one factorization of `J`, the
    /// solves `J a = F_p` and `J b = F`, `dp = (w_x·b - N) / (w_p - w_x·a)`, `dx = -b - a dp`
    /// (the bordered solve of `[F; N]`, negated), raw tangent `sign(pivot) (-a, 1)`.
    fn block_elimination(
        &mut self,
        f: &[f64],
        n_value: f64,
        d: &mut [f64],
        counters: &mut WorkCounters,
    ) -> Result<(), BorderedFailure> {
        let n = self.metric.n;
        let ws = &mut *self.ws;
        let w = if self.constraint.arclength {
            &ws.w
        } else {
            &ws.zeros
        };
        let border = [self.constraint.w_p];
        let factored = ws.border.factor(self.solver, &ws.jac, &ws.fp, w, &border);
        if !matches!(factored, Err(BorderedError::Factorization(_))) {
            counters.linear_solves += 2;
        }
        factored.map_err(border_failure)?;
        let (dx, dp) = d.split_at_mut(n);
        dx.copy_from_slice(f);
        dp[0] = n_value;
        ws.border
            .solve(self.solver, dx, dp)
            .map_err(border_failure)?;
        for v in d.iter_mut() {
            *v = -*v;
        }
        let sign = ws.border.schur_complement()[0].signum();
        for (t, ai) in ws.tangent.iter_mut().zip(ws.border.inner_solution()) {
            *t = -sign * ai;
        }
        ws.tangent[n] = sign;
        Ok(())
    }

    /// Dense LU of the assembled bordered matrix `[[J, F_p], [w_x^T, w_p]]`: the correction
    /// `d` and the raw tangent (kernel of `[J, F_p]` normalised by `w·t = 1`).
    fn dense_bordered(
        &mut self,
        assemble: DenseAssembler<P::Jacobian>,
        f: &[f64],
        n_value: f64,
        d: &mut [f64],
    ) -> Result<(), LinearSolveError> {
        let n = self.metric.n;
        let constraint = self.constraint;
        let ws = &mut *self.ws;
        let mut m = ws.dense.take().unwrap_or_else(|| Mat::zeros(n + 1, n + 1));
        assemble(&ws.jac, m.as_mut().submatrix_mut(0, 0, n, n));
        for i in 0..n {
            m[(i, n)] = ws.fp[i];
            m[(n, i)] = if constraint.arclength { ws.w[i] } else { 0.0 };
        }
        m[(n, n)] = constraint.w_p;
        let result = (|| {
            check_finite_dense(n + 1, n + 1, |i, j| m[(i, j)])?;
            let lu = PartialPivLu::new(m.as_ref());
            let u = lu.U();
            check_pivots((0..=n).map(|i| u[(i, i)]), DEFAULT_PIVOT_THRESHOLD)?;
            let mut rhs = Mat::<f64>::zeros(n + 1, 2);
            for i in 0..n {
                rhs[(i, 0)] = -f[i];
            }
            rhs[(n, 0)] = -n_value;
            rhs[(n, 1)] = 1.0;
            lu.solve_in_place(rhs.as_mut());
            for (i, di) in d.iter_mut().enumerate() {
                *di = rhs[(i, 0)];
            }
            for i in 0..=n {
                ws.tangent[i] = rhs[(i, 1)];
            }
            Ok(())
        })();
        ws.dense = Some(m);
        result
    }
}

/// The corrector's failure for an error of the bordered solver.
fn border_failure(error: BorderedError) -> BorderedFailure {
    match error {
        BorderedError::Factorization(e) | BorderedError::Solve(e) => BorderedFailure::Linear(e),
        BorderedError::SingularBorder { pivot, .. } => BorderedFailure::SingularBorder(pivot),
        BorderedError::NonFinite => BorderedFailure::NonFinite,
        BorderedError::DimensionMismatch {
            expected, found, ..
        } => BorderedFailure::Linear(LinearSolveError::DimensionMismatch { expected, found }),
    }
}

/// Everything one correction needs besides the point.
pub(super) struct Corrector<'a, P: GeneralizedJacobian + ?Sized, S: ?Sized> {
    pub problem: &'a mut P,
    pub solver: &'a mut S,
    pub ws: &'a mut Bordered<P::Jacobian>,
    pub fallback: Option<DenseAssembler<P::Jacobian>>,
    pub metric: &'a Metric,
    /// The trust ball and the metric it is measured in.
    pub trust: Option<(&'a TrustBall, &'a Metric)>,
    pub rules: KernelRules,
}

impl<'a, P, S> Corrector<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    /// The bordered system `[F; N]` of this corrector under `constraint`, counting its
    /// solves into `counts`.
    fn into_system<'c>(
        self,
        constraint: Constraint,
        counts: &'c mut CorrectorCounts,
    ) -> BorderedSystem<'c, P, S>
    where
        'a: 'c,
    {
        BorderedSystem {
            problem: self.problem,
            solver: self.solver,
            ws: self.ws,
            fallback: self.fallback,
            metric: self.metric,
            constraint,
            trust: self.trust,
            counts,
        }
    }

    /// Newton on `[F; N] = 0` from the joined point `y = (x, p)`. On success `y` holds the
    /// converged point, `ws.tangent` the raw tangent and the problem's parameter equals
    /// `p`; on failure the caller restores the parameter. Returns the smallest finite
    /// `|[F; N]|` seen as well.
    pub fn correct(
        self,
        y: &mut [f64],
        constraint: Constraint,
        work: &mut WorkCounters,
        counts: &mut CorrectorCounts,
    ) -> (Result<Corrected, CorrectorFailure>, f64) {
        let n = self.metric.n;
        let rules = self.rules;
        let mut kernel = std::mem::take(&mut self.ws.kernel);
        let mut system = self.into_system(constraint, counts);
        let run = kernel.run(&mut system, y, &rules, work);
        let residual_norm = norm2(&kernel.residual()[..n]);
        system.ws.kernel = kernel;
        let iteration = run.iterations;
        let result = match run.stop {
            Stop::Converged | Stop::ConvergedAtFloor => Ok(Corrected {
                iterations: run.iterations,
                residual_norm,
            }),
            // The corrector runs without a stagnation rule: a stagnation is an iteration
            // budget spent.
            Stop::MaxIterations | Stop::Stagnated => Err(CorrectorFailure::MaxIterations {
                iterations: run.iterations,
                residual_norm,
            }),
            Stop::Stalled { step_norm } => Err(CorrectorFailure::Stalled {
                iteration,
                residual_norm,
                step_norm,
            }),
            Stop::LineSearchFailed { last_step } => Err(CorrectorFailure::LineSearchFailed {
                iteration,
                residual_norm,
                last_step,
            }),
            Stop::Direction(failure) => Err(failure.at(iteration)),
            Stop::Evaluation(error) => Err(CorrectorFailure::Evaluation { iteration, error }),
            Stop::NonFinite => Err(CorrectorFailure::NonFinite { iteration }),
        };
        (result, run.smallest)
    }

    /// The raw tangent at `y = (x, p)` without correcting it: the kernel of `[J, F_p]`
    /// with the generalized Jacobian evaluated at `y` (so with the pieces active there),
    /// written to `ws.tangent` as `(-a, 1)`, `J a = F_p`. The problem's parameter is left
    /// at `p`.
    pub fn tangent_at(
        self,
        y: &[f64],
        work: &mut WorkCounters,
        counts: &mut CorrectorCounts,
    ) -> Result<(), CorrectorFailure> {
        let n = self.metric.n;
        let constraint = Constraint {
            arclength: false,
            w_p: 1.0,
            target: y[n],
        };
        let untrusted = Corrector {
            trust: None,
            ..self
        };
        let mut system = untrusted.into_system(constraint, counts);
        let zero = vec![0.0; n + 1];
        let mut d = vec![0.0; n + 1];
        system
            .direction(y, &zero, &mut d, SolveAccuracy::new(0.0, 0.0), work)
            .map_err(|failure| failure.at(0))
    }
}
