//! Semismooth Newton method with line-search globalization.
//!
//! Each iteration solves `J_k d = -F(x_k)` with `J_k` an element of the generalized
//! Jacobian (provided by the problem, [`GeneralizedJacobian`]), then takes
//! `x_{k+1} = x_k + alpha_k d` with `alpha_k` from the chosen [`Globalization`] on the
//! merit `m(x) = 0.5 |F(x)|^2` (Qi & Sun 1993, Math. Program. 58; globalization as in
//! De Luca, Facchinei & Kanzow 1996, Math. Program. 75, and Grippo, Lampariello &
//! Lucidi 1986 for the non-monotone rule). Near a BD-regular solution of a strongly
//! semismooth `F`, the full step is accepted and convergence is Q-quadratic.
//!
//! The driver owns the loop; the line search sees only `alpha -> merit`
//! ([`crate::linesearch`]); the linear solver only matrices and right-hand sides
//! ([`Factorize`], [`LinearSolve`](crate::LinearSolve)). The iteration itself (step rule, termination tests,
//! best iterate) is the one the continuation corrector runs too, with a bordered direction
//! instead of the plain solve. [`NewtonSolver`] keeps all buffers (and the Jacobian)
//! between solves, so continuation and parameter sweeps allocate nothing per iteration;
//! [`solve`] is a one-shot wrapper.
//!
//! # Outcome
//!
//! `Err` ([`NewtonError`]) only when the solver could not run: invalid options, an initial
//! guess of the wrong length. A run that ran returns `Ok(report)` whatever it ended with:
//! its typed [`NewtonReport::termination`] says why it stopped
//! ([`NewtonReport::converged`] whether it converged), and the best iterate is written to
//! `x`.
//!
//! # Options and defaults ([`NewtonOptions`])
//!
//! | field | default | meaning |
//! |---|---|---|
//! | `absolute_tolerance` | `1e-10` | converged when `\|F\|_2 <= max(abs, rel \|F(x_0)\|_2, floor)` |
//! | `relative_tolerance` | `0` (off) | see above; in `[0, 1)` |
//! | `residual_floor` | `0` (off) | `\|F\|` round-off alone produces near a solution: the tolerance is at least this, and a run that stalls with `\|F\| <= 100 floor` has converged ([`Termination::ConvergedAtRoundoff`]) |
//! | `step_tolerance` | `1e-15` | stalled when `alpha \|d\| <= step_tol (1 + \|x\|)` |
//! | `max_iterations` | `200` | Newton iterations (not counting line-search trials) |
//! | `globalization` | [`Globalization::polyalgorithm`] | none, Armijo, non-monotone, hybrid or polyalgorithm |
//!
//! # Polyalgorithm (the default globalization)
//!
//! Semismooth Newton on a complementarity system with full steps behaves like a primal-dual
//! active-set method: from a reasonable guess it finds the active set in a few iterations,
//! but it may cycle between active sets or creep one switch per iteration; a line search on
//! `|F|^2 / 2` cannot repair this, because the merit has kinks wherever the active set
//! changes and backtracking stalls on them. [`Globalization::Polyalgorithm`] therefore
//! tries, within one budget of `max_iterations`:
//!
//! 1. `full_steps` full Newton steps (the fast path: most solves end here). When the
//!    problem offers a [`Smoothing`](crate::Smoothing) they stop earlier once they stagnate
//!    ([`Termination::Stagnated`]: after 8 steps, `|F|` did not fall tenfold over the last 6
//!    against the smallest before them, the first iterate excluded);
//! 2. when the problem offers a [`Smoothing`](crate::Smoothing): the smoothing path
//!    `F_mu(x) = 0` from the initial guess, `mu` from the problem's smoothing scale down three
//!    decades (Newton with an Armijo search on the smooth merit at the start, then the
//!    crate's pseudo-arclength continuation in `log10 mu` with the tangent predictor), then
//!    full Newton steps on `F`; a path that stops after two decades hands its last point to
//!    those steps too (stopped when they stagnate: after 15 steps, `|F|` did not fall
//!    tenfold over the last 10). When this
//!    fails, the path is followed once more with its points corrected to a tolerance
//!    shrinking like `mu` (`|F_mu| <= beta mu`, the neighbourhood of smoothing Newton
//!    methods; [`ParameterDependent::tolerance_scale`](crate::ParameterDependent::tolerance_scale)):
//!    late on the path the Newton basin of `F_mu` shrinks like `mu`, and points corrected
//!    to one tolerance can lie outside it;
//! 3. the non-monotone line search from the initial guess, on at most half of the
//!    iterations left;
//! 4. the Newton homotopy `H(x, t) = F(x) - (1 - t) F(x_0)` from `(x_0, 0)` to `t = 1`,
//!    followed by the continuation (the state weighted 0.99 in the arclength so that
//!    corners where `t` turns back are passed), then full Newton steps on `F` at `t = 1`.
//!    It needs nothing from the problem but `F` and `J`; for a forced structure whose
//!    contacts are open at `x_0 = 0` it is the load homotopy.
//!
//! The report names the strategy that converged ([`NewtonReport::strategy`]) and every
//! attempt ([`NewtonReport::attempts`]); the best iterate of all attempts is returned.
//!
//! ```
//! use faer::Mat;
//! use semismooth::linalg::FaerDenseLu;
//! use semismooth::newton::{solve, NewtonOptions};
//! use semismooth::{EvaluationError, GeneralizedJacobian, Residual};
//!
//! /// F(x) = min(x, A x + q) for the LCP with A = [[2, 1], [1, 2]], q = [-1, 1]:
//! /// solution x = [0.5, 0] (w = A x + q = [0, 1.5]).
//! struct Lcp;
//! const A: [[f64; 2]; 2] = [[2.0, 1.0], [1.0, 2.0]];
//! const Q: [f64; 2] = [-1.0, 1.0];
//! impl Residual for Lcp {
//!     fn dim(&self) -> usize { 2 }
//!     fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
//!         for i in 0..2 {
//!             let w = A[i][0] * x[0] + A[i][1] * x[1] + Q[i];
//!             out[i] = x[i].min(w);
//!         }
//!         Ok(())
//!     }
//! }
//! impl GeneralizedJacobian for Lcp {
//!     type Jacobian = Mat<f64>;
//!     fn new_jacobian(&self) -> Mat<f64> { Mat::zeros(2, 2) }
//!     fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
//!         for i in 0..2 {
//!             let w = A[i][0] * x[0] + A[i][1] * x[1] + Q[i];
//!             for j in 0..2 {
//!                 // min picks x_i where x_i <= w_i (row of I), else w_i (row of A).
//!                 jac[(i, j)] = if x[i] <= w { (i == j) as u8 as f64 } else { A[i][j] };
//!             }
//!         }
//!         Ok(())
//!     }
//! }
//!
//! let mut x = [1.0, 1.0];
//! let report = solve(&mut Lcp, &mut FaerDenseLu::new(), &mut x, &NewtonOptions::default())
//!     .unwrap();
//! assert!((x[0] - 0.5).abs() < 1e-12 && x[1].abs() < 1e-12);
//! assert!(report.iterations <= 5);
//! ```

pub(crate) mod kernel;
mod path;
mod polyalgorithm;

use std::ops::AddAssign;

use crate::linalg::LinearSolveError;
pub use crate::linesearch::{InvalidLineSearchOption, LineSearchOptions};
use crate::{EvaluationError, Factorize, GeneralizedJacobian, ProblemCounters};
use kernel::FLOOR_STALL_FACTOR;
use kernel::{Kernel, KernelRules, NewtonSystem, StepRule, Stop};

/// How the step length is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Globalization {
    /// Always the full step `alpha = 1` (local method).
    None,
    /// Armijo backtracking on `0.5 |F|^2`: monotone decrease.
    Armijo(LineSearchOptions),
    /// Grippo–Lampariello–Lucidi: Armijo against the largest merit of the last
    /// `memory` iterates (`memory >= 1`; `1` is Armijo).
    NonMonotone {
        /// Number of past merits in the reference (default 10).
        memory: usize,
        /// Backtracking options.
        line_search: LineSearchOptions,
    },
    /// Full steps first, then the non-monotone line search: the first `full_steps`
    /// iterations take `alpha = 1` whenever `F` can be evaluated and stays finite
    /// (semismooth Newton on complementarity systems then behaves as a primal-dual
    /// active-set method, which may cross regions of large residual on its way to the
    /// solution); if it has not converged by then, it restarts from the initial guess with
    /// the GLL line search (the best iterate of both phases is returned).
    Hybrid {
        /// Iterations of the full-step phase.
        full_steps: usize,
        /// Memory of the non-monotone phase (`>= 1`).
        memory: usize,
        /// Backtracking options of the non-monotone phase.
        line_search: LineSearchOptions,
    },
    /// A polyalgorithm (the default): full steps first; when they have not converged
    /// after `full_steps` iterations, the smoothing path (problems with a
    /// [`Smoothing`](crate::Smoothing)), the non-monotone line search, then the Newton
    /// homotopy `F(x) - (1 - t) F(x_0) = 0`, each from the initial guess
    /// ([module docs](self), *Polyalgorithm*). The report names the strategy that
    /// converged ([`NewtonReport::strategy`]) and every attempt.
    Polyalgorithm {
        /// Iterations of the full-step phase.
        full_steps: usize,
        /// Memory of the line-search phase (`>= 1`).
        memory: usize,
        /// Backtracking options of the line-search phase.
        line_search: LineSearchOptions,
    },
}

impl Globalization {
    /// [`Globalization::Hybrid`] with 30 full steps, then GLL with memory 10 (the default).
    pub fn hybrid() -> Self {
        Self::Hybrid {
            full_steps: 30,
            memory: 10,
            line_search: LineSearchOptions::default(),
        }
    }

    /// [`Globalization::Polyalgorithm`] with 30 full steps, then the smoothing path and
    /// the Newton homotopy, then GLL with memory 10 (the default).
    pub fn polyalgorithm() -> Self {
        Self::Polyalgorithm {
            full_steps: 30,
            memory: 10,
            line_search: LineSearchOptions::default(),
        }
    }

    /// [`Globalization::NonMonotone`] with memory 10.
    pub fn non_monotone() -> Self {
        Self::NonMonotone {
            memory: 10,
            line_search: LineSearchOptions::default(),
        }
    }
}

impl Default for Globalization {
    fn default() -> Self {
        Self::polyalgorithm()
    }
}

/// Options of the Newton driver (defaults in the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    /// Absolute tolerance on `|F|_2`, `>= 0`.
    pub absolute_tolerance: f64,
    /// Relative tolerance on `|F|_2 / |F(x_0)|_2`, in `[0, 1)` (0 = off).
    pub relative_tolerance: f64,
    /// `|F|_2` that round-off alone produces near a solution, `>= 0` (0 = off): the
    /// tolerance is at least this, and a stall with `|F| <= 100 residual_floor` is
    /// convergence ([`Termination::ConvergedAtRoundoff`]).
    pub residual_floor: f64,
    /// Stall threshold on the accepted step, `>= 0`.
    pub step_tolerance: f64,
    /// Maximum number of Newton iterations.
    pub max_iterations: usize,
    /// Step-length rule.
    pub globalization: Globalization,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            absolute_tolerance: 1e-10,
            relative_tolerance: 0.0,
            residual_floor: 0.0,
            step_tolerance: 1e-15,
            max_iterations: 200,
            globalization: Globalization::default(),
        }
    }
}

impl NewtonOptions {
    /// Checks every field; the error names the field, the value and the allowed range.
    pub fn validate(&self) -> Result<(), NewtonError> {
        let invalid = |name, value, allowed| NewtonError::InvalidOption {
            name,
            value,
            allowed,
        };
        for (name, t) in [
            ("absolute_tolerance", self.absolute_tolerance),
            ("residual_floor", self.residual_floor),
            ("step_tolerance", self.step_tolerance),
        ] {
            if !(t.is_finite() && t >= 0.0) {
                return Err(invalid(name, t, "finite and >= 0"));
            }
        }
        let t = self.relative_tolerance;
        if !(t.is_finite() && (0.0..1.0).contains(&t)) {
            return Err(invalid("relative_tolerance", t, "[0, 1)"));
        }
        let line_search = match self.globalization {
            Globalization::None => None,
            Globalization::Armijo(ls) => Some(ls),
            Globalization::NonMonotone {
                memory,
                line_search,
            }
            | Globalization::Hybrid {
                memory,
                line_search,
                ..
            }
            | Globalization::Polyalgorithm {
                memory,
                line_search,
                ..
            } => {
                if memory == 0 {
                    return Err(invalid("globalization.memory", 0.0, ">= 1"));
                }
                Some(line_search)
            }
        };
        if let Some(ls) = line_search {
            ls.validate()
                .map_err(|e| invalid(e.qualified_name("line_search"), e.value, e.allowed))?;
        }
        Ok(())
    }

    /// The kernel's rules of a run with the step rule `step`.
    fn rules(&self, step: StepRule) -> KernelRules {
        KernelRules {
            absolute_tolerance: self.absolute_tolerance,
            relative_tolerance: self.relative_tolerance,
            residual_floor: self.residual_floor,
            step_tolerance: self.step_tolerance,
            max_iterations: self.max_iterations,
            min_iterations: 0,
            step,
            restore_best: true,
            stagnation: None,
        }
    }
}

/// Why the iteration stopped.
#[derive(Clone, Debug, PartialEq)]
pub enum Termination {
    /// `|F| <= max(absolute, relative |F(x_0)|, residual_floor)`.
    Converged,
    /// The step stalled with `|F|` within 100 times the residual floor of
    /// [`NewtonOptions::residual_floor`]: converged as far as floating point allows.
    ConvergedAtRoundoff {
        /// `100 residual_floor`.
        floor: f64,
    },
    /// `max_iterations` reached without convergence.
    MaxIterations,
    /// The full-step phase of [`Globalization::Polyalgorithm`] made no progress: `|F|`
    /// fell by less than a factor 10 over its last iterations.
    Stagnated,
    /// The accepted step `alpha |d|` fell below `step_tolerance (1 + |x|)`.
    Stalled,
    /// No step length `>= min_step` gave sufficient decrease.
    LineSearchFailed,
    /// The Jacobian could not be factored, or the solve failed (singular, out of memory).
    LinearSolve(LinearSolveError),
    /// `F` or the Newton direction had a NaN or infinite component.
    NonFinite,
    /// The problem could not be evaluated: at the initial guess, at a full step without
    /// line search, for its Jacobian, or anywhere for its own error
    /// ([`EvaluationError::Problem`], which ends the run at once).
    Evaluation(EvaluationError),
}

/// A way of reaching a root, as a report names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Strategy {
    /// Newton with full steps (`newton`).
    FullSteps,
    /// Newton with a line search on the merit (`line-search`).
    LineSearch,
    /// The Newton homotopy followed to `t = 1`, then Newton (`newton-homotopy`).
    Homotopy,
    /// The smoothing path followed to a small smoothing, then Newton (`smoothing`).
    Smoothing,
}

impl Strategy {
    /// The name used in reports: `newton`, `line-search`, `newton-homotopy`.
    pub fn name(self) -> &'static str {
        match self {
            Self::FullSteps => "newton",
            Self::LineSearch => "line-search",
            Self::Homotopy => "newton-homotopy",
            Self::Smoothing => "smoothing",
        }
    }
}

impl std::fmt::Display for Strategy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One strategy tried by a run.
#[derive(Clone, Debug, PartialEq)]
pub struct Attempt {
    /// The strategy.
    pub strategy: Strategy,
    /// Its iterations (for the homotopy: corrector iterations along the path, failed
    /// steps included, plus the Newton iterations at `t = 1`).
    pub iterations: usize,
    /// Whether it converged.
    pub converged: bool,
    /// How it ended, in words.
    pub outcome: String,
}

impl Attempt {
    fn new(strategy: Strategy, iterations: usize, termination: &Termination) -> Self {
        Self {
            strategy,
            iterations,
            converged: termination.converged(),
            outcome: termination.to_string(),
        }
    }

    fn failed_path(strategy: Strategy, path: &path::PathOutcome) -> Self {
        Self {
            strategy,
            iterations: path.iterations,
            converged: false,
            outcome: format!(
                "the path stopped at {:.6} of its length: {}",
                path.furthest,
                path.reason.as_deref().unwrap_or("no reason given")
            ),
        }
    }
}

impl Termination {
    /// Whether the run converged ([`Termination::Converged`] or
    /// [`Termination::ConvergedAtRoundoff`]).
    pub fn converged(&self) -> bool {
        matches!(self, Self::Converged | Self::ConvergedAtRoundoff { .. })
    }
}

/// Short names: `converged` (`converged (stalled at the round-off floor ...)`),
/// `max-iterations`, `stagnated`, `stalled`, `line-search-failed`, `singular-jacobian: ...`
/// (or `out-of-memory: ...` and the like for other linear-solver failures), `non-finite`,
/// `outside-domain: ...` (or `problem-error: ...` for the problem's own error).
impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Converged => write!(f, "converged"),
            Self::ConvergedAtRoundoff { floor } => write!(
                f,
                "converged (stalled at the round-off floor {floor:.1e} of this model)"
            ),
            Self::MaxIterations => write!(f, "max-iterations"),
            Self::Stagnated => write!(f, "stagnated"),
            Self::Stalled => write!(f, "stalled"),
            Self::LineSearchFailed => write!(f, "line-search-failed"),
            Self::LinearSolve(e) => write!(f, "{}: {e}", e.kind()),
            Self::NonFinite => write!(f, "non-finite"),
            Self::Evaluation(e) => write!(f, "{}: {e}", e.kind()),
        }
    }
}

/// Work done by a solve. Summable (`+=`) over several solves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorkCounters {
    /// Calls to `Residual::residual` (including line-search trials).
    pub residual_evaluations: u64,
    /// Calls to `GeneralizedJacobian::jacobian`.
    pub jacobian_evaluations: u64,
    /// Calls to `Factorize::factor` (successful or not).
    pub factorizations: u64,
    /// Calls to `LinearSolve::solve_in_place`.
    pub linear_solves: u64,
    /// Rejected line-search trials.
    pub line_search_backtracks: u64,
    /// The problem's own counters over the solve ([`crate::Residual::problem_counters`]).
    pub problem: ProblemCounters,
}

impl AddAssign for WorkCounters {
    fn add_assign(&mut self, rhs: Self) {
        self.residual_evaluations += rhs.residual_evaluations;
        self.jacobian_evaluations += rhs.jacobian_evaluations;
        self.factorizations += rhs.factorizations;
        self.linear_solves += rhs.linear_solves;
        self.line_search_backtracks += rhs.line_search_backtracks;
        self.problem += rhs.problem;
    }
}

/// What a Newton run did.
#[derive(Clone, Debug, PartialEq)]
pub struct NewtonReport {
    /// Why it stopped.
    pub termination: Termination,
    /// The strategy of the last attempt (the one that converged, when one did).
    pub strategy: Strategy,
    /// Every strategy tried, in order (one entry unless the globalization is
    /// [`Globalization::Polyalgorithm`]).
    pub attempts: Vec<Attempt>,
    /// Newton iterations over all attempts (corrector iterations of a homotopy included).
    pub iterations: usize,
    /// The tolerance the run was judged against: `max(absolute, relative |F(x_0)|,
    /// residual_floor)`.
    pub effective_tolerance: f64,
    /// `|F|_2` at the initial guess and after each accepted step of the attempts that
    /// iterate on `F` (`iterations + 1` values with a single attempt; a homotopy's corrector
    /// iterates on the homotopy, and its iterations are not listed).
    pub residual_norms: Vec<f64>,
    /// Accepted step lengths `alpha_k`, as `residual_norms`.
    pub step_lengths: Vec<f64>,
    /// Accepted step norms `alpha_k |d_k|_2`, as `residual_norms`.
    pub step_norms: Vec<f64>,
    /// Estimated order `q` from the last three residual norms,
    /// `log(r_{k+1}/r_k) / log(r_k/r_{k-1})` (also for runs that did not converge: a
    /// stalled or capped run shows its rate); `None` with fewer than three norms, when
    /// one of them is below `1e-300` (exact termination, e.g. the active set was found
    /// and the remaining system was linear), or when the estimate is undefined.
    pub observed_order: Option<f64>,
    /// Work counters.
    pub counters: WorkCounters,
}

impl NewtonReport {
    /// Whether the run converged (see [`Termination::converged`]).
    pub fn converged(&self) -> bool {
        self.termination.converged()
    }

    /// `|F|_2` at the returned `x`, the best accepted iterate (the smallest entry of
    /// [`residual_norms`](Self::residual_norms)); `NaN` only if `F(x_0)` was not finite.
    pub fn residual_norm(&self) -> f64 {
        self.residual_norms
            .iter()
            .copied()
            .reduce(f64::min)
            .unwrap_or(f64::NAN)
    }
}

/// Why the solver could not run (a run that ran and stopped is an `Ok` report, see
/// [`NewtonReport::termination`]).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NewtonError {
    /// An option is outside its allowed range.
    #[error("invalid Newton option {name} = {value}: allowed {allowed}")]
    InvalidOption {
        /// Field name (dotted for nested fields).
        name: &'static str,
        /// Rejected value.
        value: f64,
        /// Allowed range.
        allowed: &'static str,
    },
    /// `x` does not have the problem's dimension.
    #[error("initial guess has length {found}, the problem has dimension {expected}")]
    DimensionMismatch {
        /// `problem.dim()`.
        expected: usize,
        /// `x.len()`.
        found: usize,
    },
}

/// `log(r3/r2) / log(r2/r1)` from the last three norms, see
/// [`NewtonReport::observed_order`].
fn observed_order(norms: &[f64]) -> Option<f64> {
    let [r1, r2, r3] = norms.get(norms.len().checked_sub(3)?..)? else {
        return None;
    };
    if [r1, r2, r3]
        .iter()
        .any(|r| !(r.is_finite() && **r >= 1e-300))
    {
        return None;
    }
    let q = (r3 / r2).ln() / (r2 / r1).ln();
    q.is_finite().then_some(q)
}

/// Why a plain Newton direction could not be computed.
enum PlainFailure {
    Linear(LinearSolveError),
    Evaluation(EvaluationError),
}

/// `J d = -F` with the problem's Jacobian and the linear solver.
struct PlainNewton<'a, P: GeneralizedJacobian + ?Sized, S: ?Sized> {
    problem: &'a mut P,
    solver: &'a mut S,
    jacobian: &'a mut P::Jacobian,
}

impl<P, S> NewtonSystem for PlainNewton<'_, P, S>
where
    P: GeneralizedJacobian + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    type Failure = PlainFailure;

    fn evaluate(&mut self, x: &[f64], f: &mut [f64]) -> Result<(), EvaluationError> {
        self.problem.residual(x, f)
    }

    fn direction(
        &mut self,
        x: &[f64],
        f: &[f64],
        d: &mut [f64],
        counters: &mut WorkCounters,
    ) -> Result<(), PlainFailure> {
        counters.jacobian_evaluations += 1;
        self.problem
            .jacobian(x, self.jacobian)
            .map_err(PlainFailure::Evaluation)?;
        counters.factorizations += 1;
        self.solver
            .factor(self.jacobian)
            .map_err(PlainFailure::Linear)?;
        for (di, fi) in d.iter_mut().zip(f) {
            *di = -fi;
        }
        counters.linear_solves += 1;
        self.solver.solve_in_place(d).map_err(PlainFailure::Linear)
    }
}

/// A reusable semismooth Newton solver: options plus every buffer of the iteration and
/// the Jacobian `J`, kept between [`NewtonSolver::solve`] calls.
///
/// The Jacobian is created by the problem's `new_jacobian` on the first solve and again
/// only when the dimension changes (call [`NewtonSolver::clear_jacobian`] to force it).
/// After a solve the linear solver holds the factorization of the Jacobian at the last
/// iterate where a Newton direction was computed (not necessarily the returned `x`).
#[derive(Debug)]
pub struct NewtonSolver<J> {
    options: NewtonOptions,
    jacobian: Option<J>,
    dim: usize,
    kernel: Kernel,
    /// The initial guess, kept by the polyalgorithm (each attempt starts from it).
    start: Vec<f64>,
}

impl<J> NewtonSolver<J> {
    /// A solver with validated `options`.
    pub fn new(options: NewtonOptions) -> Result<Self, NewtonError> {
        options.validate()?;
        Ok(Self {
            options,
            jacobian: None,
            dim: 0,
            kernel: Kernel::default(),
            start: Vec::new(),
        })
    }

    /// The options in use.
    pub fn options(&self) -> &NewtonOptions {
        &self.options
    }

    /// Replaces the options (validated first; unchanged on error).
    pub fn set_options(&mut self, options: NewtonOptions) -> Result<(), NewtonError> {
        options.validate()?;
        self.options = options;
        Ok(())
    }

    /// Drops the stored Jacobian so the next solve asks the problem for a new one.
    pub fn clear_jacobian(&mut self) {
        self.jacobian = None;
    }

    /// The residual `F(x)` at the returned `x` of the last solve (empty before any solve).
    pub fn residual(&self) -> &[f64] {
        let f = self.kernel.residual();
        &f[..self.dim.min(f.len())]
    }

    /// Runs semismooth Newton from `x` (initial guess in, best iterate out).
    ///
    /// `Ok(report)` when it ran, converged or not ([`NewtonReport::converged`]);
    /// [`NewtonError::DimensionMismatch`] when `x` does not fit the problem. `x` always
    /// holds finite values on return if it did on entry.
    pub fn solve<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
    ) -> Result<NewtonReport, NewtonError>
    where
        P: GeneralizedJacobian<Jacobian = J> + ?Sized,
        S: Factorize<J> + ?Sized,
    {
        let n = problem.dim();
        if x.len() != n {
            return Err(NewtonError::DimensionMismatch {
                expected: n,
                found: x.len(),
            });
        }
        if self.dim != n {
            self.jacobian = None;
        }
        self.dim = n;
        let start = problem.problem_counters();
        let mut counters = WorkCounters::default();
        let mut log = Log::default();
        let (termination, strategy, attempts, tolerance) = match self.options.globalization {
            Globalization::Polyalgorithm {
                full_steps,
                memory,
                line_search,
            } => self.polyalgorithm(
                problem,
                linear,
                x,
                (full_steps, memory, line_search),
                &mut counters,
                &mut log,
            ),
            Globalization::Hybrid {
                full_steps,
                memory,
                line_search,
            } => {
                let rules = self.options.rules(StepRule::Backtracking {
                    memory,
                    line_search,
                });
                let (termination, run) = self.run_with(
                    problem,
                    linear,
                    x,
                    &rules,
                    (&mut counters, &mut log),
                    |kernel, system, x, rules, counters| {
                        hybrid(kernel, system, x, rules, full_steps, counters)
                    },
                );
                let strategy = if run.iterations <= full_steps {
                    Strategy::FullSteps
                } else {
                    Strategy::LineSearch
                };
                let attempt = Attempt::new(strategy, run.iterations, &termination);
                (termination, strategy, vec![attempt], run.tolerance)
            }
            globalization => {
                let (step, strategy) = match globalization {
                    Globalization::Armijo(line_search) => (
                        StepRule::Backtracking {
                            memory: 1,
                            line_search,
                        },
                        Strategy::LineSearch,
                    ),
                    Globalization::NonMonotone {
                        memory,
                        line_search,
                    } => (
                        StepRule::Backtracking {
                            memory,
                            line_search,
                        },
                        Strategy::LineSearch,
                    ),
                    _ => (StepRule::Full, Strategy::FullSteps),
                };
                let rules = self.options.rules(step);
                let (termination, run) =
                    self.phase(problem, linear, x, &rules, &mut counters, &mut log);
                let attempt = Attempt::new(strategy, run.iterations, &termination);
                (termination, strategy, vec![attempt], run.tolerance)
            }
        };
        counters.problem = problem.problem_counters().since(&start);
        let report = NewtonReport {
            observed_order: observed_order(&log.residual_norms),
            termination,
            strategy,
            iterations: attempts.iter().map(|a| a.iterations).sum(),
            attempts,
            effective_tolerance: tolerance,
            residual_norms: log.residual_norms,
            step_lengths: log.step_lengths,
            step_norms: log.step_norms,
            counters,
        };
        Ok(report)
    }

    /// One run of the kernel with the plain direction and `rules.step` throughout; its
    /// histories are appended to `log`.
    fn phase<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
        rules: &KernelRules,
        counters: &mut WorkCounters,
        log: &mut Log,
    ) -> (Termination, kernel::Run<PlainFailure>)
    where
        P: GeneralizedJacobian<Jacobian = J> + ?Sized,
        S: Factorize<J> + ?Sized,
    {
        self.run_with(
            problem,
            linear,
            x,
            rules,
            (counters, log),
            |kernel, system, x, rules, counters| kernel.run(system, x, rules, counters),
        )
    }

    /// One run of the kernel with the plain direction, driven by `drive`; its histories
    /// are appended to `log`.
    fn run_with<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
        rules: &KernelRules,
        (counters, log): (&mut WorkCounters, &mut Log),
        drive: impl FnOnce(
            &mut Kernel,
            &mut PlainNewton<'_, P, S>,
            &mut [f64],
            &KernelRules,
            &mut WorkCounters,
        ) -> kernel::Run<PlainFailure>,
    ) -> (Termination, kernel::Run<PlainFailure>)
    where
        P: GeneralizedJacobian<Jacobian = J> + ?Sized,
        S: Factorize<J> + ?Sized,
    {
        let jacobian = self.jacobian.get_or_insert_with(|| problem.new_jacobian());
        let mut system = PlainNewton {
            problem,
            solver: linear,
            jacobian,
        };
        let run = drive(&mut self.kernel, &mut system, x, rules, counters);
        log.residual_norms
            .extend_from_slice(&self.kernel.residual_norms);
        log.step_lengths
            .extend_from_slice(&self.kernel.step_lengths);
        log.step_norms.extend_from_slice(&self.kernel.step_norms);
        let termination = termination_of(&run.stop, rules.residual_floor);
        (termination, run)
    }
}

/// [`Globalization::Hybrid`] on the kernel: full steps while they can be evaluated for
/// `full_steps` iterations, then `rules.step` (the backtracking) from the initial guess for
/// the rest of the budget; a full step that cannot be evaluated hands over to the
/// backtracking from where it is instead.
fn hybrid<S: NewtonSystem + ?Sized>(
    kernel: &mut Kernel,
    system: &mut S,
    x: &mut [f64],
    rules: &KernelRules,
    full_steps: usize,
    counters: &mut WorkCounters,
) -> kernel::Run<S::Failure> {
    let StepRule::Backtracking {
        memory,
        line_search,
    } = rules.step
    else {
        return kernel.run(system, x, rules, counters);
    };
    if full_steps == 0 {
        return kernel.run(system, x, rules, counters);
    }
    let mut step = StepRule::FullWhileFinite {
        memory,
        line_search,
    };
    let max = rules.max_iterations;
    let stop = kernel
        .start(system, x, rules, counters)
        .or_else(|| kernel.iterate(system, x, rules, &mut step, full_steps.min(max), counters))
        .or_else(|| {
            if full_steps >= max {
                return None;
            }
            if matches!(step, StepRule::FullWhileFinite { .. }) {
                // The full steps have not converged: start again from the initial guess with
                // the line search (they may have wandered where descent stalls; the best
                // iterate so far is kept).
                step = rules.step;
                if let Some(stop) = kernel.restart(system, x, &step, counters) {
                    return Some(stop);
                }
            }
            kernel.iterate(system, x, rules, &mut step, max, counters)
        });
    kernel.finish(x, rules, stop.unwrap_or(Stop::MaxIterations))
}

/// The termination a kernel stop means for a run on `F` with `residual_floor`.
fn termination_of(stop: &Stop<PlainFailure>, residual_floor: f64) -> Termination {
    match stop {
        Stop::Converged => Termination::Converged,
        Stop::ConvergedAtFloor => Termination::ConvergedAtRoundoff {
            floor: FLOOR_STALL_FACTOR * residual_floor,
        },
        Stop::MaxIterations => Termination::MaxIterations,
        Stop::Stagnated => Termination::Stagnated,
        Stop::Stalled { .. } => Termination::Stalled,
        Stop::LineSearchFailed { .. } => Termination::LineSearchFailed,
        Stop::Direction(PlainFailure::Linear(e)) => Termination::LinearSolve(*e),
        Stop::Direction(PlainFailure::Evaluation(e)) | Stop::OutsideDomain(e) => {
            Termination::Evaluation(e.clone())
        }
        Stop::NonFinite => Termination::NonFinite,
    }
}
/// Histories of the attempts that iterate on `F`.
#[derive(Debug, Default)]
struct Log {
    residual_norms: Vec<f64>,
    step_lengths: Vec<f64>,
    step_norms: Vec<f64>,
}

/// One-shot semismooth Newton: validates `options`, runs [`NewtonSolver::solve`].
///
/// `x`: initial guess in, best iterate out. `Ok(report)` when it ran, converged or not
/// ([`NewtonReport::converged`]); `Err` when it could not run (invalid options, dimension
/// mismatch).
pub fn solve<P, S>(
    problem: &mut P,
    solver: &mut S,
    x: &mut [f64],
    options: &NewtonOptions,
) -> Result<NewtonReport, NewtonError>
where
    P: GeneralizedJacobian + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    NewtonSolver::<P::Jacobian>::new(*options)?.solve(problem, solver, x)
}

#[cfg(test)]
mod tests {
    use super::kernel::norm2;
    use super::*;

    #[test]
    fn observed_order_from_last_three_norms() {
        let q = observed_order(&[1.0, 1e-2, 1e-4, 1e-8]).unwrap();
        assert!((q - 2.0).abs() < 1e-12);
        assert_eq!(observed_order(&[1.0, 1e-2]), None);
        assert_eq!(observed_order(&[1.0, 1e-2, 0.0]), None);
        assert_eq!(observed_order(&[1.0, 1.0, 0.5]), None);
    }

    #[test]
    fn norm_does_not_overflow_and_flags_non_finite() {
        assert!((norm2(&[3e200, 4e200]) / 5e200 - 1.0).abs() < 1e-15);
        assert_eq!(norm2(&[0.0, 0.0]), 0.0);
        assert_eq!(norm2(&[1.0, f64::NAN]), f64::INFINITY);
        assert_eq!(norm2(&[f64::INFINITY]), f64::INFINITY);
    }

    #[test]
    fn validation_names_field_value_and_range() {
        let o = NewtonOptions {
            relative_tolerance: 1.0,
            ..Default::default()
        };
        assert_eq!(
            o.validate(),
            Err(NewtonError::InvalidOption {
                name: "relative_tolerance",
                value: 1.0,
                allowed: "[0, 1)"
            })
        );
        let o = NewtonOptions {
            globalization: Globalization::NonMonotone {
                memory: 0,
                line_search: LineSearchOptions::default(),
            },
            ..Default::default()
        };
        assert!(matches!(
            o.validate(),
            Err(NewtonError::InvalidOption {
                name: "globalization.memory",
                ..
            })
        ));
        let o = NewtonOptions {
            globalization: Globalization::Armijo(LineSearchOptions {
                shrink: 0.0,
                ..Default::default()
            }),
            ..Default::default()
        };
        assert!(
            matches!(o.validate(), Err(NewtonError::InvalidOption { name: "line_search.shrink", value, .. }) if value == 0.0)
        );
        let o = NewtonOptions {
            absolute_tolerance: f64::NAN,
            ..Default::default()
        };
        assert!(matches!(
            o.validate(),
            Err(NewtonError::InvalidOption {
                name: "absolute_tolerance",
                ..
            })
        ));
        assert!(NewtonOptions::default().validate().is_ok());
    }
}
