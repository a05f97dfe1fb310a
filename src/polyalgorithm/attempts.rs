//! The attempts of the polyalgorithm (module docs of [`crate::polyalgorithm`]): full steps,
//! the smoothing path, the non-monotone line search and the Newton homotopy, each from the
//! initial guess, within one iteration budget.

use crate::continuation::Predictor;
use crate::iteration::kernel::{norm2, KernelRules, Run, Stagnation, StepRule};
use crate::iteration::{Attempt, Log, Outcome};
use crate::linesearch::LineSearchOptions;
use crate::newton::{PlainFailure, Strategy, Termination, Tolerances, WorkCounters};
use crate::{Factorize, GeneralizedJacobian, Residual};

use super::path::{self, PathShape};
use super::{ends_run, Polyalgorithm, SmoothingOf};

impl<J> Polyalgorithm<J> {
    /// Full steps, then the smoothing path (when `smoothing` is given), the line search and
    /// the Newton homotopy; the best iterate of all attempts is returned.
    pub(super) fn run<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
        smoothing: Option<SmoothingOf<P>>,
        work: (&mut WorkCounters, &mut Log),
    ) -> Outcome
    where
        P: GeneralizedJacobian<Jacobian = J> + ?Sized,
        S: Factorize<J> + ?Sized,
    {
        // The initial guess in storage kept between solves (no allocation once sized).
        let mut start = std::mem::take(&mut self.start);
        start.clear();
        start.extend_from_slice(x);
        let outcome = self.attempts(problem, linear, x, &start, smoothing, work);
        self.start = start;
        outcome
    }

    /// The attempts of the polyalgorithm from `start` (= `x` on entry), with the run's
    /// counters and histories.
    fn attempts<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
        start: &[f64],
        smoothing: Option<SmoothingOf<P>>,
        (counters, log): (&mut WorkCounters, &mut Log),
    ) -> Outcome
    where
        P: GeneralizedJacobian<Jacobian = J> + ?Sized,
        S: Factorize<J> + ?Sized,
    {
        let base = KernelRules {
            max_iterations: self.options.full_steps.min(self.options.max_iterations),
            ..self.options.rules(StepRule::Full)
        };
        // With a smoothing to fall back on, the full steps stop as soon as they stagnate.
        let first = KernelRules {
            stagnation: smoothing.is_some().then_some(FULL_STEP_STAGNATION),
            ..base
        };

        // 1. Full steps.
        let (termination, run) = self.work.phase(problem, linear, x, &first, counters, log);
        let tolerance = run.tolerance;
        let attempt = Attempt::new(Strategy::FullSteps, run.iterations, &termination);
        if termination.converged() || ends_run(&termination) {
            return ended(termination, Strategy::FullSteps, vec![attempt], tolerance);
        }
        let scale = path::state_scale(&self.work.kernel.step_norms, x.len());
        let best = Best::new(x, self.work.kernel.residual(), run.smallest);
        let mut attempts = Attempts {
            solver: self,
            problem,
            linear,
            x,
            start,
            counters,
            log,
            base,
            stagnates: first.stagnation.is_some(),
            tolerance,
            scale,
            attempts: vec![attempt],
            used: run.iterations,
            best,
            last: termination,
            strategy: Strategy::FullSteps,
        };
        if let Some(outcome) = attempts.smoothing(smoothing) {
            return outcome;
        }
        if let Some(outcome) = attempts.line_search() {
            return outcome;
        }
        if let Some(outcome) = attempts.homotopy() {
            return outcome;
        }
        attempts.best_outcome()
    }

    /// The smoothing path from `x`: `F_mu0(x) = 0` solved by Newton with an Armijo search
    /// (the smoothed merit is differentiable), then followed to `mu0 10^-SMOOTHING_DECADES`.
    fn smoothing_path<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
        setup: &SmoothingSetup<P>,
        counters: &mut WorkCounters,
    ) -> path::PathOutcome
    where
        P: GeneralizedJacobian<Jacobian = J> + ?Sized,
        S: Factorize<J> + ?Sized,
    {
        let mut failed = path::PathOutcome::default();
        let SmoothingSetup {
            ops,
            mu0,
            state_scale,
            tolerance,
            budget,
            line_search,
            tolerance_rate,
        } = *setup;
        let mut smoothed = path::SmoothingPath::new(&mut *problem, ops, mu0);
        let mut f = vec![0.0; x.len()];
        counters.residual_evaluations += 1;
        if let Err(error) = smoothed.residual(x, &mut f) {
            failed.reason = Some("the smoothed residual cannot be evaluated at the start".into());
            failed.error = error.ends_run().then_some(error);
            return failed;
        }
        let accuracy = tolerance.max(SMOOTHING_ACCURACY * norm2(&f));
        let mut smoothed = smoothed.with_tolerance_decay(tolerance_rate, tolerance / accuracy);
        let rules = KernelRules {
            tolerances: Tolerances {
                absolute_tolerance: accuracy,
                relative_tolerance: 0.0,
                ..self.options.tolerances
            },
            max_iterations: budget.min(SMOOTHING_START_ITERATIONS),
            ..self.options.rules(StepRule::Backtracking {
                memory: 1,
                line_search,
            })
        };
        let mut scratch = Log::default();
        // The smoothed iterates are not iterates of F: their histories are not reported.
        let (termination, run) =
            self.work
                .phase(&mut smoothed, linear, x, &rules, counters, &mut scratch);
        failed.iterations = run.iterations;
        if !termination.converged() {
            failed.reason = Some(format!("the smoothed problem at the start: {termination}"));
            if let Termination::Evaluation(error) = termination {
                failed.error = error.ends_run().then_some(error);
            }
            return failed;
        }
        let plan = path::PathPlan {
            shape: SMOOTHING_PATH,
            state_scale,
            accuracy,
            budget: budget.saturating_sub(run.iterations),
        };
        let mut outcome = path::follow(&mut smoothed, &mut *linear, x, &plan);
        *counters += outcome.counters;
        outcome.iterations += run.iterations;
        outcome
    }
}

/// The attempts after the full steps: the polyalgorithm, the problem, its linear solver,
/// the iterate and the initial guess, the run's counters and histories, the rules of the
/// full steps (whether they stop when they stagnate), the run's tolerance and state scale,
/// and the attempts so far with the iterations they used, the best iterate and the last
/// termination and strategy.
struct Attempts<'a, J, P: ?Sized, S: ?Sized> {
    solver: &'a mut Polyalgorithm<J>,
    problem: &'a mut P,
    linear: &'a mut S,
    x: &'a mut [f64],
    start: &'a [f64],
    counters: &'a mut WorkCounters,
    log: &'a mut Log,
    base: KernelRules,
    stagnates: bool,
    tolerance: f64,
    scale: f64,
    attempts: Vec<Attempt>,
    used: usize,
    best: Best,
    last: Termination,
    strategy: Strategy,
}

impl<J, P, S> Attempts<'_, J, P, S>
where
    P: GeneralizedJacobian<Jacobian = J> + ?Sized,
    S: Factorize<J> + ?Sized,
{
    /// The iterations left of the run's budget.
    fn left(&self) -> usize {
        self.solver.options.max_iterations.saturating_sub(self.used)
    }

    /// Full steps on F from the end of a path (`reached` when it reached its end) within
    /// what is left of the budget.
    ///
    /// The end of a path is near a root: usually a few steps, sometimes a slow creep that
    /// still converges. From a path that stopped short they stop when they stagnate, as the
    /// first ones do, leaving the budget to the next attempt.
    fn finish_path(&mut self, reached: bool) -> (Termination, Run<PlainFailure>) {
        let rules = KernelRules {
            // What is left of the budget (none left: the end of the path is only
            // checked against the tolerance).
            max_iterations: self.left().min(self.solver.options.full_steps.max(1)),
            stagnation: (!reached && self.stagnates).then_some(FINISH_STAGNATION),
            ..self.base
        };
        self.phase(&rules)
    }

    /// A phase of the kernel from the iterate with `rules`.
    fn phase(&mut self, rules: &KernelRules) -> (Termination, Run<PlainFailure>) {
        let (problem, linear, x) = (&mut *self.problem, &mut *self.linear, &mut *self.x);
        self.solver
            .work
            .phase(problem, linear, x, rules, self.counters, self.log)
    }

    /// Attempt 2, the smoothing path, when the problem offers a smoothing; a path that
    /// stops after `SMOOTHING_PARTIAL` decades still hands its last point to Newton on `F`.
    /// When it fails, it is followed once more with the points' tolerance shrinking with
    /// `mu` (`SmoothingPath::with_tolerance_decay`). The outcome when it ends the run.
    fn smoothing(&mut self, smoothing: Option<SmoothingOf<P>>) -> Option<Outcome> {
        let (ops, mu0) = smoothing
            .map(|ops| (ops, SMOOTHING_START * (ops.scale)(self.problem)))
            .filter(|(_, mu)| mu.is_finite() && *mu > 0.0)?;
        for tolerance_rate in [0.0, TIGHTENED_TOLERANCE_RATE] {
            let budget = self.left();
            if budget == 0 {
                break;
            }
            self.x.copy_from_slice(self.start);
            let setup = SmoothingSetup {
                ops,
                mu0,
                state_scale: self.scale,
                tolerance: self.tolerance,
                budget,
                line_search: self.solver.options.line_search,
                tolerance_rate,
            };
            let outcome = self.solver.smoothing_path(
                self.problem,
                self.linear,
                self.x,
                &setup,
                self.counters,
            );
            self.used += outcome.iterations;
            self.strategy = Strategy::Smoothing;
            if outcome.reached || outcome.furthest >= SMOOTHING_PARTIAL {
                let (termination, run) = self.finish_path(outcome.reached);
                self.used += run.iterations;
                let iterations = outcome.iterations + run.iterations;
                let settled =
                    self.settle(Strategy::Smoothing, iterations, termination, run.smallest);
                if settled.is_some() {
                    return settled;
                }
            } else if let Some(ended) = self.failed(Strategy::Smoothing, outcome) {
                return Some(ended);
            }
        }
        None
    }

    /// Attempt 3, the non-monotone line search from the initial guess, on at most half of
    /// what is left (it ends early when backtracking fails at a kink of the merit). The
    /// outcome when it ends the run.
    fn line_search(&mut self) -> Option<Outcome> {
        let budget = self.left() / 2;
        if budget == 0 {
            return None;
        }
        self.x.copy_from_slice(self.start);
        let options = &self.solver.options;
        let rules = KernelRules {
            step: StepRule::Backtracking {
                memory: options.memory,
                line_search: options.line_search,
            },
            max_iterations: budget,
            ..self.base
        };
        let (termination, run) = self.phase(&rules);
        self.used += run.iterations;
        let settled = self.settle(
            Strategy::LineSearch,
            run.iterations,
            termination,
            run.smallest,
        );
        if settled.is_none() {
            self.strategy = Strategy::LineSearch;
        }
        settled
    }

    /// Attempt 4, the Newton homotopy from the initial guess to t = 1. The outcome when it
    /// ends the run.
    fn homotopy(&mut self) -> Option<Outcome> {
        let budget = self.left();
        if budget == 0 {
            return None;
        }
        let start = self.start;
        let mut f0 = vec![0.0; start.len()];
        self.counters.residual_evaluations += 1;
        let evaluated = self.problem.residual(start, &mut f0);
        if let Err(error) = evaluated.as_ref() {
            if error.ends_run() {
                let termination = Termination::Evaluation(error.clone());
                return Some(self.end(termination, self.strategy));
            }
        }
        if evaluated.is_err() || !f0.iter().all(|v| v.is_finite()) {
            return None;
        }
        self.x.copy_from_slice(start);
        let plan = path::PathPlan {
            shape: NEWTON_HOMOTOPY,
            state_scale: self.scale,
            accuracy: self.tolerance.max(path::PATH_ACCURACY * norm2(&f0)),
            budget,
        };
        let mut homotopy = path::NewtonHomotopy::new(&mut *self.problem, &f0);
        let outcome = path::follow(&mut homotopy, &mut *self.linear, self.x, &plan);
        *self.counters += outcome.counters;
        self.used += outcome.iterations;
        self.strategy = Strategy::Homotopy;
        if !outcome.reached {
            return self.failed(Strategy::Homotopy, outcome);
        }
        let (termination, run) = self.finish_path(true);
        let iterations = outcome.iterations + run.iterations;
        self.settle(Strategy::Homotopy, iterations, termination, run.smallest)
    }

    /// The outcome of the attempts so far ended by `termination` of `strategy`.
    fn end(&mut self, termination: Termination, strategy: Strategy) -> Outcome {
        let attempts = std::mem::take(&mut self.attempts);
        ended(termination, strategy, attempts, self.tolerance)
    }

    /// Records the attempt `strategy` of `iterations` that ended in `termination` at the
    /// iterate (smallest residual norm `smallest`): the outcome when it ends the run, else
    /// `None` with the best iterate updated.
    fn settle(
        &mut self,
        strategy: Strategy,
        iterations: usize,
        termination: Termination,
        smallest: f64,
    ) -> Option<Outcome> {
        self.attempts
            .push(Attempt::new(strategy, iterations, &termination));
        if termination.converged() || ends_run(&termination) {
            return Some(self.end(termination, strategy));
        }
        self.best
            .update(self.x, self.solver.work.kernel.residual(), smallest);
        self.last = termination;
        None
    }

    /// Records the path of `strategy` that stopped short: the outcome when the problem's
    /// own error ended it.
    fn failed(&mut self, strategy: Strategy, outcome: path::PathOutcome) -> Option<Outcome> {
        self.attempts.push(failed_path(strategy, &outcome));
        let error = outcome.error?;
        Some(self.end(Termination::Evaluation(error), strategy))
    }

    /// The outcome when no attempt converged: the best iterate of all, with the last
    /// attempt's termination.
    fn best_outcome(self) -> Outcome {
        if self.best.restore(self.x) {
            self.solver.work.kernel.set_residual(&self.best.f);
        }
        ended(self.last, self.strategy, self.attempts, self.tolerance)
    }
}

/// The outcome of the attempts.
fn ended(
    termination: Termination,
    strategy: Strategy,
    attempts: Vec<Attempt>,
    tolerance: f64,
) -> Outcome {
    Outcome {
        termination,
        strategy,
        attempts,
        tolerance,
    }
}

/// The attempt of a path that stopped short of its end.
fn failed_path(strategy: Strategy, path: &path::PathOutcome) -> Attempt {
    Attempt {
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

/// The Newton homotopy of attempt 4, from `t = 0` to `t = 1`.
const NEWTON_HOMOTOPY: PathShape = PathShape {
    end: 1.0,
    // Ten steps over an affine path; small enough that a corner of the path (a contact
    // closing) is approached before it is overshot.
    steps: 10.0,
    growth: 1.0,
    // The state dominates the arclength: at a corner where t turns back while the state
    // moves on (a contact closing inside an overhang), the arclength hyperplane still cuts
    // the far piece.
    theta: 0.99,
    target_iterations: 5,
    predictor: Predictor::Secant,
};

/// The smoothing path of attempt 2, over [`SMOOTHING_DECADES`] decades of `mu`: a smooth
/// path, followed along its tangent (the corrector's factorization gives it free); steps of
/// one decade at first, at most two; state and parameter weigh alike. Measured on the public
/// grid: the tangent predictor and the cap of two decades save a fifth of the corrector
/// iterations against the secant and a cap of four (fewer rejected steps where contacts
/// form).
const SMOOTHING_PATH: PathShape = PathShape {
    end: SMOOTHING_DECADES,
    steps: SMOOTHING_DECADES,
    growth: 2.0,
    theta: 0.5,
    target_iterations: 3,
    predictor: Predictor::Tangent,
};

/// What the smoothing path starts from: the problem's smoothing, `mu0`, the state scale of
/// the path, the run's tolerance, the iterations left and the line search of the smoothed
/// start.
struct SmoothingSetup<P: ?Sized> {
    ops: SmoothingOf<P>,
    mu0: f64,
    state_scale: f64,
    tolerance: f64,
    budget: usize,
    line_search: LineSearchOptions,
    /// [`path::SmoothingPath::with_tolerance_decay`]'s rate.
    tolerance_rate: f64,
}

/// The smoothing path starts at `mu = SMOOTHING_START x` the problem's smoothing scale
/// (smaller starts leave the smoothed problem as hard as the problem itself; larger ones
/// lengthen the path).
const SMOOTHING_START: f64 = 1.0;
/// Decades of `mu` the smoothing path descends before Newton on `F` takes over.
const SMOOTHING_DECADES: f64 = 3.0;
/// The second smoothing path corrects its points at `mu` to `SMOOTHING_ACCURACY (mu /
/// mu_0)^rate` relative: the neighbourhood `|F_mu| <= beta mu` of smoothing Newton methods,
/// where the Newton basin of `F_mu` (which shrinks like `mu`) is not left late on the path.
/// Not the first path's: measured on the public grid it costs corrector iterations
/// (worst 60 -> 67 at rate 0.5, 70 at rate 1), while with one tolerance the 40-element
/// rod at `H = 160` stalls at `mu = 10^-2.25 mu_0` (a restart there diverges at fixed `mu`).
const TIGHTENED_TOLERANCE_RATE: f64 = 1.0;
/// Decades of `mu` after which a path that stops short hands over to Newton on `F` anyway.
const SMOOTHING_PARTIAL: f64 = 2.0;
/// Accuracy of the smoothing path's points relative to `|F_mu0|` at the start: the end of
/// the path must lie in the basin of semismooth Newton on `F` (1e-2 measured too loose).
const SMOOTHING_ACCURACY: f64 = 1e-3;
/// Newton iterations at most on the smoothed problem at the path's start.
const SMOOTHING_START_ITERATIONS: usize = 30;
/// The full-step phase stops when, after 8 steps, the last 6 did not bring `|F|` ten times
/// below the smallest before them (measured on the public grid: every full-step run that
/// converged later had made that progress, or crept one contact switch per step).
const FULL_STEP_STAGNATION: Stagnation = Stagnation {
    after: 8,
    window: 6,
    factor: 0.1,
};

/// Full steps from the end of a path that stopped short stop when, after 15 steps, the
/// last 10 did not bring `|F|` ten times below the smallest before them (a looser rule than
/// the first full steps': from such a point they may creep and still converge, measured
/// on `c = 100 x` the default on the canonical rod).
const FINISH_STAGNATION: Stagnation = Stagnation {
    after: 15,
    window: 10,
    factor: 0.1,
};

/// The best iterate over several attempts.
struct Best {
    x: Vec<f64>,
    f: Vec<f64>,
    norm: f64,
    /// Whether the last attempt ended elsewhere.
    moved: bool,
}

impl Best {
    fn new(x: &[f64], f: &[f64], norm: f64) -> Self {
        Self {
            x: x.to_vec(),
            f: f.to_vec(),
            norm,
            moved: false,
        }
    }

    fn update(&mut self, x: &[f64], f: &[f64], norm: f64) {
        if norm < self.norm || self.norm.is_nan() {
            self.x.copy_from_slice(x);
            self.f.copy_from_slice(f);
            self.norm = norm;
            self.moved = false;
        } else {
            self.moved = true;
        }
    }

    /// Writes the best iterate into `x` if the last attempt ended elsewhere.
    fn restore(&self, x: &mut [f64]) -> bool {
        if self.moved {
            x.copy_from_slice(&self.x);
        }
        self.moved
    }
}
