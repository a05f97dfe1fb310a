//! Pseudo-arclength continuation of a branch of solutions of `F(x, p) = 0`, and a
//! natural-parameter sweep to compare it with.
//!
//! # The method
//!
//! Points `y = (x, p)` of the branch are measured with the weighted inner product
//! (BifurcationKit's `theta`, see Keller 1977 and Doedel's AUTO notes)
//!
//! ```text
//! <(a, α), (b, β)>_θ = (θ / n) a·b + (1 - θ) α β,        |y|_θ = sqrt(<y, y>_θ),
//! ```
//!
//! (with [`ContinuationOptions::state_scale`] `s`, `a·b` becomes `Σ a_i b_i / s_i^2`),
//! and step lengths `ds` are lengths in that norm. From an accepted point `y0` with unit
//! direction `t` (tangent for the first step, secant afterwards by default) the predictor is
//! `y0 + ds t`; the corrector is Newton on the bordered system
//!
//! ```text
//! F(x, p) = 0,    N(x, p) = <t, y - y0>_θ - ds = 0,
//! [[J, F_p], [w_x^T, w_p]] [dx; dp] = -[F; N],    w_x = (θ/n) t_x,  w_p = (1-θ) t_p,
//! ```
//!
//! solved by block elimination with ONE factorization of `J` per corrector iteration and two
//! solves, `J a = F_p` and `J b = F`: `dp = (w_x·b - N) / (w_p - w_x·a)`, `dx = -b - a dp`.
//! The bordered matrix is never assembled, so structured Jacobians (sparse, condensed)
//! keep their structure. The tangent at the converged point comes for free from the last
//! `a`: it is `±(-a, 1)` normalised (the kernel of `[J, F_p]`), with `J` and `F_p` from
//! the last corrector iteration, i.e. at the iterate before the converged one (an error
//! of the size of the last correction; the corrector always takes at least one step).
//!
//! # Folds and the dense fallback
//!
//! At a fold `J` is singular while the bordered matrix is not. Block elimination then loses
//! accuracy (the pivot `w_p - w_x·a` is a difference of large numbers) or the factorization
//! reports [`LinearSolveError::Singular`]. In practice the iterates rarely hit the singular
//! set exactly, and block elimination passes folds (the tests pass several). For Jacobians
//! that are singular on whole regions (piecewise-linear problems with a flat piece), the
//! continuation can fall back to a dense LU of the assembled `(n+1) x (n+1)` bordered
//! matrix. This is an optional capability chosen by a second entry point,
//! [`Continuation::with_dense_fallback`], which exists only when the Jacobian type
//! implements [`DenseAssemble`]; structured Jacobians that cannot be assembled use
//! [`Continuation::new`] and report a corrector failure instead (the step is then halved).
//!
//! # Step control
//!
//! After an accepted point corrected in `k` iterations the step is multiplied by
//! `sqrt(target_iterations / k)` clamped to `[1/2, 2]`, then clamped to
//! `[min_step, max_step]`. A failed corrector halves the step (not below `min_step`) and
//! restores the problem's parameter (`set_parameter`) to the last accepted point. The run
//! ends when an attempt at `min_step` fails ([`ContinuationTermination::StepTooSmall`]),
//! after `max_consecutive_failures` failures in a row
//! ([`ContinuationTermination::TooManyFailures`]), when the parameter leaves
//! `[parameter_min, parameter_max]` (the last point is then re-solved at the bound), or after
//! `max_points` points.
//!
//! Folds are detected as sign changes of the parameter component of the tangent, oriented
//! along the step just taken, confirmed by a reversal of the parameter's increments between
//! accepted points, and located by cubic Hermite interpolation of `p(s)` (values and slopes
//! `dp/ds = t_p` at both points); a reversal at a corner of a piecewise-smooth branch (no
//! sign change of `t_p`) is a fold at the extreme point ([`FoldDetector`], also usable on
//! branches stitched together from several runs).
//!
//! # Corners
//!
//! Branches of semismooth problems are only piecewise smooth. Where the branch turns by
//! more than 90° in the θ-norm at a corner, the pseudo-arclength hyperplane (normal to the
//! incoming direction `d`) no longer cuts the far piece, whatever the step: halving ends
//! the run there. Before giving up ([`ContinuationOptions::pass_corners`]), the step that
//! failed last is tried twice more from the last point: on the hyperplane normal to `d`'s
//! state part only, `d_x · (x - x_k) = ds |d_x|²` (cuts a far piece along which the state
//! keeps moving forward, e.g. a fold at a corner), then at the next parameter
//! `p_k + sign(d_p) ds / sqrt(1 - θ)` (cuts a far piece along which the parameter keeps
//! moving). A point found this way ([`ContinuationCounters::corner_passes`]) is accepted
//! with its tangent oriented along that constraint's normal, and the next predictor
//! follows that tangent (the chord across the corner is no direction for the far piece).
//!
//! The corrector takes full Newton steps unless
//! [`ContinuationOptions::corrector_line_search`] asks for Armijo backtracking on
//! `(|F|^2 + N^2) / 2` ([`crate::linesearch::backtrack`]).
//!
//! # Style
//!
//! [`Continuation`] is an [`Iterator`] over accepted points (BifurcationKit's style); the
//! first item is the starting point corrected at fixed `p0`. [`Continuation::run`] collects a
//! whole [`Branch`]. [`natural_sweep`] solves at a list of parameters with
//! [`crate::newton`] from the previous solution, for comparison: it fails or jumps at folds.
//!
//! References: H. B. Keller, *Numerical solution of bifurcation and nonlinear eigenvalue
//! problems* (1977); E. Allgower & K. Georg, *Numerical Continuation Methods* (1990), for
//! the bordered system and its block elimination; BifurcationKit.jl (`Palc`) for the
//! θ-weighted arclength and the iterator; NLvib for the step bounds.
//!
//! ```
//! use faer::Mat;
//! use semismooth::continuation::{Continuation, ContinuationOptions, ContinuationTermination};
//! use semismooth::linalg::FaerDenseLu;
//! use semismooth::{GeneralizedJacobian, ParameterDependent, Residual};
//!
//! /// The S-curve x^3 - x - p = 0 (folds at p = ±2/(3√3)).
//! struct SCurve { p: f64 }
//! impl Residual for SCurve {
//!     fn dim(&self) -> usize { 1 }
//!     fn residual(&mut self, x: &[f64], out: &mut [f64]) { out[0] = x[0].powi(3) - x[0] - self.p; }
//! }
//! impl GeneralizedJacobian for SCurve {
//!     type Jacobian = Mat<f64>;
//!     fn new_jacobian(&self) -> Mat<f64> { Mat::zeros(1, 1) }
//!     fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) { jac[(0, 0)] = 3.0 * x[0] * x[0] - 1.0; }
//! }
//! impl ParameterDependent for SCurve {
//!     fn parameter(&self) -> f64 { self.p }
//!     fn set_parameter(&mut self, p: f64) { self.p = p; }
//! }
//!
//! let mut problem = SCurve { p: -1.0 };
//! let mut solver = FaerDenseLu::new();
//! let options = ContinuationOptions { parameter_min: -1.0, parameter_max: 1.0, ..Default::default() };
//! let branch = Continuation::new(&mut problem, &mut solver, &[-1.3], -1.0, options)
//!     .unwrap()
//!     .run()
//!     .unwrap();
//! assert_eq!(branch.fold_parameters().len(), 2);
//! assert!(matches!(branch.termination, ContinuationTermination::ReachedBound { .. }));
//! ```

use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{Mat, MatMut};

use crate::linalg::{check_pivots, DenseAssemble, LinearSolveError, DEFAULT_PIVOT_THRESHOLD};
use crate::linesearch::{backtrack, LineSearchOptions};
use crate::newton::{NewtonError, NewtonOptions, NewtonSolver, Termination, WorkCounters};
use crate::{GeneralizedJacobian, LinearSolve, ParameterDependent};

/// Relative size below which the block-elimination pivot `w_p - w_x·a` is treated as zero:
/// `|w_p - w_x·a| <= BORDER_PIVOT_THRESHOLD (|w_p| + |w_x| |a|)`.
pub const BORDER_PIVOT_THRESHOLD: f64 = 1e-12;

/// In which direction of the parameter the branch is followed from the starting point.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Direction {
    /// The first step increases the parameter (default).
    #[default]
    Increasing,
    /// The first step decreases the parameter.
    Decreasing,
}

impl Direction {
    fn sign(self) -> f64 {
        match self {
            Direction::Increasing => 1.0,
            Direction::Decreasing => -1.0,
        }
    }
}

/// How the next point is predicted from the last accepted one.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Predictor {
    /// Along the secant through the last two accepted points (default; the first step
    /// always uses the tangent).
    #[default]
    Secant,
    /// Along the tangent at the last accepted point (from the corrector's last
    /// factorization, no extra cost).
    Tangent,
}

/// Options of the pseudo-arclength continuation. Build with struct update syntax from
/// [`Default`] and check with [`ContinuationOptions::validate`] (done by
/// [`Continuation::new`]).
///
/// Step lengths are measured in the `theta`-weighted norm of the module documentation.
#[derive(Clone, Debug, PartialEq)]
pub struct ContinuationOptions {
    /// First step length `ds`. Default `0.01`.
    pub initial_step: f64,
    /// Smallest step length; a failure at this step ends the run. Default `0.002`
    /// (NLvib's habit: `ds/5 .. 5 ds` around the initial step).
    pub min_step: f64,
    /// Largest step length. Default `0.05`.
    pub max_step: f64,
    /// Corrector iterations the step control aims at: after `k` iterations the step is
    /// multiplied by `sqrt(target / k)` clamped to `[1/2, 2]`. Default `3`.
    pub target_iterations: usize,
    /// Corrector iterations (factorizations) allowed per attempted step. Default `10`.
    pub max_corrector_iterations: usize,
    /// The corrector has converged when the 2-norm `|F(x, p)| <= corrector_tolerance`
    /// (after at least one Newton correction). Default `1e-10`.
    pub corrector_tolerance: f64,
    /// The corrector gives up (stalled) when a correction has `|dy|_θ <= step_tolerance
    /// (1 + |y|_θ)` while `|F|` is still above the tolerance. Default `1e-14`.
    pub step_tolerance: f64,
    /// Lower bound of the parameter: the run stops when the branch goes below it.
    /// Default `-inf` (no bound).
    pub parameter_min: f64,
    /// Upper bound of the parameter: the run stops when the branch goes above it.
    /// Default `+inf` (no bound).
    pub parameter_max: f64,
    /// Largest number of accepted points, the starting point included. Default `1000`.
    pub max_points: usize,
    /// Failed attempts in a row (each halving the step) after which the run stops.
    /// Default `3` (NLvib).
    pub max_consecutive_failures: usize,
    /// Weight `θ` in `(0, 1)` between the state (`θ/n` per component) and the parameter
    /// (`1 - θ`) in the arclength. Default `0.5`.
    pub theta: f64,
    /// Typical magnitude `s_i > 0` of each unknown (length `n`): the state part of the
    /// inner product becomes `(θ/n) Σ a_i b_i / s_i^2`, so that unknowns of different
    /// units (displacements and contact forces) weigh alike. Default `None` (all `1`).
    pub state_scale: Option<Vec<f64>>,
    /// Direction of the parameter on the first step. Default [`Direction::Increasing`].
    pub direction: Direction,
    /// Predictor after the first step. Default [`Predictor::Secant`].
    pub predictor: Predictor,
    /// Backtracking (Armijo) on the corrector's merit `(|F|^2 + N^2) / 2` along each
    /// bordered Newton correction; `None` takes full steps. Default `None` (the predictor
    /// is usually close enough; a line search helps nonsmooth problems whose full steps
    /// jump between active sets, and a poor starting guess).
    pub corrector_line_search: Option<LineSearchOptions>,
    /// Locate folds by cubic Hermite interpolation of `p(s)` between the two points that
    /// bracket the sign change (otherwise the fold is reported at the extreme point of the
    /// accepted points). Default `true`.
    pub refine_folds: bool,
    /// When the step has been halved to its end (the run would stop), try once to pass a
    /// corner of a piecewise-smooth branch (see the module documentation, *Corners*)
    /// before giving up. Default `true`.
    pub pass_corners: bool,
}

impl Default for ContinuationOptions {
    fn default() -> Self {
        Self {
            initial_step: 0.01,
            min_step: 0.002,
            max_step: 0.05,
            target_iterations: 3,
            max_corrector_iterations: 10,
            corrector_tolerance: 1e-10,
            step_tolerance: 1e-14,
            parameter_min: f64::NEG_INFINITY,
            parameter_max: f64::INFINITY,
            max_points: 1000,
            max_consecutive_failures: 3,
            theta: 0.5,
            state_scale: None,
            direction: Direction::Increasing,
            predictor: Predictor::Secant,
            corrector_line_search: None,
            refine_folds: true,
            pass_corners: true,
        }
    }
}

impl ContinuationOptions {
    /// NLvib-like step settings around `ds`: `initial_step = ds`, `min_step = ds / 5`,
    /// `max_step = 5 ds`, other fields at their defaults.
    pub fn with_step(ds: f64) -> Self {
        Self {
            initial_step: ds,
            min_step: ds / 5.0,
            max_step: 5.0 * ds,
            ..Self::default()
        }
    }

    /// Checks every field; the error names the field, its value and what is allowed.
    pub fn validate(&self) -> Result<(), ContinuationError> {
        fn invalid(name: &'static str, value: f64, allowed: &'static str) -> ContinuationError {
            ContinuationError::InvalidOption {
                name,
                value,
                allowed,
            }
        }
        let positive_finite = |name, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(invalid(name, v, "finite and > 0"))
            }
        };
        positive_finite("min_step", self.min_step)?;
        positive_finite("max_step", self.max_step)?;
        positive_finite("initial_step", self.initial_step)?;
        if self.max_step < self.min_step {
            return Err(invalid("max_step", self.max_step, ">= min_step"));
        }
        if self.initial_step < self.min_step || self.initial_step > self.max_step {
            return Err(invalid(
                "initial_step",
                self.initial_step,
                "within [min_step, max_step]",
            ));
        }
        if self.target_iterations == 0 {
            return Err(invalid("target_iterations", 0.0, ">= 1"));
        }
        if self.max_corrector_iterations == 0 {
            return Err(invalid("max_corrector_iterations", 0.0, ">= 1"));
        }
        positive_finite("corrector_tolerance", self.corrector_tolerance)?;
        if !(self.step_tolerance.is_finite() && self.step_tolerance >= 0.0) {
            return Err(invalid(
                "step_tolerance",
                self.step_tolerance,
                "finite and >= 0",
            ));
        }
        if self.parameter_min.is_nan() || self.parameter_min == f64::INFINITY {
            return Err(invalid(
                "parameter_min",
                self.parameter_min,
                "a number or -inf",
            ));
        }
        if self.parameter_max.is_nan() || self.parameter_max == f64::NEG_INFINITY {
            return Err(invalid(
                "parameter_max",
                self.parameter_max,
                "a number or +inf",
            ));
        }
        if self.parameter_max <= self.parameter_min {
            return Err(invalid(
                "parameter_max",
                self.parameter_max,
                "> parameter_min",
            ));
        }
        if self.max_points == 0 {
            return Err(invalid("max_points", 0.0, ">= 1"));
        }
        if self.max_consecutive_failures == 0 {
            return Err(invalid("max_consecutive_failures", 0.0, ">= 1"));
        }
        if !(self.theta > 0.0 && self.theta < 1.0) {
            return Err(invalid("theta", self.theta, "in the open interval (0, 1)"));
        }
        if let Some(scale) = &self.state_scale {
            if let Some(&bad) = scale.iter().find(|s| !(s.is_finite() && **s > 0.0)) {
                return Err(invalid("state_scale", bad, "finite and > 0 entries"));
            }
        }
        if let Some(ls) = &self.corrector_line_search {
            ls.validate().map_err(|e| {
                let name = match e.name {
                    "sufficient_decrease" => "corrector_line_search.sufficient_decrease",
                    "shrink" => "corrector_line_search.shrink",
                    _ => "corrector_line_search.min_step",
                };
                invalid(name, e.value, e.allowed)
            })?;
        }
        Ok(())
    }
}

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
    /// it changes sign at folds.
    pub tangent_parameter: f64,
}

/// Something noticed along the branch.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum ContinuationEvent {
    /// The parameter turns back (see [`FoldDetector`]): on a smooth branch `t_p` changed
    /// sign between points `index - 1` and `index`; at a corner of a piecewise-smooth branch
    /// `index` is the extreme point itself.
    Fold {
        /// Index (in the branch) of the first point after the sign change of `t_p`, or of
        /// the extreme point where `t_p` did not change sign.
        index: usize,
        /// Parameter at the fold (refined by interpolation when
        /// [`ContinuationOptions::refine_folds`] is set).
        parameter: f64,
    },
}

/// Why a corrector attempt failed (the step is then rejected).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
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
pub enum ContinuationTermination {
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
}

impl std::fmt::Display for ContinuationTermination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
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
        }
    }
}

/// Work done by a continuation run.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ContinuationCounters {
    /// The Newton-style counters: residual evaluations (line-search trials included),
    /// Jacobian evaluations and `factor` calls (one each per corrector iteration), solves
    /// (two per corrector iteration with block elimination), corrector line-search
    /// backtracks, and the FFTs the problem counted during the run.
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
    }
}

/// A computed branch.
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    /// Accepted points in branch order, the corrected starting point first.
    pub points: Vec<BranchPoint>,
    /// Events (folds) in branch order.
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
        self.events
            .iter()
            .map(|e| match e {
                ContinuationEvent::Fold { parameter, .. } => *parameter,
            })
            .collect()
    }

    /// Maps every point to a user quantity (an amplitude, a norm), in branch order.
    pub fn measure<T>(&self, f: impl FnMut(&BranchPoint) -> T) -> Vec<T> {
        self.points.iter().map(f).collect()
    }
}

/// Why a continuation could not run.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
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
    /// The Newton options of a natural sweep are invalid (or the state has the wrong
    /// length).
    #[error(transparent)]
    Newton(#[from] NewtonError),
    /// The starting point could not be corrected at fixed parameter.
    #[error("the starting point could not be corrected at p = {parameter}: {failure}")]
    StartNotConverged {
        /// The starting parameter.
        parameter: f64,
        /// Why the corrector failed.
        failure: CorrectorFailure,
    },
}

/// Writes a Jacobian as a dense matrix (the dense-fallback capability).
type DenseAssembler<J> = fn(&J, MatMut<'_, f64>);

/// Buffers reused by every corrector iteration.
struct Work<J> {
    n: usize,
    theta: f64,
    /// `1 / s_i^2` from [`ContinuationOptions::state_scale`] (empty: all ones).
    weights: Vec<f64>,
    jac: J,
    f: Vec<f64>,
    fp: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    /// Line-search trial state.
    trial: Vec<f64>,
    /// θ-weighted constraint row `w_x`.
    w: Vec<f64>,
    /// Raw (unnormalised) tangent from the last iteration, length `n + 1`, with positive
    /// inner product with the constraint row.
    tangent: Vec<f64>,
    /// Dense bordered matrix (allocated on first fallback).
    dense: Option<Mat<f64>>,
}

impl<J> Work<J> {
    fn new(n: usize, theta: f64, scale: Option<&[f64]>, jac: J) -> Self {
        Self {
            n,
            theta,
            weights: scale
                .map(|s| s.iter().map(|v| 1.0 / (v * v)).collect())
                .unwrap_or_default(),
            jac,
            f: vec![0.0; n],
            fp: vec![0.0; n],
            a: vec![0.0; n],
            b: vec![0.0; n],
            trial: vec![0.0; n],
            w: vec![0.0; n],
            tangent: vec![0.0; n + 1],
            dense: None,
        }
    }

    /// `<(ax, ap), (bx, bp)>_θ`.
    fn dot(&self, ax: &[f64], ap: f64, bx: &[f64], bp: f64) -> f64 {
        let s: f64 = if self.weights.is_empty() {
            ax.iter().zip(bx).map(|(u, v)| u * v).sum()
        } else {
            ax.iter()
                .zip(bx)
                .zip(&self.weights)
                .map(|((u, v), w)| u * v * w)
                .sum()
        };
        self.theta / self.n as f64 * s + (1.0 - self.theta) * ap * bp
    }
    fn norm(&self, x: &[f64], p: f64) -> f64 {
        self.dot(x, p, x, p).sqrt()
    }
}

/// The extra equation `N(y) = w_x·x + w_p p - target` (with `w_x = 0` when `arclength` is
/// false: the parameter is then fixed at `target / w_p`).
#[derive(Clone, Copy)]
struct Constraint {
    arclength: bool,
    w_p: f64,
    target: f64,
}

struct Corrected {
    iterations: usize,
    residual_norm: f64,
}

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|u| u * u).sum::<f64>().sqrt()
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|u| u.is_finite())
}

/// Newton on `[F; N] = 0`. On success `x`, `p` hold the converged point, `ws.tangent` the
/// raw tangent and the problem's parameter equals `p`. On failure the caller restores the
/// parameter. `smallest` receives the smallest finite `|F|` seen.
#[allow(clippy::too_many_arguments)]
fn correct<P, S>(
    problem: &mut P,
    solver: &mut S,
    ws: &mut Work<P::Jacobian>,
    fallback: Option<DenseAssembler<P::Jacobian>>,
    options: &ContinuationOptions,
    x: &mut [f64],
    p: &mut f64,
    constraint: Constraint,
    counters: &mut ContinuationCounters,
    smallest: &mut f64,
) -> Result<Corrected, CorrectorFailure>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: LinearSolve<P::Jacobian> + ?Sized,
{
    let n = ws.n;
    *smallest = f64::INFINITY;
    let mut last_step_norm = f64::INFINITY;
    // Whether ws.f already holds F at (x, p) (the line search's accepted trial).
    let mut fresh = false;
    for k in 0..=options.max_corrector_iterations {
        problem.set_parameter(*p);
        if !fresh {
            problem.residual(x, &mut ws.f);
            counters.work.residual_evaluations += 1;
        }
        fresh = false;
        if !all_finite(&ws.f) {
            return Err(CorrectorFailure::NonFinite { iteration: k });
        }
        let r = norm2(&ws.f);
        *smallest = smallest.min(r);
        if k >= 1 && r <= options.corrector_tolerance {
            return Ok(Corrected {
                iterations: k,
                residual_norm: r,
            });
        }
        if k == options.max_corrector_iterations {
            return Err(CorrectorFailure::MaxIterations {
                iterations: k,
                residual_norm: r,
            });
        }
        if k >= 1 && last_step_norm <= options.step_tolerance * (1.0 + ws.norm(x, *p)) {
            return Err(CorrectorFailure::Stalled {
                iteration: k,
                residual_norm: r,
                step_norm: last_step_norm,
            });
        }
        let w_x_dot_x: f64 = if constraint.arclength {
            ws.w.iter().zip(x.iter()).map(|(u, v)| u * v).sum()
        } else {
            0.0
        };
        let n_value = w_x_dot_x + constraint.w_p * *p - constraint.target;

        problem.jacobian(x, &mut ws.jac);
        counters.work.jacobian_evaluations += 1;
        problem.residual_parameter_derivative(x, &mut ws.fp);
        counters.parameter_derivative_evaluations += 1;
        // The default F_p moves the parameter and restores it; make sure it is ours.
        problem.set_parameter(*p);
        if !all_finite(&ws.fp) {
            return Err(CorrectorFailure::NonFinite { iteration: k });
        }
        counters.corrector_iterations += 1;
        counters.work.factorizations += 1;
        let block = match solver.factor(&ws.jac) {
            Ok(()) => block_elimination(solver, ws, constraint, n_value, counters, k)?,
            Err(error) => BlockOutcome::NeedsFallback(CorrectorFailure::LinearSolve {
                iteration: k,
                error,
            }),
        };
        let dp = match block {
            BlockOutcome::Step(dp) => dp,
            BlockOutcome::NeedsFallback(failure) => match fallback {
                Some(assemble) => {
                    counters.dense_bordered_factorizations += 1;
                    dense_bordered(assemble, ws, constraint, n_value).map_err(|error| {
                        CorrectorFailure::LinearSolve {
                            iteration: k,
                            error,
                        }
                    })?
                }
                None => return Err(failure),
            },
        };
        // ws.b holds dx.
        if !all_finite(&ws.b) || !dp.is_finite() || !all_finite(&ws.tangent) {
            return Err(CorrectorFailure::NonFinite { iteration: k });
        }
        let mut alpha = 1.0;
        if let Some(ls) = &options.corrector_line_search {
            let merit0 = 0.5 * (r * r + n_value * n_value);
            let mut evaluations = 0;
            let searched = backtrack(merit0, -2.0 * merit0, ls, |t| {
                for ((yi, xi), di) in ws.trial.iter_mut().zip(x.iter()).zip(&ws.b) {
                    *yi = xi + t * di;
                }
                problem.set_parameter(*p + t * dp);
                problem.residual(&ws.trial, &mut ws.f);
                evaluations += 1;
                // N is linear: after a fraction t of the correction it is (1 - t) N.
                let nt = (1.0 - t) * n_value;
                0.5 * (ws.f.iter().map(|v| v * v).sum::<f64>() + nt * nt)
            });
            counters.work.residual_evaluations += evaluations;
            match searched {
                Ok(accepted) => {
                    counters.work.line_search_backtracks += accepted.backtracks;
                    alpha = accepted.step;
                    fresh = true;
                }
                Err(failed) => {
                    counters.work.line_search_backtracks += failed.backtracks;
                    return Err(CorrectorFailure::LineSearchFailed {
                        iteration: k,
                        residual_norm: r,
                        last_step: failed.last_step,
                    });
                }
            }
        }
        for (xi, di) in x.iter_mut().zip(&ws.b) {
            *xi += alpha * di;
        }
        *p += alpha * dp;
        last_step_norm = alpha * ws.norm(&ws.b, dp);
        debug_assert_eq!(ws.tangent.len(), n + 1);
    }
    // Not reached: the loop returns at k == max_corrector_iterations.
    Err(CorrectorFailure::MaxIterations {
        iterations: options.max_corrector_iterations,
        residual_norm: *smallest,
    })
}

enum BlockOutcome {
    /// `ws.b` holds `dx`; the value is `dp`.
    Step(f64),
    NeedsFallback(CorrectorFailure),
}

/// Block elimination with the current factorization: `J a = F_p`, `J b = F`,
/// `dp = (w_x·b - N) / (w_p - w_x·a)`, `dx = -b - a dp` (written into `ws.b`), raw tangent
/// `sign(pivot) (-a, 1)`.
fn block_elimination<J, S>(
    solver: &mut S,
    ws: &mut Work<J>,
    constraint: Constraint,
    n_value: f64,
    counters: &mut ContinuationCounters,
    k: usize,
) -> Result<BlockOutcome, CorrectorFailure>
where
    S: LinearSolve<J> + ?Sized,
{
    let n = ws.n;
    ws.a.copy_from_slice(&ws.fp);
    ws.b.copy_from_slice(&ws.f);
    counters.work.linear_solves += 2;
    for rhs in [&mut ws.a, &mut ws.b] {
        if let Err(error) = solver.solve_in_place(rhs) {
            return Ok(BlockOutcome::NeedsFallback(CorrectorFailure::LinearSolve {
                iteration: k,
                error,
            }));
        }
    }
    if !all_finite(&ws.a) || !all_finite(&ws.b) {
        return Err(CorrectorFailure::NonFinite { iteration: k });
    }
    let (w_a, w_b, w_norm) = if constraint.arclength {
        let wa: f64 = ws.w.iter().zip(&ws.a).map(|(u, v)| u * v).sum();
        let wb: f64 = ws.w.iter().zip(&ws.b).map(|(u, v)| u * v).sum();
        (wa, wb, norm2(&ws.w))
    } else {
        (0.0, 0.0, 0.0)
    };
    let pivot = constraint.w_p - w_a;
    let scale = constraint.w_p.abs() + w_norm * norm2(&ws.a);
    if !pivot.is_finite() || pivot.abs() <= BORDER_PIVOT_THRESHOLD * scale {
        return Ok(BlockOutcome::NeedsFallback(
            CorrectorFailure::SingularBorder {
                iteration: k,
                pivot,
            },
        ));
    }
    let dp = (w_b - n_value) / pivot;
    let sign = pivot.signum();
    for i in 0..n {
        ws.tangent[i] = -sign * ws.a[i];
        ws.b[i] = -ws.b[i] - ws.a[i] * dp;
    }
    ws.tangent[n] = sign;
    Ok(BlockOutcome::Step(dp))
}

/// Dense LU of the assembled bordered matrix `[[J, F_p], [w_x^T, w_p]]`: the correction
/// (`dx` into `ws.b`, `dp` returned) and the raw tangent (kernel of `[J, F_p]` normalised by
/// `w·t = 1`).
fn dense_bordered<J>(
    assemble: DenseAssembler<J>,
    ws: &mut Work<J>,
    constraint: Constraint,
    n_value: f64,
) -> Result<f64, LinearSolveError> {
    let n = ws.n;
    let mut m = ws.dense.take().unwrap_or_else(|| Mat::zeros(n + 1, n + 1));
    assemble(&ws.jac, m.as_mut().submatrix_mut(0, 0, n, n));
    for i in 0..n {
        m[(i, n)] = ws.fp[i];
        m[(n, i)] = if constraint.arclength { ws.w[i] } else { 0.0 };
    }
    m[(n, n)] = constraint.w_p;
    let result = (|| {
        for j in 0..=n {
            for i in 0..=n {
                let value = m[(i, j)];
                if !value.is_finite() {
                    return Err(LinearSolveError::NonFiniteEntry {
                        row: i,
                        col: j,
                        value,
                    });
                }
            }
        }
        let lu = PartialPivLu::new(m.as_ref());
        let u = lu.U();
        check_pivots((0..=n).map(|i| u[(i, i)]), DEFAULT_PIVOT_THRESHOLD)?;
        let mut rhs = Mat::<f64>::zeros(n + 1, 2);
        for i in 0..n {
            rhs[(i, 0)] = -ws.f[i];
        }
        rhs[(n, 0)] = -n_value;
        rhs[(n, 1)] = 1.0;
        lu.solve_in_place(rhs.as_mut());
        for i in 0..n {
            ws.b[i] = rhs[(i, 0)];
        }
        for i in 0..=n {
            ws.tangent[i] = rhs[(i, 1)];
        }
        Ok(rhs[(n, 0)])
    })();
    ws.dense = Some(m);
    result
}

/// Parameter at the fold between two points, from the cubic Hermite interpolant of `p(s)`
/// with values `p0, p1` and slopes `m0, m1` (opposite signs) over the θ-length `h`.
fn hermite_fold(p0: f64, m0: f64, p1: f64, m1: f64, h: f64) -> f64 {
    // p'(τ) = A τ² + B τ + C on τ in [0, 1]; C = h m0 and p'(1) = h m1 have opposite signs.
    let a = 6.0 * p0 + 3.0 * h * m0 - 6.0 * p1 + 3.0 * h * m1;
    let b = -6.0 * p0 - 4.0 * h * m0 + 6.0 * p1 - 2.0 * h * m1;
    let c = h * m0;
    let dp = |t: f64| (a * t + b) * t + c;
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    let lo_sign = dp(lo).signum();
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if dp(mid).signum() == lo_sign {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t = 0.5 * (lo + hi);
    let (t2, t3) = (t * t, t * t * t);
    let h00 = 2.0 * t3 - 3.0 * t2 + 1.0;
    let h10 = t3 - 2.0 * t2 + t;
    let h01 = -2.0 * t3 + 3.0 * t2;
    let h11 = t3 - t2;
    let value = h00 * p0 + h10 * h * m0 + h01 * p1 + h11 * h * m1;
    if value.is_finite() {
        value
    } else {
        p1
    }
}

/// One accepted point as the fold detector sees it.
#[derive(Clone, Copy, Debug)]
struct FoldSample {
    parameter: f64,
    tangent_parameter: f64,
    /// θ-length of the chord from the previous point.
    chord: f64,
}

/// Fold detection along a sequence of accepted points.
///
/// A fold is a local extremum of the parameter along the branch: the increments
/// `p_k - p_{k-1}` change sign at the extreme point `k`. On a smooth branch the tangent's
/// parameter component `t_p` changes sign between `k - 1` and `k` or between `k` and `k + 1`;
/// the fold is then located by cubic Hermite interpolation of `p(s)` on that interval (when
/// refinement is asked for and the interpolated extremum lies beyond `p_k`, within the
/// reach of the neighbouring steps), otherwise reported at the extreme point `p_k`. A reversal without such a sign change (a fold at a corner of a
/// piecewise-smooth branch) is reported at `p_k`. A sign change of `t_p` without a reversal
/// of the increments (a generalized Jacobian taken on the other side of a corner, where
/// the tangent of the neighbouring piece points backwards) is no fold.
///
/// A fold is confirmed by the first point after the extremum, so it is reported one point
/// late; a fold at the last point of a branch is not reported.
#[derive(Clone, Debug)]
pub struct FoldDetector {
    refine: bool,
    /// The last three points (oldest first).
    recent: Vec<FoldSample>,
    /// Index of the newest point in `recent`.
    newest: usize,
    /// Sign of the last non-zero parameter increment.
    increment_sign: f64,
}

impl FoldDetector {
    /// A detector; `refine` locates folds by Hermite interpolation.
    pub fn new(refine: bool) -> Self {
        Self {
            refine,
            recent: Vec::with_capacity(3),
            newest: 0,
            increment_sign: 0.0,
        }
    }

    /// Adds the next accepted point: its parameter, the parameter component of its unit
    /// tangent oriented along the branch, and the θ-length of the chord from the previous
    /// point (ignored for the first). Returns the fold this point confirms, if any; its
    /// `index` counts the points pushed (from 0).
    pub fn push(
        &mut self,
        parameter: f64,
        tangent_parameter: f64,
        chord: f64,
    ) -> Option<ContinuationEvent> {
        let sample = FoldSample {
            parameter,
            tangent_parameter,
            chord,
        };
        if self.recent.is_empty() {
            self.recent.push(sample);
            self.newest = 0;
            return None;
        }
        self.newest += 1;
        if self.recent.len() == 3 {
            self.recent.remove(0);
        }
        self.recent.push(sample);
        let m = self.recent.len();
        let increment = parameter - self.recent[m - 2].parameter;
        if increment == 0.0 {
            return None;
        }
        let sign = increment.signum();
        let previous = std::mem::replace(&mut self.increment_sign, sign);
        if previous == 0.0 || previous == sign {
            return None;
        }
        // The extreme point is the one before this increment.
        let extreme = self.recent[m - 2];
        let extreme_index = self.newest - 1;
        // Intervals [k-1, k] and [k, k+1] around the extreme k, as (left, right, index of
        // right); a sign change of t_p from `previous` to `sign` brackets a smooth fold.
        let mut brackets = Vec::with_capacity(2);
        if m == 3 {
            brackets.push((self.recent[0], self.recent[1], extreme_index));
        }
        brackets.push((self.recent[m - 2], self.recent[m - 1], self.newest));
        let bracket = brackets.into_iter().find(|(a, b, _)| {
            a.tangent_parameter.signum() == previous && b.tangent_parameter.signum() == sign
        });
        let reach = if m == 3 {
            (extreme.parameter - self.recent[0].parameter)
                .abs()
                .max(increment.abs())
        } else {
            increment.abs()
        };
        let (index, parameter) = match bracket {
            Some((a, b, index)) if self.refine && b.chord > 0.0 => {
                let p = hermite_fold(
                    a.parameter,
                    a.tangent_parameter,
                    b.parameter,
                    b.tangent_parameter,
                    b.chord,
                );
                let beyond = (p - extreme.parameter) * previous;
                if beyond >= 0.0 && beyond <= reach {
                    (index, p)
                } else {
                    (index, extreme.parameter)
                }
            }
            _ => (extreme_index, extreme.parameter),
        };
        Some(ContinuationEvent::Fold { index, parameter })
    }
}

enum Phase {
    NotStarted { x0: Vec<f64>, p0: f64 },
    Running,
    Finished,
}

/// Pseudo-arclength continuation as an iterator over accepted [`BranchPoint`]s.
///
/// The first item is the starting point corrected at fixed `p0` by the continuation's own
/// corrector (Newton, with the line search of
/// [`ContinuationOptions::corrector_line_search`] if set; from a poor guess, solve first
/// with [`crate::newton`]). An `Err` item
/// (the start could not be corrected) ends the iteration. When the iteration ends,
/// [`Continuation::termination`] says why, [`Continuation::events`] lists the folds and the
/// problem's parameter is that of the last accepted point.
pub struct Continuation<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: LinearSolve<P::Jacobian> + ?Sized,
{
    problem: &'a mut P,
    solver: &'a mut S,
    options: ContinuationOptions,
    fallback: Option<DenseAssembler<P::Jacobian>>,
    ws: Work<P::Jacobian>,
    phase: Phase,
    /// Last accepted point.
    last: Option<BranchPoint>,
    /// Unit tangent at the last accepted point (length n + 1).
    tangent: Vec<f64>,
    /// Unit predictor direction for the next step (length n + 1).
    direction: Vec<f64>,
    step: f64,
    points: usize,
    consecutive_failures: usize,
    /// Sign of the last non-zero tangent parameter component.
    folds: FoldDetector,
    events: Vec<ContinuationEvent>,
    termination: Option<ContinuationTermination>,
    counters: ContinuationCounters,
    fft_start: u64,
}

impl<'a, P, S> Continuation<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: LinearSolve<P::Jacobian> + ?Sized,
{
    /// Prepares a continuation from the guess `x0` at parameter `p0`. Checks the options,
    /// the dimension and that `p0` is finite and within the bounds; the work starts with the
    /// first call of [`Iterator::next`].
    pub fn new(
        problem: &'a mut P,
        solver: &'a mut S,
        x0: &[f64],
        p0: f64,
        options: ContinuationOptions,
    ) -> Result<Self, ContinuationError> {
        options.validate()?;
        let n = problem.dim();
        if n == 0 || x0.len() != n {
            return Err(ContinuationError::DimensionMismatch {
                expected: n,
                found: x0.len(),
            });
        }
        if !p0.is_finite() || p0 < options.parameter_min || p0 > options.parameter_max {
            return Err(ContinuationError::InvalidStart {
                parameter: p0,
                min: options.parameter_min,
                max: options.parameter_max,
            });
        }
        if let Some(scale) = &options.state_scale {
            if scale.len() != n {
                return Err(ContinuationError::InvalidOption {
                    name: "state_scale",
                    value: scale.len() as f64,
                    allowed: "one entry per unknown (the problem's dimension)",
                });
            }
        }
        let ws = Work::new(
            n,
            options.theta,
            options.state_scale.as_deref(),
            problem.new_jacobian(),
        );
        let fft_start = problem.fft_count();
        let folds = FoldDetector::new(options.refine_folds);
        Ok(Self {
            problem,
            solver,
            step: options.initial_step,
            options,
            fallback: None,
            ws,
            phase: Phase::NotStarted {
                x0: x0.to_vec(),
                p0,
            },
            last: None,
            tangent: vec![0.0; n + 1],
            direction: vec![0.0; n + 1],
            points: 0,
            consecutive_failures: 0,
            folds,
            events: Vec::new(),
            termination: None,
            counters: ContinuationCounters::default(),
            fft_start,
        })
    }

    /// Why the run stopped (`None` while it runs, or after a start failure).
    pub fn termination(&self) -> Option<&ContinuationTermination> {
        self.termination.as_ref()
    }

    /// Events found so far.
    pub fn events(&self) -> &[ContinuationEvent] {
        &self.events
    }

    /// Work done so far.
    pub fn counters(&self) -> ContinuationCounters {
        let mut c = self.counters;
        c.work.ffts = self.problem.fft_count().saturating_sub(self.fft_start);
        c
    }

    /// The problem (its parameter is that of the last accepted point between items), e.g.
    /// to evaluate user quantities at the point just returned.
    pub fn problem(&self) -> &P {
        self.problem
    }

    /// The step length the next attempt will use.
    pub fn next_step(&self) -> f64 {
        self.step
    }

    /// Runs to the end and collects the branch.
    pub fn run(mut self) -> Result<Branch, ContinuationError> {
        let mut points = Vec::new();
        for item in self.by_ref() {
            points.push(item?);
        }
        let termination = self
            .termination
            .clone()
            .unwrap_or(ContinuationTermination::MaxPoints {
                points: points.len(),
            });
        Ok(Branch {
            points,
            events: std::mem::take(&mut self.events),
            termination,
            counters: self.counters(),
        })
    }

    fn finish(&mut self, termination: ContinuationTermination) {
        self.termination = Some(termination);
        self.phase = Phase::Finished;
    }

    /// Normalises `ws.tangent` in the θ-norm into `self.tangent`, oriented to have a
    /// non-negative inner product with `(ref_x, ref_p)`.
    fn take_tangent(&mut self, reference: Option<&[f64]>, ref_p: f64) {
        let n = self.ws.n;
        let norm = self.ws.norm(&self.ws.tangent[..n], self.ws.tangent[n]);
        let mut t: Vec<f64> = self.ws.tangent.iter().map(|v| v / norm).collect();
        let orientation = match reference {
            Some(r) => self.ws.dot(&t[..n], t[n], &r[..n], r[n]),
            None => t[n] * ref_p,
        };
        if orientation < 0.0 {
            for v in &mut t {
                *v = -*v;
            }
        }
        self.tangent = t;
    }

    /// [`correct`] on this run's problem, solver, workspace and counters.
    fn correct_at(
        &mut self,
        x: &mut [f64],
        p: &mut f64,
        constraint: Constraint,
        smallest: &mut f64,
    ) -> Result<Corrected, CorrectorFailure> {
        correct(
            &mut *self.problem,
            &mut *self.solver,
            &mut self.ws,
            self.fallback,
            &self.options,
            x,
            p,
            constraint,
            &mut self.counters,
            smallest,
        )
    }

    fn start(&mut self, x0: Vec<f64>, p0: f64) -> Result<BranchPoint, ContinuationError> {
        let mut x = x0;
        let mut p = p0;
        let mut smallest = f64::INFINITY;
        let constraint = Constraint {
            arclength: false,
            w_p: 1.0,
            target: p0,
        };
        let corrected = self.correct_at(&mut x, &mut p, constraint, &mut smallest);
        let corrected = match corrected {
            Ok(c) => c,
            Err(failure) => {
                self.problem.set_parameter(p0);
                self.phase = Phase::Finished;
                return Err(ContinuationError::StartNotConverged {
                    parameter: p0,
                    failure,
                });
            }
        };
        self.take_tangent(None, self.options.direction.sign());
        self.direction.copy_from_slice(&self.tangent);
        let n = self.ws.n;
        let point = BranchPoint {
            state: x,
            parameter: p,
            iterations: corrected.iterations,
            residual_norm: corrected.residual_norm,
            step: 0.0,
            tangent_parameter: self.tangent[n],
        };
        self.folds
            .push(point.parameter, point.tangent_parameter, 0.0);
        self.last = Some(point.clone());
        self.points = 1;
        self.phase = Phase::Running;
        if self.points >= self.options.max_points {
            self.finish(ContinuationTermination::MaxPoints {
                points: self.points,
            });
        }
        Ok(point)
    }

    /// Attempts steps until one is accepted (`Some`) or the run ends (`None`).
    fn advance(&mut self) -> Option<BranchPoint> {
        let n = self.ws.n;
        let last = self.last.clone()?;
        let mut x = vec![0.0; n];
        loop {
            let ds = self.step;
            for ((xi, si), di) in x.iter_mut().zip(&last.state).zip(&self.direction) {
                *xi = si + ds * di;
            }
            self.direction_weights();
            let mut p = last.parameter + ds * self.direction[n];
            let w_p = (1.0 - self.options.theta) * self.direction[n];
            let w_dot_last: f64 = self
                .ws
                .w
                .iter()
                .zip(&last.state)
                .map(|(u, v)| u * v)
                .sum::<f64>()
                + w_p * last.parameter;
            let constraint = Constraint {
                arclength: true,
                w_p,
                target: w_dot_last + ds,
            };
            let mut smallest = f64::INFINITY;
            let before = self.counters.corrector_iterations;
            let corrected = self.correct_at(&mut x, &mut p, constraint, &mut smallest);
            match corrected {
                Ok(c) => return self.accept(&last, x, p, ds, c, None),
                Err(failure) => {
                    self.reject(before, last.parameter);
                    self.consecutive_failures += 1;
                    let ending = ds <= self.options.min_step
                        || self.consecutive_failures >= self.options.max_consecutive_failures;
                    if ending && self.options.pass_corners {
                        if let Some(point) = self.pass_corner(&last, ds) {
                            return point;
                        }
                    }
                    if ds <= self.options.min_step {
                        self.finish(ContinuationTermination::StepTooSmall {
                            parameter: last.parameter,
                            step: ds,
                            residual_norm: smallest,
                            failure,
                        });
                        return None;
                    }
                    if self.consecutive_failures >= self.options.max_consecutive_failures {
                        self.finish(ContinuationTermination::TooManyFailures {
                            parameter: last.parameter,
                            step: ds,
                            failures: self.consecutive_failures,
                            residual_norm: smallest,
                            failure,
                        });
                        return None;
                    }
                    self.step = (0.5 * ds).max(self.options.min_step);
                }
            }
        }
    }

    /// `ws.w = (θ/n) s⁻² ⊙ d_x`: the state part of the normal of the arclength constraint
    /// along the current direction `d` (`s` the state scale, 1 without one).
    fn direction_weights(&mut self) {
        let theta_x = self.options.theta / self.ws.n as f64;
        for (i, (wi, di)) in self.ws.w.iter_mut().zip(&self.direction).enumerate() {
            *wi = theta_x * di * self.ws.weights.get(i).copied().unwrap_or(1.0);
        }
    }

    /// Books a rejected attempt (begun at `before` corrector iterations) and restores the
    /// problem's parameter to the last accepted point's.
    fn reject(&mut self, before: u64, parameter: f64) {
        self.counters.rejected_steps += 1;
        self.counters.rejected_iterations += self.counters.corrector_iterations - before;
        self.problem.set_parameter(parameter);
    }

    /// The corner passes of the module documentation (*Corners*), with step `ds` from
    /// `last` along the current direction: first on the hyperplane normal to the direction's
    /// state part, then at the next parameter `p + ds / sqrt(1 - θ)` (sign of the direction's
    /// parameter component). `Some(result of accept)` when one converged.
    fn pass_corner(&mut self, last: &BranchPoint, ds: f64) -> Option<Option<BranchPoint>> {
        let n = self.ws.n;
        let d = self.direction.clone();
        let state_part = self.ws.dot(&d[..n], 0.0, &d[..n], 0.0);
        let parameter_part = (1.0 - self.options.theta) * d[n] * d[n];
        for on_state in [true, false] {
            let (scale, along, constraint) = if on_state {
                if state_part < 1e-6 {
                    continue;
                }
                self.direction_weights();
                let mut along = d.clone();
                along[n] = 0.0;
                let target: f64 = self
                    .ws
                    .w
                    .iter()
                    .zip(&last.state)
                    .zip(&d)
                    .map(|((w, x), di)| w * (x + ds * di))
                    .sum();
                let constraint = Constraint {
                    arclength: true,
                    w_p: 0.0,
                    target,
                };
                (ds, along, constraint)
            } else {
                if parameter_part < 1e-6 {
                    continue;
                }
                let step_p = ds / (1.0 - self.options.theta).sqrt() * d[n].signum();
                let mut along = vec![0.0; n + 1];
                along[n] = d[n].signum();
                let constraint = Constraint {
                    arclength: false,
                    w_p: 1.0,
                    target: last.parameter + step_p,
                };
                (step_p / d[n], along, constraint)
            };
            let mut x: Vec<f64> = last
                .state
                .iter()
                .zip(&d)
                .map(|(x, di)| x + scale * di)
                .collect();
            let mut p = last.parameter + scale * d[n];
            let mut smallest = f64::INFINITY;
            let before = self.counters.corrector_iterations;
            match self.correct_at(&mut x, &mut p, constraint, &mut smallest) {
                Ok(c) => {
                    self.counters.corner_passes += 1;
                    let step = self.ws.norm(
                        &x.iter()
                            .zip(&last.state)
                            .map(|(a, b)| a - b)
                            .collect::<Vec<_>>(),
                        p - last.parameter,
                    );
                    return Some(self.accept(last, x, p, step, c, Some(&along)));
                }
                Err(_) => self.reject(before, last.parameter),
            }
        }
        None
    }

    fn accept(
        &mut self,
        last: &BranchPoint,
        mut x: Vec<f64>,
        mut p: f64,
        ds: f64,
        corrected: Corrected,
        along: Option<&[f64]>,
    ) -> Option<BranchPoint> {
        let n = self.ws.n;
        self.consecutive_failures = 0;
        let direction = self.direction.clone();
        self.take_tangent(Some(&direction), 0.0);
        let mut iterations = corrected.iterations;
        let mut residual_norm = corrected.residual_norm;
        let mut step = ds;

        // Leaving the bounds: re-solve at the bound from the interpolated point.
        let bound = if p > self.options.parameter_max {
            Some(self.options.parameter_max)
        } else if p < self.options.parameter_min {
            Some(self.options.parameter_min)
        } else {
            None
        };
        if bound == Some(last.parameter) {
            // Already on the bound and heading out: nothing new to report.
            self.problem.set_parameter(last.parameter);
            self.finish(ContinuationTermination::ReachedBound {
                parameter: last.parameter,
                bound: last.parameter,
            });
            return None;
        }
        if let Some(pb) = bound {
            let lambda = (pb - last.parameter) / (p - last.parameter);
            let mut xb: Vec<f64> = last
                .state
                .iter()
                .zip(&x)
                .map(|(a, b)| a + lambda * (b - a))
                .collect();
            let mut pbv = pb;
            let mut smallest = f64::INFINITY;
            let constraint = Constraint {
                arclength: false,
                w_p: 1.0,
                target: pb,
            };
            let saved_tangent = self.tangent.clone();
            match self.correct_at(&mut xb, &mut pbv, constraint, &mut smallest) {
                Ok(c) => {
                    self.take_tangent(Some(&direction), 0.0);
                    x = xb;
                    p = pbv;
                    iterations += c.iterations;
                    residual_norm = c.residual_norm;
                    step = lambda * ds;
                }
                Err(_) => {
                    self.tangent = saved_tangent;
                    // Keep the point outside the bound; the problem follows it.
                    self.problem.set_parameter(p);
                }
            }
        }

        // Secant direction for the next predictor.
        let dx: Vec<f64> = x.iter().zip(&last.state).map(|(a, b)| a - b).collect();
        let dpar = p - last.parameter;
        let chord = self.ws.norm(&dx, dpar);
        // Orient the tangent along the step just taken: where the branch turns sharply the
        // predictor's direction can make an obtuse angle with the new tangent, and orienting
        // by it would reverse the tangent (a spurious fold, and a tangent predictor heading
        // back along the branch). The secant always has a positive component along the
        // predictor (the arclength constraint), so it is the forward direction here.
        let forward = match along {
            Some(a) => self
                .ws
                .dot(&self.tangent[..n], self.tangent[n], &a[..n], a[n]),
            None if chord > 0.0 => self.ws.dot(&self.tangent[..n], self.tangent[n], &dx, dpar),
            None => 0.0,
        };
        if forward < 0.0 {
            for v in &mut self.tangent {
                *v = -*v;
            }
        }

        // Fold detection.
        let tp = self.tangent[n];
        if let Some(event) = self.folds.push(p, tp, chord) {
            self.events.push(event);
        }

        match self.options.predictor {
            // After a corner the chord cuts across it: the new piece's tangent is the way on.
            Predictor::Secant if chord > 0.0 && along.is_none() => {
                for (d, v) in self.direction.iter_mut().zip(&dx) {
                    *d = v / chord;
                }
                self.direction[n] = dpar / chord;
            }
            _ => self.direction.copy_from_slice(&self.tangent),
        }

        let factor = (self.options.target_iterations as f64 / iterations.max(1) as f64)
            .sqrt()
            .clamp(0.5, 2.0);
        self.step = (ds * factor).clamp(self.options.min_step, self.options.max_step);

        let point = BranchPoint {
            state: x,
            parameter: p,
            iterations,
            residual_norm,
            step,
            tangent_parameter: tp,
        };
        self.last = Some(point.clone());
        self.points += 1;
        if let Some(pb) = bound {
            self.finish(ContinuationTermination::ReachedBound {
                parameter: point.parameter,
                bound: pb,
            });
        } else if self.points >= self.options.max_points {
            self.finish(ContinuationTermination::MaxPoints {
                points: self.points,
            });
        }
        Some(point)
    }
}

impl<'a, P, S> Continuation<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    P::Jacobian: DenseAssemble,
    S: LinearSolve<P::Jacobian> + ?Sized,
{
    /// Enables the dense fallback: when `J` is singular (the factorization fails) or the
    /// block-elimination pivot vanishes, the corrector assembles the `(n+1) x (n+1)`
    /// bordered matrix and solves it by dense LU (counted in
    /// [`ContinuationCounters::dense_bordered_factorizations`]). Only available when the
    /// Jacobian type implements [`DenseAssemble`]; meant for small or dense problems.
    pub fn with_dense_fallback(mut self) -> Self {
        self.fallback = Some(<P::Jacobian as DenseAssemble>::assemble_dense);
        self
    }
}

impl<P, S> Iterator for Continuation<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: LinearSolve<P::Jacobian> + ?Sized,
{
    type Item = Result<BranchPoint, ContinuationError>;

    fn next(&mut self) -> Option<Self::Item> {
        match std::mem::replace(&mut self.phase, Phase::Running) {
            Phase::Finished => {
                self.phase = Phase::Finished;
                None
            }
            Phase::NotStarted { x0, p0 } => Some(self.start(x0, p0)),
            Phase::Running => self.advance().map(Ok),
        }
    }
}

impl<P, S> std::iter::FusedIterator for Continuation<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: LinearSolve<P::Jacobian> + ?Sized,
{
}

/// Runs a whole continuation: [`Continuation::new`] then [`Continuation::run`].
pub fn run<P, S>(
    problem: &mut P,
    solver: &mut S,
    x0: &[f64],
    p0: f64,
    options: ContinuationOptions,
) -> Result<Branch, ContinuationError>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: LinearSolve<P::Jacobian> + ?Sized,
{
    Continuation::new(problem, solver, x0, p0, options)?.run()
}

/// One solved point of a natural-parameter sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepPoint {
    /// The state.
    pub state: Vec<f64>,
    /// The parameter.
    pub parameter: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// `|F|` at the point.
    pub residual_norm: f64,
}

/// Where and why a natural sweep stopped early.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepFailure {
    /// Index in the requested parameters.
    pub index: usize,
    /// The parameter.
    pub parameter: f64,
    /// Why Newton stopped.
    pub termination: Termination,
    /// Newton iterations spent there.
    pub iterations: usize,
    /// `|F|` at Newton's best iterate there.
    pub residual_norm: f64,
}

/// Result of a natural-parameter sweep: the solved points in order, and the first failure
/// (the sweep stops there).
#[derive(Clone, Debug, PartialEq)]
pub struct NaturalSweep {
    /// Points solved before the first failure.
    pub points: Vec<SweepPoint>,
    /// The first failure, if any.
    pub failure: Option<SweepFailure>,
    /// Work done (summed over the Newton solves).
    pub counters: WorkCounters,
}

/// Natural-parameter continuation: for each `p` in `parameters`, semismooth Newton
/// ([`crate::newton`], with `options`) at fixed `p` from the previous solution (`x0` for
/// the first). At a fold it fails or jumps to another branch; it exists to be compared with
/// the pseudo-arclength [`Continuation`]. Stops at the first failure; the problem's
/// parameter is then left at the last solved point.
pub fn natural_sweep<P, S>(
    problem: &mut P,
    solver: &mut S,
    x0: &[f64],
    parameters: &[f64],
    options: &NewtonOptions,
) -> Result<NaturalSweep, ContinuationError>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: LinearSolve<P::Jacobian> + ?Sized,
{
    let mut newton = NewtonSolver::<P::Jacobian>::new(*options)?;
    let n = problem.dim();
    if x0.len() != n {
        return Err(ContinuationError::DimensionMismatch {
            expected: n,
            found: x0.len(),
        });
    }
    if let Some(&bad) = parameters.iter().find(|p| !p.is_finite()) {
        return Err(ContinuationError::InvalidStart {
            parameter: bad,
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
        });
    }
    let mut counters = WorkCounters::default();
    let mut points: Vec<SweepPoint> = Vec::with_capacity(parameters.len());
    let mut x = x0.to_vec();
    let mut failure = None;
    for (index, &parameter) in parameters.iter().enumerate() {
        problem.set_parameter(parameter);
        let report = newton.solve(problem, solver, &mut x)?;
        counters += report.counters;
        if report.converged() {
            points.push(SweepPoint {
                state: x.clone(),
                parameter,
                iterations: report.iterations,
                residual_norm: report.residual_norm(),
            });
        } else {
            if let Some(last) = points.last() {
                problem.set_parameter(last.parameter);
            }
            failure = Some(SweepFailure {
                index,
                parameter,
                residual_norm: report.residual_norm(),
                iterations: report.iterations,
                termination: report.termination,
            });
            break;
        }
    }
    Ok(NaturalSweep {
        points,
        failure,
        counters,
    })
}

#[cfg(test)]
mod tests {
    use super::hermite_fold;

    #[test]
    fn hermite_fold_is_exact_for_a_quadratic_turn() {
        // p(s) = 1 - (s - 0.3)^2 / 2 on [0, h] with h = 0.8: values and slopes at both ends;
        // a cubic Hermite interpolant reproduces a quadratic, so the maximum 1 is exact.
        let p = |s: f64| 1.0 - 0.5 * (s - 0.3) * (s - 0.3);
        let dp = |s: f64| -(s - 0.3);
        let h = 0.8;
        let fold = hermite_fold(p(0.0), dp(0.0), p(h), dp(h), h);
        assert!((fold - 1.0).abs() < 1e-15, "{fold}");
    }
}
