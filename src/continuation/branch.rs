//! What a continuation produces: points, events, termination, counters, errors.

use crate::linalg::LinearSolveError;
use crate::newton::{NewtonError, WorkCounters};
use crate::EvaluationError;

/// One accepted point of a branch.
#[derive(Clone, Debug, PartialEq)]
pub struct BranchPoint {
    /// The state `x`.
    pub state: Vec<f64>,
    /// The parameter `p`.
    pub parameter: f64,
    /// Corrector iterations (= factorizations) spent on this point (for a point re-solved
    /// on a parameter bound, those of the arclength step plus those of the re-solve).
    pub iterations: usize,
    /// `|F(x, p)|` (2-norm) at the point.
    pub residual_norm: f64,
    /// Step length (θ-norm) that produced this point; `0` for the starting point.
    pub step: f64,
    /// Parameter component `t_p` of the unit (θ-norm) tangent, oriented along the branch;
    /// it changes sign at folds (0 at a corner, which has no tangent).
    pub tangent_parameter: f64,
    /// A corner of a piecewise-affine branch located exactly
    /// ([`Continuation::with_affine_pieces`](super::Continuation::with_affine_pieces)),
    /// not a corrected point (`iterations`, `residual_norm` and `step` are 0).
    pub corner: bool,
}

/// Something noticed along the branch.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ContinuationEvent {
    /// The parameter turns back (see [`FoldDetector`](super::FoldDetector)): on a smooth branch `t_p` changed
    /// sign between points `index - 1` and `index`; at a corner of a piecewise-smooth branch
    /// `index` is the extreme point itself.
    Fold {
        /// Index (in the branch) of the first point after the sign change of `t_p`, or of
        /// the extreme point where `t_p` did not change sign.
        index: usize,
        /// Parameter at the fold (refined by interpolation when
        /// [`ContinuationOptions::refine_folds`](super::ContinuationOptions::refine_folds) is set).
        parameter: f64,
    },
    /// The parameter turned back by less than
    /// [`ContinuationOptions::fold_excursion`](super::ContinuationOptions::fold_excursion)
    /// and forward again (see [`FoldDetector`](super::FoldDetector)): a corner of a
    /// piecewise-smooth branch, not a fold. One event per reversal of the increments.
    Zigzag {
        /// Index of the point where the increments reverse.
        index: usize,
        /// Its parameter.
        parameter: f64,
    },
    /// A corner of a piecewise-affine branch, crossed exactly
    /// ([`Continuation::with_affine_pieces`](super::Continuation::with_affine_pieces)).
    Corner {
        /// Index of the corner point in the branch.
        index: usize,
        /// Its parameter.
        parameter: f64,
    },
}

/// Why a corrector attempt failed (the step is then rejected).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CorrectorFailure {
    /// No convergence within `max_corrector_iterations`.
    #[error("no convergence in {iterations} iterations (|F| = {residual_norm:e})")]
    MaxIterations {
        /// Iterations performed.
        iterations: usize,
        /// `|F|` at the last iterate.
        residual_norm: f64,
    },
    /// The residual, `F_p` or a correction was NaN or infinite.
    #[error("non-finite residual, F_p or correction at iteration {iteration}")]
    NonFinite {
        /// Iteration at which it happened.
        iteration: usize,
    },
    /// The corrections became negligible while `|F|` stayed above the tolerance.
    #[error(
        "stalled at iteration {iteration}: correction {step_norm:e} with |F| = {residual_norm:e}"
    )]
    Stalled {
        /// Iteration at which it happened.
        iteration: usize,
        /// `|F|` there.
        residual_norm: f64,
        /// θ-norm of the last correction.
        step_norm: f64,
    },
    /// The linear solver failed (a singular Jacobian without dense fallback, or a solver
    /// error).
    #[error("linear solve failed at iteration {iteration}: {error}")]
    LinearSolve {
        /// Iteration at which it happened.
        iteration: usize,
        /// The solver's error.
        error: LinearSolveError,
    },
    /// The corrector's line search found no step with sufficient decrease.
    #[error("line search failed at iteration {iteration} (|F| = {residual_norm:e}, last step {last_step:e})")]
    LineSearchFailed {
        /// Iteration at which it happened.
        iteration: usize,
        /// `|F|` at the iterate.
        residual_norm: f64,
        /// The last step length tried.
        last_step: f64,
    },
    /// The problem could not be evaluated at an iterate (outside its domain, outside the
    /// trust ball around the last point, or the problem's own error).
    #[error("the problem could not be evaluated at iteration {iteration}: {error}")]
    Evaluation {
        /// Iteration at which it happened.
        iteration: usize,
        /// The problem's error.
        error: EvaluationError,
    },
    /// The block-elimination pivot `w_p - w_x·a` vanished and no dense fallback is set.
    #[error("bordered system singular at iteration {iteration}: pivot w_p - w_x·a = {pivot:e}")]
    SingularBorder {
        /// Iteration at which it happened.
        iteration: usize,
        /// The pivot.
        pivot: f64,
    },
}

/// Why a continuation run stopped.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ContinuationTermination {
    /// The starting point could not be corrected at the starting parameter (the branch has
    /// no point).
    StartFailed {
        /// The starting parameter.
        parameter: f64,
        /// Why the corrector failed.
        failure: CorrectorFailure,
    },
    /// The branch left `[parameter_min, parameter_max]`; the last point was re-solved at
    /// the bound when possible (then `parameter == bound`).
    ReachedBound {
        /// Parameter of the last point.
        parameter: f64,
        /// The bound that was crossed.
        bound: f64,
    },
    /// `max_points` points were accepted.
    MaxPoints {
        /// Number of points.
        points: usize,
    },
    /// An attempt at `min_step` failed.
    StepTooSmall {
        /// Parameter of the last accepted point.
        parameter: f64,
        /// Step length of the failed attempt.
        step: f64,
        /// Smallest finite `|F|` seen in the failed attempt (`inf` if none was finite).
        residual_norm: f64,
        /// Why the attempt failed.
        failure: CorrectorFailure,
    },
    /// `max_consecutive_failures` attempts failed in a row.
    TooManyFailures {
        /// Parameter of the last accepted point.
        parameter: f64,
        /// Step length of the last failed attempt.
        step: f64,
        /// Number of failures in a row.
        failures: usize,
        /// Smallest finite `|F|` seen in the last failed attempt (`inf` if none).
        residual_norm: f64,
        /// Why the last attempt failed.
        failure: CorrectorFailure,
    },
    /// A restarted segment went back along the branch (one of its points came close to a
    /// point before the restart, [`RestartPolicy`](super::RestartPolicy)): the branch
    /// ends at the restart point, where no step ahead was found.
    Retraced {
        /// Parameter of the restart point.
        parameter: f64,
    },
    /// The corrector iterations allowed over the run
    /// ([`ContinuationOptions::max_total_corrector_iterations`](super::ContinuationOptions::max_total_corrector_iterations))
    /// were spent.
    IterationBudgetSpent {
        /// Parameter of the last accepted point.
        parameter: f64,
        /// The budget (every corrector iteration of the run, all of it spent).
        budget: usize,
    },
    /// A new segment (after a restart or a walk over corners) could not be corrected at
    /// its starting parameter.
    SegmentStartFailed {
        /// The starting parameter.
        parameter: f64,
        /// Why the corrector failed.
        failure: CorrectorFailure,
    },
    /// The problem's own error ([`EvaluationError::Problem`]) ended the run.
    ProblemFailed {
        /// Parameter of the last accepted point (the start's, before the first).
        parameter: f64,
        /// The error.
        error: EvaluationError,
    },
}

impl std::fmt::Display for ContinuationTermination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::StartFailed { parameter, failure } => write!(
                f,
                "the starting point could not be corrected at p = {parameter}: {failure}"
            ),
            Self::ReachedBound { parameter, bound } => {
                write!(
                    f,
                    "reached the parameter bound {bound} (last point at {parameter})"
                )
            }
            Self::MaxPoints { points } => write!(f, "reached the point limit ({points} points)"),
            Self::StepTooSmall {
                parameter,
                step,
                residual_norm,
                failure,
            } => write!(
                f,
                "step too small: the attempt with step {step:e} from p = {parameter} failed \
                 (smallest |F| {residual_norm:e}): {failure}"
            ),
            Self::TooManyFailures {
                parameter,
                step,
                failures,
                residual_norm,
                failure,
            } => write!(
                f,
                "{failures} failed attempts in a row from p = {parameter}, last step {step:e} \
                 (smallest |F| {residual_norm:e}): {failure}"
            ),
            Self::Retraced { parameter } => write!(
                f,
                "stalled at p = {parameter}: no step ahead (a corner the continuation cannot \
                 turn), and the only step found goes back along the branch"
            ),
            Self::IterationBudgetSpent { parameter, budget } => write!(
                f,
                "the {budget} corrector iterations allowed were spent (last point at p = {parameter})"
            ),
            Self::SegmentStartFailed { parameter, failure } => write!(
                f,
                "a new segment could not be corrected at p = {parameter}: {failure}"
            ),
            Self::ProblemFailed { parameter, error } => write!(
                f,
                "the problem failed after the point at p = {parameter}: {error}"
            ),
        }
    }
}

/// Work done by a continuation run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ContinuationCounters {
    /// The Newton-style counters: residual evaluations (line-search trials included),
    /// Jacobian evaluations and `factor` calls (one each per corrector iteration), solves
    /// (two per corrector iteration with block elimination), corrector line-search
    /// backtracks, corner walks (their Jacobians, factorizations and solves), and the
    /// problem's own counters over the run.
    pub work: WorkCounters,
    /// Evaluations of `F_p` (each may cost residual evaluations inside the problem, which
    /// are not counted in `work`).
    pub parameter_derivative_evaluations: u64,
    /// Dense LU factorizations of the assembled bordered matrix (fallback).
    pub dense_bordered_factorizations: u64,
    /// Corrector iterations of all attempts, accepted or not, start and bound landing
    /// included.
    pub corrector_iterations: u64,
    /// Corrector iterations spent on rejected attempts.
    pub rejected_iterations: u64,
    /// Rejected attempts.
    pub rejected_steps: u64,
    /// Points accepted by a corner pass (module documentation, *Corners*).
    pub corner_passes: u64,
    /// Of the corner passes, those along the tangent of the exit piece (module
    /// documentation, *Corners*).
    pub exit_passes: u64,
    /// Restarts after failed steps ([`ContinuationOptions::restarts`](super::ContinuationOptions::restarts)).
    pub restarts: u64,
    /// Corners of a piecewise-affine branch crossed exactly.
    pub corners: u64,
}

impl std::ops::AddAssign for ContinuationCounters {
    fn add_assign(&mut self, rhs: Self) {
        self.work += rhs.work;
        self.parameter_derivative_evaluations += rhs.parameter_derivative_evaluations;
        self.dense_bordered_factorizations += rhs.dense_bordered_factorizations;
        self.corrector_iterations += rhs.corrector_iterations;
        self.rejected_iterations += rhs.rejected_iterations;
        self.rejected_steps += rhs.rejected_steps;
        self.corner_passes += rhs.corner_passes;
        self.exit_passes += rhs.exit_passes;
        self.restarts += rhs.restarts;
        self.corners += rhs.corners;
    }
}

/// A computed branch.
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    /// Accepted points in branch order, the corrected starting point first.
    pub points: Vec<BranchPoint>,
    /// Events (folds, zigzags, corners) in the order they were decided.
    pub events: Vec<ContinuationEvent>,
    /// Why the run stopped.
    pub termination: ContinuationTermination,
    /// Work done.
    pub counters: ContinuationCounters,
}

impl Branch {
    /// Parameters of the points, in branch order.
    pub fn parameters(&self) -> Vec<f64> {
        self.points.iter().map(|q| q.parameter).collect()
    }

    /// Parameters of the detected folds, in branch order.
    pub fn fold_parameters(&self) -> Vec<f64> {
        self.event_parameters(|e| matches!(e, ContinuationEvent::Fold { .. }))
    }

    /// Parameters of the zigzags (reversals within the fold excursion), in branch order.
    pub fn zigzag_parameters(&self) -> Vec<f64> {
        self.event_parameters(|e| matches!(e, ContinuationEvent::Zigzag { .. }))
    }

    /// Parameters of the corners crossed exactly, in branch order.
    pub fn corner_parameters(&self) -> Vec<f64> {
        self.event_parameters(|e| matches!(e, ContinuationEvent::Corner { .. }))
    }

    fn event_parameters(&self, kind: impl Fn(&ContinuationEvent) -> bool) -> Vec<f64> {
        self.events
            .iter()
            .filter(|e| kind(e))
            .map(|e| match e {
                ContinuationEvent::Fold { parameter, .. }
                | ContinuationEvent::Zigzag { parameter, .. }
                | ContinuationEvent::Corner { parameter, .. } => *parameter,
            })
            .collect()
    }

    /// Maps every point to a user quantity (an amplitude, a norm), in branch order.
    pub fn measure<T>(&self, f: impl FnMut(&BranchPoint) -> T) -> Vec<T> {
        self.points.iter().map(f).collect()
    }
}

/// Why a continuation could not run (a run that ran and stopped has a
/// [`ContinuationTermination`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ContinuationError {
    /// An option is out of range.
    #[error("invalid option {name} = {value}: allowed {allowed}")]
    InvalidOption {
        /// Field name.
        name: &'static str,
        /// Value given.
        value: f64,
        /// What is allowed.
        allowed: &'static str,
    },
    /// The starting state does not have the problem's dimension (or the problem is empty).
    #[error("dimension mismatch: the problem has dimension {expected}, the state has {found}")]
    DimensionMismatch {
        /// Problem dimension.
        expected: usize,
        /// Length given.
        found: usize,
    },
    /// The starting parameter is not finite or outside the bounds.
    #[error("starting parameter {parameter} outside [{min}, {max}]")]
    InvalidStart {
        /// The parameter given.
        parameter: f64,
        /// Lower bound.
        min: f64,
        /// Upper bound.
        max: f64,
    },
    /// A solve of a natural sweep could not run (its options are invalid, or the state has
    /// the wrong length).
    #[error(transparent)]
    Newton(#[from] NewtonError),
}
