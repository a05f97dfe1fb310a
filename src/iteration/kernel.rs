//! The one Newton iteration of the crate: `y <- y + alpha d` with a pluggable direction `d`
//! (a plain solve `J d = -F` for [`crate::newton`], the bordered solve of the continuation
//! corrector) and a step-length rule ([`StepRule`]: the full step or a backtracking line
//! search), with one set of rules for stopping.
//!
//! The system `G(y) = 0` is seen through [`NewtonSystem`]: an evaluation (which may fail
//! outside the problem's domain) and a direction. The kernel owns the loop, the merit
//! `m(y) = |G(y)|^2 / 2`, the line search ([`crate::linesearch`]), the termination tests,
//! the best iterate and the counters of residual evaluations and backtracks; directions
//! count their own Jacobians, factorizations and solves.
//!
//! A run is [`Kernel::start`], one or more [`Kernel::iterate`] (with the same or another
//! step rule, possibly after [`Kernel::restart`] from the initial guess), then
//! [`Kernel::finish`]; [`Kernel::run`] is the common case of one rule throughout.

use crate::linalg::SolveAccuracy;
use crate::linesearch::{
    backtrack, AcceptedStep, Backtrack, LineSearchOptions, NonMonotoneHistory,
};
use crate::EvaluationError;

use super::forcing::Forcing;

use super::{Tolerances, WorkCounters};

/// A system `G(y) = 0` on `R^N` with a way to compute Newton directions.
pub(crate) trait NewtonSystem {
    /// Why a direction could not be computed.
    type Failure;

    /// Writes `G(y)` into `g`.
    fn evaluate(&mut self, y: &[f64], g: &mut [f64]) -> Result<(), EvaluationError>;

    /// Writes a Newton direction at `y` (where `G(y) = g`) into `d`, its linear solve
    /// carried out as accurately as `accuracy` asks (an iterative solver's forcing term).
    fn direction(
        &mut self,
        y: &[f64],
        g: &[f64],
        d: &mut [f64],
        accuracy: SolveAccuracy,
        counters: &mut WorkCounters,
    ) -> Result<(), Self::Failure>;

    /// The norm in which steps and iterates are compared by the stall test.
    fn step_norm(&self, v: &[f64]) -> f64 {
        norm2(v)
    }
}

/// How the step length `alpha` along a direction is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum StepRule {
    /// `alpha = 1`; a step where `G` cannot be evaluated or is not finite ends the run.
    Full,
    /// Backtracking from `alpha = 1` against the largest merit of the last `memory`
    /// iterates (Grippo–Lampariello–Lucidi; `memory = 1` is Armijo).
    Backtracking {
        memory: usize,
        line_search: LineSearchOptions,
    },
    /// `alpha = 1` while the full step can be evaluated and is finite; at the first one
    /// that is not, [`StepRule::Backtracking`] from the current iterate (the rule then
    /// becomes that one).
    FullWhileFinite {
        memory: usize,
        line_search: LineSearchOptions,
    },
}

impl StepRule {
    /// Merits remembered by the rule's reference (1 for the full step).
    fn memory(&self) -> usize {
        match *self {
            Self::Full => 1,
            Self::Backtracking { memory, .. } | Self::FullWhileFinite { memory, .. } => memory,
        }
    }
}

/// The rules of one run (validated by the callers' options).
#[derive(Clone, Copy, Debug)]
pub(crate) struct KernelRules {
    /// When the run has converged or stalled; a run that stalls within
    /// [`FLOOR_STALL_FACTOR`] of the residual floor has converged.
    pub tolerances: Tolerances,
    pub max_iterations: usize,
    /// Steps taken before convergence may be declared (the continuation corrector takes
    /// at least one, for its tangent).
    pub min_iterations: usize,
    /// The step-length rule of [`Kernel::run`].
    pub step: StepRule,
    /// Return the iterate of smallest `|G|` rather than the last one.
    pub restore_best: bool,
    /// Stop a run that stopped making progress ([`Stagnation`]); `None`: never.
    pub stagnation: Option<Stagnation>,
}

impl KernelRules {
    /// The rules of a driver's run: `tolerances`, at most `max_iterations` steps of the
    /// rule `step`, the best iterate returned, no stagnation test.
    pub fn new(tolerances: Tolerances, max_iterations: usize, step: StepRule) -> Self {
        Self {
            tolerances,
            max_iterations,
            min_iterations: 0,
            step,
            restore_best: true,
            stagnation: None,
        }
    }
}

/// A run stagnates when, after at least `after` iterations, the smallest `|G|` of the last
/// `window` iterates is not below `factor` times the smallest of the iterates before them
/// (the initial guess excluded: from `x_0 = 0` the first full step usually raises `|G|`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Stagnation {
    pub after: usize,
    pub window: usize,
    pub factor: f64,
}

impl Stagnation {
    /// Whether the history `norms` (`|G|` at the initial guess and after each step)
    /// stagnates.
    fn holds(&self, norms: &[f64]) -> bool {
        let steps = norms.len().saturating_sub(1);
        if steps < self.after.max(self.window + 1) {
            return false;
        }
        let (before, recent) = norms[1..].split_at(steps - self.window);
        let smallest = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        smallest(recent) >= self.factor * smallest(before)
    }
}

/// A run that stalls with `|G| <= FLOOR_STALL_FACTOR * residual_floor` has converged as far
/// as floating point allows.
pub(crate) const FLOOR_STALL_FACTOR: f64 = 100.0;

/// Iterations of a run whose histories are reserved once and for all (longer runs grow
/// them).
const RESERVED_ITERATIONS: usize = 1000;

/// Why the kernel stopped.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Stop<E> {
    Converged,
    /// Stalled within [`FLOOR_STALL_FACTOR`] of the residual floor.
    ConvergedAtFloor,
    MaxIterations,
    /// No progress by the rule of [`KernelRules::stagnation`].
    Stagnated,
    Stalled {
        step_norm: f64,
    },
    LineSearchFailed {
        last_step: f64,
    },
    Direction(E),
    NonFinite,
    /// `G` could not be evaluated: at the initial guess, at a full step, or anywhere for an
    /// error that ends the run ([`EvaluationError::Problem`]).
    Evaluation(EvaluationError),
}

/// What a run did (the histories live in the [`Kernel`] until the next run).
#[derive(Clone, Debug)]
pub(crate) struct Run<E> {
    pub stop: Stop<E>,
    pub iterations: usize,
    /// `max(absolute, relative |G(y_0)|, floor)`.
    pub tolerance: f64,
    /// Smallest finite `|G|` over the iterates (`inf` if none was finite).
    pub smallest: f64,
}

/// Where a run stands between [`Kernel::start`] and [`Kernel::finish`].
#[derive(Clone, Copy, Debug, Default)]
struct Progress {
    /// `|G|` at the current iterate.
    norm: f64,
    /// The smallest `|G|` accepted so far (the best iterate's).
    best_norm: f64,
    /// Smallest finite `|G|` over the iterates.
    smallest: f64,
    iterations: usize,
    tolerance: f64,
}

/// Buffers of the iteration, kept between runs (nothing is allocated once sizes settle).
#[derive(Debug, Default)]
pub(crate) struct Kernel {
    g: Vec<f64>,
    g_trial: Vec<f64>,
    d: Vec<f64>,
    trial: Vec<f64>,
    best: Vec<f64>,
    best_g: Vec<f64>,
    start: Vec<f64>,
    history: Option<NonMonotoneHistory>,
    progress: Progress,
    /// The inexact-Newton forcing term of the run ([`super::forcing`]).
    forcing: Forcing,
    /// `|G|` at the initial guess and after each accepted step.
    pub residual_norms: Vec<f64>,
    /// Accepted step lengths.
    pub step_lengths: Vec<f64>,
    /// Accepted step norms `alpha |d|`.
    pub step_norms: Vec<f64>,
}

pub(crate) use crate::linalg::norm2;

/// The step a backtracking search accepted, its backtracks counted; `Err` with the stop
/// when it failed or the merit could not be evaluated.
fn backtracked<E>(
    searched: Result<AcceptedStep, Backtrack<EvaluationError>>,
    counters: &mut WorkCounters,
) -> Result<f64, Stop<E>> {
    match searched {
        Ok(accepted) => {
            counters.line_search_backtracks += accepted.backtracks;
            Ok(accepted.step)
        }
        Err(Backtrack::Failed(failure)) => {
            counters.line_search_backtracks += failure.backtracks;
            Err(Stop::LineSearchFailed {
                last_step: failure.last_step,
            })
        }
        Err(Backtrack::Aborted { error, backtracks }) => {
            counters.line_search_backtracks += backtracks;
            Err(Stop::Evaluation(error))
        }
    }
}

fn merit_of(norm: f64) -> f64 {
    if norm.is_finite() {
        0.5 * norm * norm
    } else {
        f64::INFINITY
    }
}

impl Kernel {
    /// `G(y)` (counted); `Ok(|G|)`.
    fn evaluate<S: NewtonSystem + ?Sized>(
        system: &mut S,
        y: &[f64],
        g: &mut [f64],
        counters: &mut WorkCounters,
    ) -> Result<f64, EvaluationError> {
        counters.residual_evaluations += 1;
        system.evaluate(y, g)?;
        Ok(norm2(g))
    }

    /// The non-monotone history reset to `memory` values.
    fn reset_history(&mut self, memory: usize) -> &mut NonMonotoneHistory {
        let history = self
            .history
            .get_or_insert_with(|| NonMonotoneHistory::new(memory));
        history.reset(memory);
        history
    }

    /// Runs the iteration from `y` with `rules.step` throughout (initial guess in; the
    /// returned iterate out, see [`KernelRules::restore_best`]). On return `self.g` holds
    /// `G` at the returned `y` (unless it could not be evaluated).
    pub(crate) fn run<S: NewtonSystem + ?Sized>(
        &mut self,
        system: &mut S,
        y: &mut [f64],
        rules: &KernelRules,
        counters: &mut WorkCounters,
    ) -> Run<S::Failure> {
        let mut step = rules.step;
        let stop = self
            .start(system, y, rules, counters)
            .or_else(|| self.iterate(system, y, rules, &mut step, rules.max_iterations, counters));
        self.finish(y, rules, stop.unwrap_or(Stop::MaxIterations))
    }

    /// Begins a run at `y`: evaluates `G`, sets the tolerance, resets the histories (the
    /// line-search reference with `rules.step`'s memory). `Some(stop)` when the run ends
    /// there (converged, or `G` could not be evaluated or is not finite).
    pub(crate) fn start<S: NewtonSystem + ?Sized>(
        &mut self,
        system: &mut S,
        y: &[f64],
        rules: &KernelRules,
        counters: &mut WorkCounters,
    ) -> Option<Stop<S::Failure>> {
        let n = y.len();
        for v in [
            &mut self.g,
            &mut self.g_trial,
            &mut self.d,
            &mut self.trial,
            &mut self.best,
            &mut self.best_g,
            &mut self.start,
        ] {
            v.resize(n, 0.0);
        }
        // Room for a long run once and for all (no allocation per run).
        let capacity = rules.max_iterations.min(RESERVED_ITERATIONS) + 1;
        for v in [
            &mut self.residual_norms,
            &mut self.step_lengths,
            &mut self.step_norms,
        ] {
            v.clear();
            v.reserve(capacity);
        }
        self.forcing = Forcing::default();
        self.progress = Progress {
            norm: f64::INFINITY,
            best_norm: f64::INFINITY,
            smallest: f64::INFINITY,
            iterations: 0,
            tolerance: rules.tolerances.absolute_tolerance,
        };
        let norm = match Self::evaluate(system, y, &mut self.g, counters) {
            Ok(norm) => norm,
            Err(e) => return Some(Stop::Evaluation(e)),
        };
        self.residual_norms.push(norm);
        let tolerance = rules.tolerances.threshold(norm);
        self.reset_history(rules.step.memory()).push(merit_of(norm));
        self.best.copy_from_slice(y);
        self.best_g.copy_from_slice(&self.g);
        self.start.copy_from_slice(y);
        self.progress = Progress {
            norm,
            best_norm: norm,
            smallest: if norm.is_finite() {
                norm
            } else {
                f64::INFINITY
            },
            iterations: 0,
            tolerance,
        };
        if !norm.is_finite() {
            return Some(Stop::NonFinite);
        }
        let converged = norm <= tolerance.max(rules.tolerances.floor_at(y));
        (rules.min_iterations == 0 && converged).then_some(Stop::Converged)
    }

    /// Goes back to the run's initial guess (`y` overwritten) and resets the line-search
    /// reference for `step`; the iteration count, the best iterate and the histories go
    /// on. `Some(stop)` when `G` can no longer be evaluated there.
    pub(crate) fn restart<S: NewtonSystem + ?Sized>(
        &mut self,
        system: &mut S,
        y: &mut [f64],
        step: &StepRule,
        counters: &mut WorkCounters,
    ) -> Option<Stop<S::Failure>> {
        y.copy_from_slice(&self.start);
        let norm = match Self::evaluate(system, y, &mut self.g, counters) {
            Ok(norm) => norm,
            Err(e) => return Some(Stop::Evaluation(e)),
        };
        self.progress.norm = norm;
        self.forcing = Forcing::default();
        self.reset_history(step.memory()).push(merit_of(norm));
        None
    }

    /// Iterates with the step rule `step` until the run has made `until` iterations in all
    /// (`None`) or it stops (`Some`). A [`StepRule::FullWhileFinite`] that had to backtrack
    /// is [`StepRule::Backtracking`] on return.
    pub(crate) fn iterate<S: NewtonSystem + ?Sized>(
        &mut self,
        system: &mut S,
        y: &mut [f64],
        rules: &KernelRules,
        step: &mut StepRule,
        until: usize,
        counters: &mut WorkCounters,
    ) -> Option<Stop<S::Failure>> {
        while self.progress.iterations < until {
            let tolerance = self.progress.tolerance.max(rules.tolerances.floor_at(y));
            // Full steps keep exact directions: semismooth Newton's finite termination on a
            // piecewise-affine system rests on them (an inexact direction can leave the
            // right active set: a Krylov run then fell back from 13 full steps to 42
            // iterations of the smoothing path on 100 stops).
            let accuracy = match step {
                StepRule::Full => SolveAccuracy::new(0.0, 0.0),
                _ => self.forcing.next(self.progress.norm, tolerance),
            };
            if let Err(e) = system.direction(y, &self.g, &mut self.d, accuracy, counters) {
                return Some(Stop::Direction(e));
            }
            if self.d.iter().any(|v| !v.is_finite()) {
                return Some(Stop::NonFinite);
            }

            let merit0 = merit_of(self.progress.norm);
            let (g_trial, trial, d) = (&mut self.g_trial, &mut self.trial, &self.d);
            // A domain error is an infinite merit (the step is shortened); an error that
            // ends the run ends the search.
            let mut domain_error = None;
            let mut merit = |alpha: f64| {
                for ((t, yi), di) in trial.iter_mut().zip(y.iter()).zip(d) {
                    *t = yi + alpha * di;
                }
                match Self::evaluate(system, trial, g_trial, counters) {
                    Ok(norm) => Ok(merit_of(norm)),
                    Err(e) if e.ends_run() => Err(e),
                    Err(e) => {
                        domain_error = Some(e);
                        Ok(f64::INFINITY)
                    }
                }
            };
            let line_search = match *step {
                StepRule::Full => match merit(1.0) {
                    Ok(m) if m.is_finite() => None,
                    Ok(_) => return Some(domain_error.map_or(Stop::NonFinite, Stop::Evaluation)),
                    Err(e) => return Some(Stop::Evaluation(e)),
                },
                StepRule::FullWhileFinite {
                    memory,
                    line_search,
                } => match merit(1.0) {
                    Ok(m) if m.is_finite() => None,
                    Ok(_) => {
                        // A full step that cannot be evaluated ends the full steps.
                        *step = StepRule::Backtracking {
                            memory,
                            line_search,
                        };
                        let history = self.history.as_mut().expect("reset by start");
                        history.reset(memory);
                        history.push(merit0);
                        Some(line_search)
                    }
                    Err(e) => return Some(Stop::Evaluation(e)),
                },
                StepRule::Backtracking { line_search, .. } => Some(line_search),
            };
            let mut alpha = 1.0;
            if let Some(ls) = line_search {
                let history = self.history.as_ref().expect("reset by start");
                let searched = backtrack(history.reference(), -2.0 * merit0, &ls, &mut merit);
                match backtracked(searched, counters) {
                    Ok(step) => alpha = step,
                    Err(stop) => return Some(stop),
                }
            }

            if let Some(stop) = self.accept(system, y, rules, alpha) {
                return Some(stop);
            }
        }
        None
    }

    /// Takes the step of length `alpha` along the direction (`y` and `G` become the trial
    /// point's), records it and applies the stopping rules: `Some(stop)` when the run ends.
    fn accept<S: NewtonSystem + ?Sized>(
        &mut self,
        system: &S,
        y: &mut [f64],
        rules: &KernelRules,
        alpha: f64,
    ) -> Option<Stop<S::Failure>> {
        // Accept: y <- trial, G <- G(trial).
        y.copy_from_slice(&self.trial);
        std::mem::swap(&mut self.g, &mut self.g_trial);
        let norm = norm2(&self.g);
        let progress = &mut self.progress;
        progress.norm = norm;
        progress.iterations += 1;
        let step_norm = alpha * system.step_norm(&self.d);
        self.residual_norms.push(norm);
        self.step_lengths.push(alpha);
        self.step_norms.push(step_norm);
        if let Some(history) = self.history.as_mut() {
            history.push(merit_of(norm));
        }
        progress.smallest = progress.smallest.min(norm);
        if norm < progress.best_norm {
            progress.best_norm = norm;
            if rules.restore_best {
                self.best.copy_from_slice(y);
                self.best_g.copy_from_slice(&self.g);
            }
        }
        // The round-off floor grows with the iterate (a linear response near resonance).
        let floor = rules.tolerances.floor_at(y);
        if progress.iterations >= rules.min_iterations && norm <= progress.tolerance.max(floor) {
            progress.tolerance = progress.tolerance.max(floor);
            return Some(Stop::Converged);
        }
        if rules
            .stagnation
            .is_some_and(|rule| rule.holds(&self.residual_norms))
        {
            return Some(Stop::Stagnated);
        }
        if step_norm <= rules.tolerances.step_tolerance * (1.0 + system.step_norm(y)) {
            return Some(if norm <= FLOOR_STALL_FACTOR * floor {
                Stop::ConvergedAtFloor
            } else {
                Stop::Stalled { step_norm }
            });
        }
        None
    }

    /// Ends the run with `stop`: the best iterate goes to `y` (non-monotone steps and
    /// failures may end elsewhere) when `rules.restore_best`.
    pub(crate) fn finish<E>(
        &mut self,
        y: &mut [f64],
        rules: &KernelRules,
        stop: Stop<E>,
    ) -> Run<E> {
        let progress = self.progress;
        if rules.restore_best && (progress.norm.is_nan() || progress.best_norm < progress.norm) {
            y.copy_from_slice(&self.best);
            self.g.copy_from_slice(&self.best_g);
        }
        Run {
            stop,
            iterations: progress.iterations,
            tolerance: progress.tolerance,
            smallest: progress.smallest,
        }
    }

    /// `G` at the iterate the last run returned.
    pub(crate) fn residual(&self) -> &[f64] {
        &self.g
    }

    /// Replaces the stored `G` (when a caller returns another iterate than the last run's).
    pub(crate) fn set_residual(&mut self, g: &[f64]) {
        self.g.clear();
        self.g.extend_from_slice(g);
    }
}
