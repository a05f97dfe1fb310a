//! Semismooth Newton method with line-search globalization: a direction and a step
//! length.
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
//! ([`Factorize`], [`LinearSolve`](crate::LinearSolve)). The iteration itself (step rule,
//! termination tests, best iterate) is the one the continuation corrector runs too, with a
//! bordered direction instead of the plain solve. [`NewtonSolver`] keeps all buffers (and
//! the Jacobian) between solves, so parameter sweeps allocate nothing per iteration;
//! [`solve`] is a one-shot wrapper.
//!
//! From a poor guess (a forced structure from zero) a line search on the merit can stall
//! at its kinks: [`crate::polyalgorithm`] combines these runs with continuation paths.
//!
//! # Outcome
//!
//! `Err` ([`NewtonError`]) only when the solver could not run: invalid options, an initial
//! guess of the wrong length. A run that ran returns `Ok(report)` whatever it ended with:
//! its typed [`NewtonReport::termination`] says why it stopped
//! ([`NewtonReport::converged`] whether it converged), and the best iterate is written to
//! `x`. The report type, its [`Termination`], [`Strategy`] and [`Attempt`], and the
//! [`WorkCounters`] are shared by every driver of the crate.
//!
//! # Options and defaults ([`NewtonOptions`])
//!
//! | field | default | meaning |
//! |---|---|---|
//! | `tolerances.absolute_tolerance` | `1e-10` | converged when `\|F\|_2 <= max(abs, rel \|F(x_0)\|_2, floor)` |
//! | `tolerances.relative_tolerance` | `0` (off) | see above; in `[0, 1)` |
//! | `tolerances.residual_floor` | `0` (off) | `\|F\|` round-off alone produces near a solution: the tolerance is at least this, and a run that stalls with `\|F\| <= 100 floor` has converged ([`Termination::ConvergedAtRoundoff`]) |
//! | `tolerances.state_floor` | [`StateFloor::OFF`] | round-off in proportion to the iterate's size: at an iterate `x` the tolerance is at least `per_unit min(max_{i < entries} \|x_i\|, cap)` (a linear response near resonance, whose round-off grows with it) |
//! | `tolerances.step_tolerance` | `1e-15` | stalled when `alpha \|d\| <= step_tol (1 + \|x\|)` |
//! | `max_iterations` | `200` | Newton iterations (not counting line-search trials) |
//! | `globalization` | [`Globalization::hybrid`] | [`None`](Globalization::None), [`Armijo`](Globalization::Armijo), [`NonMonotone`](Globalization::NonMonotone) (memory 10) or [`Hybrid`](Globalization::Hybrid) (30 full steps, then non-monotone with memory 10); line searches with [`LineSearchOptions::default`] (`sigma = 1e-4`, `shrink = 0.5`, `min_step = 1e-10`) |
//!
//! ```
//! use faer::Mat;
//! use semismooth::linalg::FaerDenseLu;
//! use semismooth::newton::{solve, Globalization, NewtonOptions, Strategy};
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
//! let options = NewtonOptions { globalization: Globalization::non_monotone(), ..Default::default() };
//! let report = solve(&mut Lcp, &mut FaerDenseLu::new(), &mut x, &options).unwrap();
//! assert!(report.converged() && report.strategy == Strategy::LineSearch);
//! assert!((x[0] - 0.5).abs() < 1e-12 && x[1].abs() < 1e-12);
//! assert!(report.iterations <= 5);
//! ```

use crate::iteration::kernel::{
    Kernel, KernelRules, NewtonSystem, Run, StepRule, Stop, FLOOR_STALL_FACTOR,
};
pub use crate::iteration::{
    Attempt, NewtonError, NewtonReport, StateFloor, Strategy, Termination, Tolerances,
    WorkCounters, EXACT_RESIDUAL,
};
use crate::iteration::{Log, Outcome};
use crate::linalg::{LinearSolveError, SolveAccuracy};
pub use crate::linesearch::LineSearchOptions;
use crate::InvalidOption;
use crate::{EvaluationError, Factorize, GeneralizedJacobian, ProblemCounters};

/// How the step length is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
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
    /// Full steps first, then the non-monotone line search (the default): the first
    /// `full_steps` iterations take `alpha = 1` whenever `F` can be evaluated and stays
    /// finite (semismooth Newton on complementarity systems then behaves as a primal-dual
    /// active-set method, which may cross regions of large residual on its way to the
    /// solution); if it has not converged by then, it restarts from the initial guess with
    /// the GLL line search (the best iterate of both phases is returned). A full step that
    /// cannot be evaluated hands over to the line search from where it is.
    Hybrid {
        /// Iterations of the full-step phase.
        full_steps: usize,
        /// Memory of the non-monotone phase (`>= 1`).
        memory: usize,
        /// Backtracking options of the non-monotone phase.
        line_search: LineSearchOptions,
    },
}

/// Full steps of [`Globalization::hybrid`] (and of the polyalgorithm's first attempt).
pub(crate) const DEFAULT_FULL_STEPS: usize = 30;
/// Memory of the default non-monotone line search.
pub(crate) const DEFAULT_MEMORY: usize = 10;

impl Globalization {
    /// [`Globalization::Hybrid`] with 30 full steps, then GLL with memory 10 (the default).
    pub fn hybrid() -> Self {
        Self::Hybrid {
            full_steps: DEFAULT_FULL_STEPS,
            memory: DEFAULT_MEMORY,
            line_search: LineSearchOptions::default(),
        }
    }

    /// [`Globalization::NonMonotone`] with memory 10.
    pub fn non_monotone() -> Self {
        Self::NonMonotone {
            memory: DEFAULT_MEMORY,
            line_search: LineSearchOptions::default(),
        }
    }
}

impl Default for Globalization {
    fn default() -> Self {
        Self::hybrid()
    }
}

/// Options of the Newton driver (defaults in the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    /// When a run has converged or stalled.
    pub tolerances: Tolerances,
    /// Maximum number of Newton iterations.
    pub max_iterations: usize,
    /// Step-length rule.
    pub globalization: Globalization,
}

/// Newton iterations of the drivers' defaults.
pub(crate) const DEFAULT_MAX_ITERATIONS: usize = 200;

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            tolerances: Tolerances::default(),
            max_iterations: DEFAULT_MAX_ITERATIONS,
            globalization: Globalization::default(),
        }
    }
}

/// Checks a line search with its memory (`memory_name` names the memory's field).
pub(crate) fn validate_line_search(
    memory_name: &'static str,
    memory: usize,
    line_search: &LineSearchOptions,
) -> Result<(), NewtonError> {
    InvalidOption::check(memory >= 1, memory_name, memory as f64, ">= 1")?;
    line_search
        .validate()
        .map_err(|e| crate::linesearch::within("line_search", e))?;
    Ok(())
}

impl NewtonOptions {
    /// Checks every field; the error names the field, the value and the allowed range.
    pub fn validate(&self) -> Result<(), NewtonError> {
        self.tolerances.validate()?;
        match self.globalization {
            Globalization::None => Ok(()),
            Globalization::Armijo(ls) => validate_line_search("globalization.memory", 1, &ls),
            Globalization::NonMonotone {
                memory,
                line_search,
            }
            | Globalization::Hybrid {
                memory,
                line_search,
                ..
            } => validate_line_search("globalization.memory", memory, &line_search),
        }
    }

    /// The kernel's rules of a run with the step rule `step`.
    fn rules(&self, step: StepRule) -> KernelRules {
        KernelRules::new(self.tolerances, self.max_iterations, step)
    }
}

/// Why a plain Newton direction could not be computed.
pub(crate) enum PlainFailure {
    Linear(LinearSolveError),
    Evaluation(EvaluationError),
}

/// `J d = -F` with the problem's Jacobian and the linear solver.
pub(crate) struct PlainNewton<'a, P: GeneralizedJacobian + ?Sized, S: ?Sized> {
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
        accuracy: SolveAccuracy,
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
        self.solver
            .solve_in_place_to(d, accuracy)
            .map_err(PlainFailure::Linear)
    }
}

/// The state plain Newton keeps between runs: the Jacobian (created by the problem's
/// `new_jacobian` on the first run and again only when the dimension changes) and the
/// kernel's buffers. Shared by [`NewtonSolver`] and the polyalgorithm.
#[derive(Debug)]
pub(crate) struct Workspace<J> {
    jacobian: Option<J>,
    dim: usize,
    pub kernel: Kernel,
}

impl<J> Default for Workspace<J> {
    fn default() -> Self {
        Self {
            jacobian: None,
            dim: 0,
            kernel: Kernel::default(),
        }
    }
}

impl<J> Workspace<J> {
    /// Checks `x` against `problem` and sizes the workspace for it; the solve's work is
    /// counted from here.
    pub fn begin<P, S>(
        &mut self,
        problem: &P,
        linear: &S,
        x: &[f64],
    ) -> Result<MeasuredSolve, NewtonError>
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
        Ok(MeasuredSolve {
            problem_start: problem.problem_counters(),
            krylov_start: linear.krylov_iterations(),
            counters: WorkCounters::default(),
            log: Log::default(),
        })
    }

    /// One run of the kernel with the plain direction and `rules.step` throughout; its
    /// histories are appended to `log`.
    pub fn phase<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
        rules: &KernelRules,
        counters: &mut WorkCounters,
        log: &mut Log,
    ) -> (Termination, Run<PlainFailure>)
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
        ) -> Run<PlainFailure>,
    ) -> (Termination, Run<PlainFailure>)
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
        log.extend(&self.kernel);
        let termination = termination_of(&run.stop, rules.tolerances.residual_floor);
        (termination, run)
    }
}

/// A solve under way ([`Workspace::begin`]): the work counted so far and the problem's
/// and the linear solver's totals at its start.
pub(crate) struct MeasuredSolve {
    problem_start: ProblemCounters,
    krylov_start: u64,
    pub counters: WorkCounters,
    pub log: Log,
}

impl MeasuredSolve {
    /// The report of the solve's `outcome`, with the problem's and the linear solver's work
    /// since its start.
    pub fn report<P, S>(mut self, problem: &P, linear: &S, outcome: Outcome) -> NewtonReport
    where
        P: GeneralizedJacobian + ?Sized,
        S: Factorize<P::Jacobian> + ?Sized,
    {
        self.counters.problem = problem.problem_counters().since(&self.problem_start);
        self.counters.krylov_iterations = linear.krylov_iterations() - self.krylov_start;
        NewtonReport::new(outcome, self.log, self.counters)
    }
}

/// A reusable semismooth Newton solver: options plus every buffer of the iteration and
/// the Jacobian `J`, kept between [`NewtonSolver::solve`] calls.
///
/// The Jacobian is created by the problem's `new_jacobian` on the first solve and again
/// only when the dimension changes. After a solve the linear solver holds the
/// factorization of the Jacobian at the last iterate where a Newton direction was
/// computed (not necessarily the returned `x`).
#[derive(Debug)]
pub struct NewtonSolver<J> {
    options: NewtonOptions,
    work: Workspace<J>,
}

impl<J> NewtonSolver<J> {
    /// A solver with validated `options`.
    pub fn new(options: NewtonOptions) -> Result<Self, NewtonError> {
        options.validate()?;
        Ok(Self {
            options,
            work: Workspace::default(),
        })
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
        let mut measured = self.work.begin(problem, linear, x)?;
        let backtracking = |memory, line_search| StepRule::Backtracking {
            memory,
            line_search,
        };
        let (step, full_steps) = match self.options.globalization {
            Globalization::None => (StepRule::Full, 0),
            Globalization::Armijo(line_search) => (backtracking(1, line_search), 0),
            Globalization::NonMonotone {
                memory,
                line_search,
            } => (backtracking(memory, line_search), 0),
            Globalization::Hybrid {
                full_steps,
                memory,
                line_search,
            } => (backtracking(memory, line_search), full_steps),
        };
        let rules = self.options.rules(step);
        let (termination, run) = self.work.run_with(
            problem,
            linear,
            x,
            &rules,
            (&mut measured.counters, &mut measured.log),
            |kernel, system, x, rules, counters| {
                full_steps_first(kernel, system, x, rules, full_steps, counters)
            },
        );
        let strategy = match self.options.globalization {
            Globalization::None => Strategy::FullSteps,
            Globalization::Hybrid { full_steps, .. } if run.iterations <= full_steps => {
                Strategy::FullSteps
            }
            _ => Strategy::LineSearch,
        };
        let outcome = Outcome {
            attempts: vec![Attempt::new(strategy, run.iterations, &termination)],
            termination,
            strategy,
            tolerance: run.tolerance,
        };
        Ok(measured.report(problem, linear, outcome))
    }
}

/// A run of the kernel with `rules.step` throughout, or ([`Globalization::Hybrid`],
/// `full_steps > 0` and a backtracking `rules.step`) full steps while they can be evaluated
/// for `full_steps` iterations, then `rules.step` from the initial guess for the rest of the
/// budget; a full step that cannot be evaluated hands over to the backtracking from where
/// it is instead.
fn full_steps_first<S: NewtonSystem + ?Sized>(
    kernel: &mut Kernel,
    system: &mut S,
    x: &mut [f64],
    rules: &KernelRules,
    full_steps: usize,
    counters: &mut WorkCounters,
) -> Run<S::Failure> {
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
pub(crate) fn termination_of(stop: &Stop<PlainFailure>, residual_floor: f64) -> Termination {
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
        Stop::Direction(PlainFailure::Evaluation(e)) | Stop::Evaluation(e) => {
            Termination::Evaluation(e.clone())
        }
        Stop::NonFinite => Termination::NonFinite,
    }
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
    use super::*;

    #[test]
    fn validation_names_field_value_and_range() {
        let o = NewtonOptions {
            tolerances: Tolerances {
                relative_tolerance: 1.0,
                ..Default::default()
            },
            ..Default::default()
        };
        assert_eq!(
            o.validate(),
            Err(NewtonError::InvalidOption(InvalidOption::new(
                "relative_tolerance",
                1.0,
                "[0, 1)"
            )))
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
            Err(NewtonError::InvalidOption(InvalidOption {
                name: "globalization.memory",
                ..
            }))
        ));
        let o = NewtonOptions {
            globalization: Globalization::Armijo(LineSearchOptions {
                shrink: 0.0,
                ..Default::default()
            }),
            ..Default::default()
        };
        assert!(
            matches!(o.validate(), Err(NewtonError::InvalidOption(InvalidOption { name: "line_search.shrink", value, .. })) if value == 0.0)
        );
        let o = NewtonOptions {
            tolerances: Tolerances::absolute(f64::NAN),
            ..Default::default()
        };
        assert!(matches!(
            o.validate(),
            Err(NewtonError::InvalidOption(InvalidOption {
                name: "absolute_tolerance",
                ..
            }))
        ));
        assert!(NewtonOptions::default().validate().is_ok());
    }
}
