//! The one Newton iteration of the crate: `y <- y + alpha d` with a pluggable direction `d`
//! (a plain solve `J d = -F` for [`crate::newton`], the bordered solve of the continuation
//! corrector) and one set of rules for the step length and for stopping.
//!
//! The system `G(y) = 0` is seen through [`NewtonSystem`]: an evaluation (which may fail
//! outside the problem's domain) and a direction. The kernel owns the loop, the merit
//! `m(y) = |G(y)|^2 / 2`, the line search ([`crate::linesearch`]), the termination tests,
//! the best iterate and the counters of residual evaluations and backtracks; directions
//! count their own Jacobians, factorizations and solves.

use crate::linesearch::{backtrack, LineSearchOptions, NonMonotoneHistory};
use crate::EvaluationError;

use super::{Globalization, WorkCounters};

/// A system `G(y) = 0` on `R^N` with a way to compute Newton directions.
pub(crate) trait NewtonSystem {
    /// Why a direction could not be computed.
    type Failure;

    /// Writes `G(y)` into `g`.
    fn evaluate(&mut self, y: &[f64], g: &mut [f64]) -> Result<(), EvaluationError>;

    /// Writes a Newton direction at `y` (where `G(y) = g`) into `d`.
    fn direction(
        &mut self,
        y: &[f64],
        g: &[f64],
        d: &mut [f64],
        counters: &mut WorkCounters,
    ) -> Result<(), Self::Failure>;

    /// The norm in which steps and iterates are compared by the stall test.
    fn step_norm(&self, v: &[f64]) -> f64 {
        norm2(v)
    }
}

/// The rules of one run (validated by the callers' options).
#[derive(Clone, Copy, Debug)]
pub(crate) struct KernelRules {
    pub absolute_tolerance: f64,
    pub relative_tolerance: f64,
    /// `|G|` that round-off alone produces near a solution: the tolerance is at least this,
    /// and a run that stalls within [`FLOOR_STALL_FACTOR`] of it has converged.
    pub residual_floor: f64,
    pub step_tolerance: f64,
    pub max_iterations: usize,
    /// Steps taken before convergence may be declared (the continuation corrector takes
    /// at least one, for its tangent).
    pub min_iterations: usize,
    pub globalization: Globalization,
    /// Return the iterate of smallest `|G|` rather than the last one.
    pub restore_best: bool,
    /// Stop a run that stopped making progress ([`Stagnation`]); `None`: never.
    pub stagnation: Option<Stagnation>,
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
pub const FLOOR_STALL_FACTOR: f64 = 100.0;

/// Why the kernel stopped.
#[derive(Clone, Copy, Debug, PartialEq)]
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
    OutsideDomain(EvaluationError),
}

/// What a run did (the histories live in the [`Kernel`] until the next run).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Run<E> {
    pub stop: Stop<E>,
    pub iterations: usize,
    /// `max(absolute, relative |G(y_0)|, floor)`.
    pub tolerance: f64,
    /// Smallest finite `|G|` over the iterates (`inf` if none was finite).
    pub smallest: f64,
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
    /// `|G|` at the initial guess and after each accepted step.
    pub residual_norms: Vec<f64>,
    /// Accepted step lengths.
    pub step_lengths: Vec<f64>,
    /// Accepted step norms `alpha |d|`.
    pub step_norms: Vec<f64>,
}

/// `|v|_2`, infinite for any non-finite component; scaled against overflow and underflow.
pub(crate) fn norm2(v: &[f64]) -> f64 {
    // One pass in the common case; the scaled pass only when the squares overflow or
    // underflow (or a component is not finite).
    let squares: f64 = v.iter().map(|x| x * x).sum();
    if squares.is_finite() && squares > f64::MIN_POSITIVE / f64::EPSILON {
        return squares.sqrt();
    }
    let mut scale = 0.0_f64;
    for x in v {
        if !x.is_finite() {
            return f64::INFINITY;
        }
        scale = scale.max(x.abs());
    }
    if scale == 0.0 {
        return 0.0;
    }
    scale * v.iter().map(|x| (x / scale).powi(2)).sum::<f64>().sqrt()
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

    /// Runs the iteration from `y` (initial guess in; the returned iterate out, see
    /// [`KernelRules::restore_best`]). On return `self.g` holds `G` at the returned `y`
    /// (unless it could not be evaluated).
    pub(crate) fn run<S: NewtonSystem + ?Sized>(
        &mut self,
        system: &mut S,
        y: &mut [f64],
        rules: &KernelRules,
        counters: &mut WorkCounters,
    ) -> Run<S::Failure> {
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
        // Room for a run of up to 1000 iterations once and for all (no allocation per run).
        let capacity = rules.max_iterations.min(1000) + 1;
        for v in [
            &mut self.residual_norms,
            &mut self.step_lengths,
            &mut self.step_norms,
        ] {
            v.clear();
            v.reserve(capacity);
        }
        let (memory, line_search, mut full_steps) = match rules.globalization {
            Globalization::None => (1, None, 0),
            Globalization::Armijo(ls) => (1, Some(ls), 0),
            Globalization::NonMonotone {
                memory,
                line_search,
            } => (memory, Some(line_search), 0),
            Globalization::Hybrid {
                full_steps,
                memory,
                line_search,
            }
            | Globalization::Polyalgorithm {
                full_steps,
                memory,
                line_search,
            } => (memory, Some(line_search), full_steps),
        };
        let history = self
            .history
            .get_or_insert_with(|| NonMonotoneHistory::new(memory));

        let mut norm = match Self::evaluate(system, y, &mut self.g, counters) {
            Ok(norm) => norm,
            Err(e) => {
                return Run {
                    stop: Stop::OutsideDomain(e),
                    iterations: 0,
                    tolerance: rules.absolute_tolerance,
                    smallest: f64::INFINITY,
                }
            }
        };
        self.residual_norms.push(norm);
        let tolerance = rules
            .absolute_tolerance
            .max(rules.relative_tolerance * norm)
            .max(rules.residual_floor);
        history.reset(memory);
        history.push(merit_of(norm));
        self.best.copy_from_slice(y);
        self.best_g.copy_from_slice(&self.g);
        self.start.copy_from_slice(y);
        let mut best_norm = norm;
        let mut smallest = if norm.is_finite() {
            norm
        } else {
            f64::INFINITY
        };
        let mut iterations = 0;

        let stop = 'newton: {
            if !norm.is_finite() {
                break 'newton Stop::NonFinite;
            }
            if rules.min_iterations == 0 && norm <= tolerance {
                break 'newton Stop::Converged;
            }
            while iterations < rules.max_iterations {
                if full_steps > 0 && iterations == full_steps {
                    // End of the full-step phase: start again from the initial guess with the
                    // line search (the full steps may have wandered into a region where
                    // descent stalls; the best iterate so far is kept).
                    full_steps = 0;
                    y.copy_from_slice(&self.start);
                    norm = match Self::evaluate(system, y, &mut self.g, counters) {
                        Ok(norm) => norm,
                        Err(e) => break 'newton Stop::OutsideDomain(e),
                    };
                    history.reset(memory);
                    history.push(merit_of(norm));
                }
                if let Err(e) = system.direction(y, &self.g, &mut self.d, counters) {
                    break 'newton Stop::Direction(e);
                }
                if self.d.iter().any(|v| !v.is_finite()) {
                    break 'newton Stop::NonFinite;
                }

                let merit0 = merit_of(norm);
                let (g_trial, trial, d) = (&mut self.g_trial, &mut self.trial, &self.d);
                let mut domain_error = None;
                let mut merit = |alpha: f64| {
                    for ((t, yi), di) in trial.iter_mut().zip(y.iter()).zip(d) {
                        *t = yi + alpha * di;
                    }
                    match Self::evaluate(system, trial, g_trial, counters) {
                        Ok(norm) => merit_of(norm),
                        Err(e) => {
                            domain_error = Some(e);
                            f64::INFINITY
                        }
                    }
                };
                let mut alpha = 1.0;
                let full_step_phase = iterations < full_steps;
                if full_step_phase && merit(1.0).is_finite() {
                    // Full step accepted without a merit test.
                } else if let Some(ls) = line_search {
                    if full_step_phase {
                        // A full step that cannot be evaluated ends the full-step phase.
                        full_steps = 0;
                        history.reset(memory);
                        history.push(merit0);
                    }
                    match backtrack(history.reference(), -2.0 * merit0, &ls, &mut merit) {
                        Ok(step) => {
                            counters.line_search_backtracks += step.backtracks;
                            alpha = step.step;
                        }
                        Err(fail) => {
                            counters.line_search_backtracks += fail.backtracks;
                            break 'newton Stop::LineSearchFailed {
                                last_step: fail.last_step,
                            };
                        }
                    }
                } else if !merit(1.0).is_finite() {
                    break 'newton match domain_error {
                        Some(e) => Stop::OutsideDomain(e),
                        None => Stop::NonFinite,
                    };
                }

                // Accept: y <- trial, G <- G(trial).
                y.copy_from_slice(&self.trial);
                std::mem::swap(&mut self.g, &mut self.g_trial);
                norm = norm2(&self.g);
                iterations += 1;
                let step_norm = alpha * system.step_norm(&self.d);
                self.residual_norms.push(norm);
                self.step_lengths.push(alpha);
                self.step_norms.push(step_norm);
                history.push(merit_of(norm));
                smallest = smallest.min(norm);
                if norm < best_norm {
                    best_norm = norm;
                    if rules.restore_best {
                        self.best.copy_from_slice(y);
                        self.best_g.copy_from_slice(&self.g);
                    }
                }
                if iterations >= rules.min_iterations && norm <= tolerance {
                    break 'newton Stop::Converged;
                }
                if rules
                    .stagnation
                    .is_some_and(|rule| rule.holds(&self.residual_norms))
                {
                    break 'newton Stop::Stagnated;
                }
                if step_norm <= rules.step_tolerance * (1.0 + system.step_norm(y)) {
                    break 'newton if norm <= FLOOR_STALL_FACTOR * rules.residual_floor {
                        Stop::ConvergedAtFloor
                    } else {
                        Stop::Stalled { step_norm }
                    };
                }
            }
            Stop::MaxIterations
        };

        // Return the best iterate (non-monotone steps and failures may end elsewhere).
        if rules.restore_best && (norm.is_nan() || best_norm < norm) {
            y.copy_from_slice(&self.best);
            self.g.copy_from_slice(&self.best_g);
        }
        Run {
            stop,
            iterations,
            tolerance,
            smallest,
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

/// The line search of an Armijo rule (used by the continuation's corrector option).
pub(crate) fn armijo(line_search: Option<LineSearchOptions>) -> Globalization {
    match line_search {
        Some(ls) => Globalization::Armijo(ls),
        None => Globalization::None,
    }
}
