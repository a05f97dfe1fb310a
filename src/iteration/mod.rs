//! The layer under the drivers: the one Newton iteration of the crate ([`kernel`]), the
//! work counters every driver keeps, and the report a Newton-type run returns.
//!
//! [`crate::newton`] (plain globalized Newton), [`crate::continuation`] (its corrector) and
//! [`crate::polyalgorithm`] (strategies from a poor guess) build on it; nothing here knows
//! about them. The public types are re-exported by [`crate::newton`].

pub(crate) mod forcing;
pub(crate) mod kernel;

use std::iter::Sum;
use std::ops::AddAssign;

use crate::linalg::LinearSolveError;
use crate::InvalidOption;
use crate::{EvaluationError, ProblemCounters};

/// `|F|` below which a run has ended on an exact root (the active set was found and the
/// remaining system was linear): no convergence order is estimated from such a norm.
pub const EXACT_RESIDUAL: f64 = 1e-300;

/// Why the iteration stopped.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub enum Termination {
    /// `|F| <= max(absolute, relative |F(x_0)|, residual_floor)`.
    Converged,
    /// The step stalled with `|F|` within 100 times [`Tolerances::residual_floor`]:
    /// converged as far as floating point allows.
    ConvergedAtRoundoff {
        /// `100 residual_floor`.
        floor: f64,
    },
    /// `max_iterations` reached without convergence.
    MaxIterations,
    /// The full steps of the [polyalgorithm](crate::polyalgorithm) made no progress: `|F|`
    /// fell by less than a factor 10 over their last iterations.
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
#[non_exhaustive]
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
    /// The name used in reports: `newton`, `line-search`, `newton-homotopy`, `smoothing`.
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
    /// The attempt of `strategy` that ended with `termination` after `iterations`.
    pub(crate) fn new(strategy: Strategy, iterations: usize, termination: &Termination) -> Self {
        Self {
            strategy,
            iterations,
            converged: termination.converged(),
            outcome: termination.to_string(),
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

/// Work done by a driver (a Newton run, the polyalgorithm, a continuation, a homotopy, a
/// natural sweep): the one counter type of the crate's drivers, summed over runs by `+=`
/// or [`Sum`].
///
/// ```
/// use semismooth::newton::WorkCounters;
/// let run = WorkCounters { residual_evaluations: 3, linear_solves: 2, ..Default::default() };
/// let total: WorkCounters = [run, run].into_iter().sum();
/// assert_eq!((total.residual_evaluations, total.linear_solves), (6, 4));
/// ```
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
    /// Krylov iterations of the linear solver over the run
    /// ([`crate::LinearSolve::krylov_iterations`]; 0 for direct solvers).
    pub krylov_iterations: u64,
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
        self.krylov_iterations += rhs.krylov_iterations;
        self.problem += rhs.problem;
    }
}

impl Sum for WorkCounters {
    fn sum<I: Iterator<Item = Self>>(iter: I) -> Self {
        iter.fold(Self::default(), |mut total, c| {
            total += c;
            total
        })
    }
}

/// What a Newton run did.
#[derive(Clone, Debug, PartialEq)]
pub struct NewtonReport {
    /// Why it stopped.
    pub termination: Termination,
    /// The strategy of the last attempt (the one that converged, when one did).
    pub strategy: Strategy,
    /// Every strategy tried, in order (one entry for a plain Newton run, one per attempt of
    /// the [polyalgorithm](crate::polyalgorithm)).
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
    /// one of them is below [`EXACT_RESIDUAL`] (exact termination), or when the estimate
    /// is undefined.
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
#[non_exhaustive]
pub enum NewtonError {
    /// An option is outside its allowed range.
    #[error("invalid Newton option {0}")]
    InvalidOption(#[from] InvalidOption),
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
        .any(|r| !(r.is_finite() && **r >= EXACT_RESIDUAL))
    {
        return None;
    }
    let q = (r3 / r2).ln() / (r2 / r1).ln();
    q.is_finite().then_some(q)
}

/// Histories of the attempts of a run that iterate on `F`.
#[derive(Debug, Default)]
pub(crate) struct Log {
    pub residual_norms: Vec<f64>,
    pub step_lengths: Vec<f64>,
    pub step_norms: Vec<f64>,
}

impl Log {
    /// Appends the histories of the kernel's last run.
    pub fn extend(&mut self, kernel: &kernel::Kernel) {
        self.residual_norms
            .extend_from_slice(&kernel.residual_norms);
        self.step_lengths.extend_from_slice(&kernel.step_lengths);
        self.step_norms.extend_from_slice(&kernel.step_norms);
    }
}

/// How a run on `F` ended, before its report is written.
pub(crate) struct Outcome {
    pub termination: Termination,
    /// The strategy of the last attempt.
    pub strategy: Strategy,
    pub attempts: Vec<Attempt>,
    /// `max(absolute, relative |F(x_0)|, residual_floor)`.
    pub tolerance: f64,
}

impl NewtonReport {
    /// The report of a run that ended with `outcome`, its histories and its counters.
    pub(crate) fn new(outcome: Outcome, log: Log, counters: WorkCounters) -> Self {
        Self {
            observed_order: observed_order(&log.residual_norms),
            termination: outcome.termination,
            strategy: outcome.strategy,
            iterations: outcome.attempts.iter().map(|a| a.iterations).sum(),
            attempts: outcome.attempts,
            effective_tolerance: outcome.tolerance,
            residual_norms: log.residual_norms,
            step_lengths: log.step_lengths,
            step_norms: log.step_norms,
            counters,
        }
    }
}

/// Absolute tolerance on `|F|_2` of the drivers' defaults.
pub(crate) const DEFAULT_ABSOLUTE_TOLERANCE: f64 = 1e-10;
/// Stall threshold on the accepted step of the drivers' defaults.
pub(crate) const DEFAULT_STEP_TOLERANCE: f64 = 1e-15;
/// The `|F|_2` that round-off produces at an iterate `x`, in proportion to its size:
/// `per_unit min(max_{i < entries} |x_i|, cap)`. The entries are the leading block of `x`
/// whose size sets the round-off (e.g. the displacements, not the forces beside them); the
/// cap bounds the size that counts (e.g. by a gap that no open contact reaches).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateFloor {
    /// Round-off per unit of size, `>= 0` (0 = off).
    pub per_unit: f64,
    /// How many leading entries of `x` measure its size (`None`: all of them).
    pub entries: Option<usize>,
    /// The largest size that counts, `> 0` (`f64::INFINITY`: no cap).
    pub cap: f64,
}

impl StateFloor {
    /// No floor.
    pub const OFF: Self = Self {
        per_unit: 0.0,
        entries: None,
        cap: f64::INFINITY,
    };

    /// `per_unit` times the largest entry of the whole iterate, uncapped.
    pub fn per_unit(per_unit: f64) -> Self {
        Self {
            per_unit,
            ..Self::OFF
        }
    }

    /// The first field out of range, its value and what is allowed (`None`: valid).
    pub fn invalid_field(&self) -> Option<(&'static str, f64, &'static str)> {
        if !(self.per_unit.is_finite() && self.per_unit >= 0.0) {
            return Some(("per_unit", self.per_unit, "finite and >= 0"));
        }
        if self.cap.is_nan() || self.cap <= 0.0 {
            return Some(("cap", self.cap, "> 0 (infinity: no cap)"));
        }
        None
    }

    /// The floor at the iterate `x`.
    pub fn at(&self, x: &[f64]) -> f64 {
        if self.per_unit == 0.0 {
            return 0.0;
        }
        let block = &x[..self.entries.unwrap_or(x.len()).min(x.len())];
        let largest = block.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        self.per_unit * largest.min(self.cap)
    }
}

/// When a run of a driver ([`NewtonOptions`](crate::newton::NewtonOptions), the polyalgorithm's options) has converged,
/// `|F|_2 <= max(absolute, relative |F(x_0)|_2, residual_floor)`, or stalled,
/// `alpha |d| <= step_tolerance (1 + |x|)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerances {
    /// Absolute tolerance on `|F|_2`, `>= 0`.
    pub absolute_tolerance: f64,
    /// Relative tolerance on `|F|_2 / |F(x_0)|_2`, in `[0, 1)` (0 = off).
    pub relative_tolerance: f64,
    /// `|F|_2` that round-off alone produces near a solution, `>= 0` (0 = off): the
    /// tolerance is at least this, and a stall with `|F| <= 100 residual_floor` is
    /// convergence ([`Termination::ConvergedAtRoundoff`]).
    pub residual_floor: f64,
    /// `|F|_2` that round-off produces per unit of the iterate's size (0 = off): at an
    /// iterate `x` the tolerance is at least [`StateFloor::at`]`(x)` (a linear problem near
    /// resonance, whose answer and round-off grow together).
    pub state_floor: StateFloor,
    /// Stall threshold on the accepted step, `>= 0`.
    pub step_tolerance: f64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Self {
            absolute_tolerance: DEFAULT_ABSOLUTE_TOLERANCE,
            relative_tolerance: 0.0,
            residual_floor: 0.0,
            state_floor: StateFloor::OFF,
            step_tolerance: DEFAULT_STEP_TOLERANCE,
        }
    }
}

impl Tolerances {
    /// The default tolerances with the absolute tolerance `absolute`.
    pub fn absolute(absolute: f64) -> Self {
        Self {
            absolute_tolerance: absolute,
            ..Self::default()
        }
    }

    /// The `|F|_2` below which a run from `|F(x_0)|_2 = initial_norm` has converged.
    pub(crate) fn threshold(&self, initial_norm: f64) -> f64 {
        self.absolute_tolerance
            .max(self.relative_tolerance * initial_norm)
            .max(self.residual_floor)
    }

    /// The round-off floor at the iterate `x`: `residual_floor + state_floor.at(x)`.
    pub(crate) fn floor_at(&self, x: &[f64]) -> f64 {
        self.residual_floor + self.state_floor.at(x)
    }

    /// Checks every field; the error names the field, the value and the allowed range.
    pub fn validate(&self) -> Result<(), NewtonError> {
        for (name, t) in [
            ("absolute_tolerance", self.absolute_tolerance),
            ("residual_floor", self.residual_floor),
            ("step_tolerance", self.step_tolerance),
        ] {
            if !(t.is_finite() && t >= 0.0) {
                return Err(NewtonError::InvalidOption(InvalidOption::new(
                    name,
                    t,
                    "finite and >= 0",
                )));
            }
        }
        let t = self.relative_tolerance;
        if !(t.is_finite() && (0.0..1.0).contains(&t)) {
            return Err(NewtonError::InvalidOption(InvalidOption::new(
                "relative_tolerance",
                t,
                "[0, 1)",
            )));
        }
        match self.state_floor.invalid_field() {
            Some((field, value, allowed)) => Err(NewtonError::InvalidOption(InvalidOption::new(
                match field {
                    "per_unit" => "state_floor.per_unit",
                    _ => "state_floor.cap",
                },
                value,
                allowed,
            ))),
            None => Ok(()),
        }
    }
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
    fn a_state_floor_measures_its_leading_entries_up_to_its_cap() {
        let x = [3.0, -5.0, 100.0];
        assert_eq!(StateFloor::OFF.at(&x), 0.0);
        assert_eq!(StateFloor::per_unit(2.0).at(&x), 200.0);
        let displacements = StateFloor {
            per_unit: 2.0,
            entries: Some(2),
            cap: f64::INFINITY,
        };
        assert_eq!(displacements.at(&x), 10.0);
        let capped = StateFloor {
            cap: 4.0,
            ..displacements
        };
        assert_eq!(capped.at(&x), 8.0);
        assert_eq!(capped.invalid_field(), None);
        let nan_cap = StateFloor {
            cap: f64::NAN,
            ..displacements
        };
        assert_eq!(nan_cap.invalid_field().map(|f| f.0), Some("cap"));
    }
}
