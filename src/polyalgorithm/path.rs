//! Paths that lead from the initial guess to a root, followed by the crate's
//! pseudo-arclength continuation: the Newton homotopy and the smoothing path.
//!
//! # The Newton homotopy
//!
//! `H(x, t) = F(x) - (1 - t) F(x_0)`, followed in `t` from the initial guess `(x_0, 0)` to
//! `t = 1`.
//!
//! `H(x_0, 0) = 0` exactly, `H(., 1) = F`, `∂H/∂x = J` (the problem's own generalized
//! Jacobian) and `∂H/∂t = F(x_0)`: the path needs nothing from the problem but `F` and `J`.
//! Its tangent at the start is the Newton direction, so on a problem that is affine along
//! the path one step of length 1 reaches `t = 1`; where the plain iteration cycles between
//! active sets or a line search stalls at a kink of the merit, the path moves through the
//! kinks one at a time, passing turning points in `t` (where `J` is singular) by the
//! arclength constraint (Keller 1978; Allgower & Georg, *Introduction to Numerical
//! Continuation Methods*, ch. 11 on the global Newton method). For a forced structure with
//! open contacts at `x_0 = 0`, `F(x_0)` is minus the forcing and the path is the load
//! homotopy: contacts close one after the other as the forcing grows. Its path is only
//! piecewise smooth (a kink wherever a switching quantity changes sign), which costs steps.
//!
//! # The smoothing path
//!
//! For a problem with a [`Smoothing`](crate::Smoothing), `F_mu(x) = 0` followed from `mu_0` down to
//! `mu_0 10^(-decades)` in the parameter `p = log10(mu_0 / mu)` (so
//! `dF/dp = -ln(10) mu dF_mu/dmu`). The path is smooth (every kink of `F` is rounded off over
//! a width `mu`), so its steps are long; near its end the iterate lies within `O(mu)` of a
//! root of `F`, where semismooth Newton on `F` terminates in a few steps (Chen, Harker,
//! Kanzow & Smale; Qi, Sun & Zhou 2000, *A new look at smoothing Newton methods*). Turning
//! points in `mu` (where several roots coexist) are passed by the arclength.

use crate::continuation::{
    Continuation, ContinuationOptions, ContinuationTermination, Direction, Predictor, RestartPolicy,
};
use crate::newton::WorkCounters;
use crate::{
    EvaluationError, Factorize, GeneralizedJacobian, ParameterDependent, ProblemCounters, Residual,
};

use super::SmoothingOf;

/// `H(x, t) = F(x) - (1 - t) F(x_0)` around a problem `F`.
pub(crate) struct NewtonHomotopy<'a, P: ?Sized> {
    problem: &'a mut P,
    start_residual: Vec<f64>,
    t: f64,
}

impl<P: Residual + ?Sized> Residual for NewtonHomotopy<'_, P> {
    fn dim(&self) -> usize {
        self.problem.dim()
    }

    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        self.problem.residual(x, out)?;
        let s = 1.0 - self.t;
        for (o, r) in out.iter_mut().zip(&self.start_residual) {
            *o -= s * r;
        }
        Ok(())
    }

    fn problem_counters(&self) -> ProblemCounters {
        self.problem.problem_counters()
    }
}

impl<P: GeneralizedJacobian + ?Sized> GeneralizedJacobian for NewtonHomotopy<'_, P> {
    type Jacobian = P::Jacobian;

    fn new_jacobian(&self) -> P::Jacobian {
        self.problem.new_jacobian()
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut P::Jacobian) -> Result<(), EvaluationError> {
        self.problem.jacobian(x, jac)
    }
}

impl<P: Residual + ?Sized> ParameterDependent for NewtonHomotopy<'_, P> {
    fn parameter(&self) -> f64 {
        self.t
    }

    fn set_parameter(&mut self, t: f64) {
        self.t = t;
    }

    fn residual_parameter_derivative(
        &mut self,
        _x: &[f64],
        out: &mut [f64],
        _scratch: &mut [f64],
    ) -> Result<(), EvaluationError> {
        out.copy_from_slice(&self.start_residual);
        Ok(())
    }
}

impl<'a, P: Residual + ?Sized> NewtonHomotopy<'a, P> {
    /// The homotopy around `problem` from a point where `F = start_residual`, at `t = 0`.
    pub(crate) fn new(problem: &'a mut P, start_residual: &[f64]) -> Self {
        Self {
            problem,
            start_residual: start_residual.to_vec(),
            t: 0.0,
        }
    }
}

/// `F_mu(x)` with `mu = mu_0 10^(-p)`, the parameter `p` (see the module docs). Dropping it
/// sets the problem's smoothing back to 0.
pub(crate) struct SmoothingPath<'a, P: Residual + ?Sized> {
    problem: &'a mut P,
    smoothing: SmoothingOf<P>,
    mu0: f64,
    p: f64,
    /// Decades of the tolerance per decade of `mu` ([`ParameterDependent::tolerance_scale`]
    /// `= (mu / mu_0)^rate`; 0: one tolerance along the path).
    tolerance_rate: f64,
    /// Smallest [`ParameterDependent::tolerance_scale`] (the run's own tolerance over the
    /// path's accuracy: points are never asked for more than the run asks of a root).
    smallest_scale: f64,
}

impl<'a, P: Residual + ?Sized> SmoothingPath<'a, P> {
    /// The path of `problem` with its `smoothing` at `p = 0` (`mu = mu0`).
    pub(crate) fn new(problem: &'a mut P, smoothing: SmoothingOf<P>, mu0: f64) -> Self {
        (smoothing.set)(problem, mu0);
        Self {
            problem,
            smoothing,
            mu0,
            p: 0.0,
            tolerance_rate: 0.0,
            smallest_scale: 0.0,
        }
    }

    /// Points at `mu` are corrected to the path's accuracy times `(mu / mu_0)^rate`, but
    /// never to less than `smallest` times it.
    pub(crate) fn with_tolerance_decay(mut self, rate: f64, smallest: f64) -> Self {
        self.tolerance_rate = rate;
        self.smallest_scale = smallest;
        self
    }

    fn mu(&self) -> f64 {
        self.mu0 * 10f64.powf(-self.p)
    }
}

impl<P: Residual + ?Sized> Drop for SmoothingPath<'_, P> {
    fn drop(&mut self) {
        (self.smoothing.set)(self.problem, 0.0);
    }
}

impl<P: Residual + ?Sized> Residual for SmoothingPath<'_, P> {
    fn dim(&self) -> usize {
        self.problem.dim()
    }

    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        self.problem.residual(x, out)
    }

    fn problem_counters(&self) -> ProblemCounters {
        self.problem.problem_counters()
    }
}

impl<P: GeneralizedJacobian + ?Sized> GeneralizedJacobian for SmoothingPath<'_, P> {
    type Jacobian = P::Jacobian;

    fn new_jacobian(&self) -> P::Jacobian {
        self.problem.new_jacobian()
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut P::Jacobian) -> Result<(), EvaluationError> {
        self.problem.jacobian(x, jac)
    }
}

impl<P: Residual + ?Sized> ParameterDependent for SmoothingPath<'_, P> {
    fn parameter(&self) -> f64 {
        self.p
    }

    fn set_parameter(&mut self, p: f64) {
        self.p = p;
        let mu = self.mu();
        (self.smoothing.set)(self.problem, mu);
    }

    /// `(mu / mu_0)^rate = 10^(-rate p)`: with rate 1, points are corrected to
    /// `|F_mu| <= tolerance mu / mu_0`, the neighbourhood of the path where smoothing Newton
    /// methods keep their iterates (`|F_mu| <= beta mu`, Chen, Harker, Kanzow & Smale).
    /// (Rate 0 gives 1: `smallest_scale <= 1`, the run's tolerance being at most the
    /// path's accuracy.)
    fn tolerance_scale(&self, p: f64) -> f64 {
        10f64
            .powf(-self.tolerance_rate * p.max(0.0))
            .max(self.smallest_scale)
    }

    fn residual_parameter_derivative(
        &mut self,
        x: &[f64],
        out: &mut [f64],
        _scratch: &mut [f64],
    ) -> Result<(), EvaluationError> {
        let factor = -std::f64::consts::LN_10 * self.mu();
        (self.smoothing.derivative)(self.problem, x, out)?;
        for o in out.iter_mut() {
            *o *= factor;
        }
        Ok(())
    }
}

/// How a path-following attempt ended.
#[derive(Clone, Debug, Default)]
pub(crate) struct PathOutcome {
    /// The end of the path was reached (`x` is then on the path there, to the accuracy).
    pub reached: bool,
    /// Corrector iterations spent (failed attempts included).
    pub iterations: usize,
    /// Largest parameter reached.
    pub furthest: f64,
    /// Why the path ended when it did not reach its end.
    pub reason: Option<String>,
    /// The problem's own error, when it ended the path ([`EvaluationError::Problem`]).
    pub error: Option<EvaluationError>,
    /// Work done.
    pub counters: WorkCounters,
}

/// How a path is followed: from parameter 0 to `end`, first steps of `1 / steps` of the
/// path's length, growing up to `growth` times that; the state weighted by `theta` in the
/// arclength; the corrector aims at `target_iterations` (and rejects a step after one more)
/// from `predictor`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathShape {
    pub end: f64,
    pub steps: f64,
    pub growth: f64,
    pub theta: f64,
    pub target_iterations: usize,
    pub predictor: Predictor,
}

/// A path of `shape` with the state lengths measured in `state_scale`, points corrected to
/// `accuracy`, at most `budget` corrector iterations.
#[derive(Clone, Copy, Debug)]
pub(crate) struct PathPlan {
    pub shape: PathShape,
    pub state_scale: f64,
    pub accuracy: f64,
    pub budget: usize,
}

/// The smallest step of a path, relative to its first.
const MIN_STEP_FRACTION: f64 = 1e-4;
/// Failed attempts in a row after which a path gives up (before a restart).
const MAX_CONSECUTIVE_FAILURES: usize = 8;

/// Continuation settings of a path (lengths in the θ-norm of [`crate::continuation`]: the
/// parameter measured in units of the whole path, the state in `plan.state_scale`).
fn path_options(n: usize, plan: &PathPlan) -> ContinuationOptions {
    let shape = &plan.shape;
    let step = 1.0 / shape.steps;
    ContinuationOptions {
        // Small enough that a corner of the path (a contact closing) is approached before
        // it is overshot.
        initial_step: step,
        max_step: step * shape.growth,
        min_step: MIN_STEP_FRACTION * step,
        max_consecutive_failures: MAX_CONSECUTIVE_FAILURES,
        max_corrector_iterations: shape.target_iterations + 1,
        target_iterations: shape.target_iterations,
        theta: shape.theta,
        corrector_tolerance: plan.accuracy,
        parameter_min: -shape.end,
        parameter_max: shape.end,
        parameter_scale: shape.end,
        state_scale: Some(vec![plan.state_scale; n]),
        direction: Direction::Increasing,
        refine_folds: false,
        restarts: Some(RestartPolicy::default()),
        max_total_corrector_iterations: Some(plan.budget),
        predictor: shape.predictor,
        ..ContinuationOptions::default()
    }
}

/// Relative accuracy of the points along a path, `|H| <= PATH_ACCURACY |F(x_0)|`: the path
/// only leads to its end, where Newton on `F` finishes to the run's tolerance.
pub(crate) const PATH_ACCURACY: f64 = 1e-2;

/// The state scale of a path (per component) from the norms of the full Newton steps
/// before it: the first step's, unless a later one is more than `BLOCKED_FIRST_STEP`
/// times longer, then the longest's. A first step that short was blocked (a friction
/// point sticking at the zero velocity of the guess holds its dof still) and does not
/// measure the solution; a path weighted by it creeps in its parameter.
pub(crate) fn state_scale(step_norms: &[f64], n: usize) -> f64 {
    let first = step_norms.first().copied().unwrap_or(f64::NAN);
    let longest =
        (step_norms.iter()).fold(f64::NAN, |m, s| if s.is_finite() { s.max(m) } else { m });
    let norm = if longest > BLOCKED_FIRST_STEP * first {
        longest
    } else {
        first
    };
    if norm.is_finite() && norm > 0.0 {
        norm / (n as f64).sqrt()
    } else {
        1.0
    }
}

/// How much longer than the first full step a later one must be for the first to count
/// as blocked. Measured: on the public grid and the hard cases (contacts alone) the
/// longest of the full steps is at most 35 times the first; on the two-dof chain with a
/// friction point beside a stop it is up to 4600 times (median 90).
const BLOCKED_FIRST_STEP: f64 = 100.0;

/// Follows `homotopy` from `(x, 0)` to the parameter `plan.shape.end` within `plan.budget`
/// corrector iterations; on success `x` is the end of the path.
pub(crate) fn follow<H, S>(
    homotopy: &mut H,
    solver: &mut S,
    x: &mut [f64],
    plan: &PathPlan,
) -> PathOutcome
where
    H: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<H::Jacobian> + ?Sized,
{
    let n = x.len();
    let options = path_options(n, plan);
    let mut outcome = PathOutcome::default();
    if plan.budget == 0 {
        outcome.reason = Some("no iterations left".into());
        return outcome;
    }
    let start = x.to_vec();
    let mut continuation = match Continuation::new(homotopy, solver, &start, 0.0, options) {
        Ok(c) => c,
        Err(e) => {
            outcome.reason = Some(e.to_string());
            return outcome;
        }
    };
    let mut last = 0.0;
    for point in continuation.by_ref() {
        outcome.furthest = outcome.furthest.max(point.parameter);
        last = point.parameter;
        x.copy_from_slice(&point.state);
    }
    let counters = continuation.counters();
    outcome.iterations = counters.corrector_iterations as usize;
    outcome.counters = counters.work;
    match continuation.termination() {
        Some(ContinuationTermination::ReachedBound { parameter, bound })
            if *bound == plan.shape.end && *parameter == plan.shape.end =>
        {
            outcome.reached = true;
        }
        Some(ContinuationTermination::ProblemFailed { error, .. }) => {
            outcome.reason = Some(error.to_string());
            outcome.error = Some(error.clone());
        }
        Some(t) if outcome.reason.is_none() => outcome.reason = Some(t.to_string()),
        _ => {}
    }
    if !outcome.reached && outcome.reason.is_none() {
        outcome.reason = Some(format!("the path ended at {last}"));
    }
    outcome
}
