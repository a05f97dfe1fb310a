//! The continuation driver: an iterator over accepted branch points with step control,
//! corner passes, bound landing, the trust ball, restarts and piecewise-affine corners.

mod affine;
mod exit;
mod resume;
mod step;

pub use resume::Resumption;

use std::collections::VecDeque;

use super::corrector::{
    Bordered, Constraint, Corrected, CorrectorCounts, DenseAssembler, Metric, TrustBall,
};
use super::pieces::AffineOps;
use super::{
    BranchPoint, ContinuationCounters, ContinuationError, ContinuationEvent, ContinuationOptions,
    ContinuationTermination, Direction, FoldDetector,
};
use crate::linalg::DenseAssemble;
use crate::newton::WorkCounters;
use crate::{Factorize, GeneralizedJacobian, ParameterDependent, ProblemCounters};

enum Phase {
    NotStarted {
        x0: Vec<f64>,
        p0: f64,
    },
    /// Taken up from another run ([`Continuation::resume`]): the start is corrected on
    /// the hyperplane through `(x0, p0)` normal to `carried` (else at fixed `p0`) and its
    /// tangent oriented along `carried`.
    Resuming {
        x0: Vec<f64>,
        p0: f64,
        carried: Vec<f64>,
    },
    Running,
    /// A restarted segment went back along the branch: the exit-tangent pass is tried at
    /// the corner where the restart began (`corner`, the failed direction `failed`).
    Retraced {
        corner: BranchPoint,
        failed: Vec<f64>,
    },
    Finished,
}

/// The kind of the current segment of the branch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Segment {
    /// The options' metric.
    Main,
    /// A restart after a failed step: the restart policy's metric for `points_left` more
    /// points.
    Restart { points_left: usize },
}

/// The points before a restart, against which the restarted segment is checked for going
/// back along the branch (joined `(x, p)` vectors).
struct Retrace {
    earlier: Vec<Vec<f64>>,
    anchor: Vec<f64>,
}

/// The piecewise-affine capability: the problem's switching functions and the walk state.
struct Pieces<P: ?Sized> {
    ops: AffineOps<P>,
    /// The piece of the last corrected point.
    current: Option<Vec<bool>>,
    /// Which way `p` last moved along the branch (`+1` or `-1`).
    travel: f64,
}

/// A converged correction made a branch point (with the θ-length of its chord from the
/// last point), or the run ended on a bound without a new point.
type Accepted = Option<(BranchPoint, f64)>;

/// What the piece bookkeeping of an accepted point decided.
enum Tracked {
    /// Go on (`Some`: elsewhere than from the point).
    Resume(Option<Resume>),
    /// The run ended while the corners were emitted.
    Ended,
}

/// How the branch goes on after a walk over corners.
enum Resume {
    /// From the walk's entry point on the next piece (a new point).
    Fresh(Vec<f64>, f64, Direction),
    /// From the point just accepted, heading this way.
    Repeat(Direction),
}

/// Pseudo-arclength continuation as an iterator over accepted [`BranchPoint`]s (the module
/// documentation has the method, the options and their defaults).
///
/// The first item is the starting point corrected at fixed `p0` by the continuation's own
/// corrector (Newton, with the line search of
/// [`ContinuationOptions::corrector_line_search`] if set; from a poor guess, solve first
/// with [`crate::newton`]); when it cannot be corrected there is no item and the
/// termination is [`ContinuationTermination::StartFailed`]. When the iteration ends,
/// [`Continuation::termination`] says why,
/// [`Continuation::events`] lists the folds and corners, and the problem's parameter is
/// that of the last accepted point.
pub struct Continuation<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    problem: &'a mut P,
    solver: &'a mut S,
    options: ContinuationOptions,
    fallback: Option<DenseAssembler<P::Jacobian>>,
    /// The metric of the current segment.
    metric: Metric,
    /// The options' metric (trust ball, retrace test, corner walks).
    main_metric: Metric,
    bordered: Bordered<P::Jacobian>,
    work: WorkCounters,
    corrector_counts: CorrectorCounts,
    phase: Phase,
    /// Last point emitted (or the corrected start of a segment that repeats it).
    last: Option<BranchPoint>,
    /// Unit tangent at the last accepted point (length n + 1).
    tangent: Vec<f64>,
    /// Unit predictor direction for the next step (length n + 1).
    direction: Vec<f64>,
    step: f64,
    points: usize,
    consecutive_failures: usize,
    folds: FoldDetector,
    events: Vec<ContinuationEvent>,
    termination: Option<ContinuationTermination>,
    counters: ContinuationCounters,
    problem_start: ProblemCounters,
    /// The solver's Krylov iterations when the run started.
    krylov_start: u64,
    trust: TrustBall,
    segment: Segment,
    segment_direction: Direction,
    /// Points emitted since the current segment began.
    segment_points: usize,
    /// Joined states of the last emitted points (for the retrace test).
    recent: VecDeque<Vec<f64>>,
    retrace: Option<Retrace>,
    /// With `exit_tangents`: the point where the steps of the main segment last failed for
    /// good and a restart began, with the failed direction (the last resort of a retrace).
    exit_corner: Option<(BranchPoint, Vec<f64>)>,
    /// Parameter component of the tangent at the last corrected (not corner) point.
    last_tangent_parameter: f64,
    pending: VecDeque<BranchPoint>,
    pieces: Option<Pieces<P>>,
    /// The next emitted point replaces the last point of the run taken up (it is already
    /// in the fold detector).
    replacing: bool,
}

impl<'a, P, S> Continuation<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
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
        let main_metric = Metric::new(
            n,
            options.theta,
            options.state_scale.as_deref(),
            options.parameter_scale,
        );
        let bordered = Bordered::new(n, problem.new_jacobian());
        let problem_start = problem.problem_counters();
        let krylov_start = solver.krylov_iterations();
        let folds = FoldDetector::new(options.refine_folds)
            .with_min_excursion(options.fold_parameter_excursion());
        let window = options.restarts.map_or(0, |r| r.retrace_window);
        Ok(Self {
            problem,
            solver,
            step: options.initial_step,
            segment_direction: options.direction,
            options,
            fallback: None,
            metric: main_metric.clone(),
            main_metric,
            bordered,
            work: WorkCounters::default(),
            corrector_counts: CorrectorCounts::default(),
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
            problem_start,
            krylov_start,
            trust: TrustBall::default(),
            segment: Segment::Main,
            segment_points: 0,
            recent: VecDeque::with_capacity(window + 1),
            retrace: None,
            exit_corner: None,
            last_tangent_parameter: 0.0,
            pending: VecDeque::new(),
            pieces: None,
            replacing: false,
        })
    }

    /// Why the run stopped (`None` while it runs).
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
        c.work = self.work;
        c.work.problem = self.problem.problem_counters().since(&self.problem_start);
        c.work.krylov_iterations = self.solver.krylov_iterations() - self.krylov_start;
        c.parameter_derivative_evaluations = self.corrector_counts.parameter_derivatives;
        c.dense_bordered_factorizations = self.corrector_counts.dense_factorizations;
        c.corrector_iterations = self.corrector_counts.iterations;
        c
    }

    /// The problem (its parameter is that of the last accepted point between items), e.g.
    /// to evaluate user quantities at the point just returned.
    pub fn problem(&self) -> &P {
        self.problem
    }

    /// Runs to the end and collects the branch.
    pub fn run(mut self) -> super::Branch {
        let points: Vec<BranchPoint> = self.by_ref().collect();
        let termination = self
            .termination
            .clone()
            .unwrap_or(ContinuationTermination::MaxPoints {
                points: points.len(),
            });
        super::Branch {
            points,
            events: std::mem::take(&mut self.events),
            termination,
            counters: self.counters(),
        }
    }

    pub(super) fn finished(&self) -> bool {
        matches!(self.phase, Phase::Finished)
    }

    /// Corrector iterations left of [`ContinuationOptions::max_total_corrector_iterations`]
    /// (`None`: no limit).
    pub(super) fn iterations_left(&self) -> Option<usize> {
        self.options
            .max_total_corrector_iterations
            .map(|budget| budget.saturating_sub(self.corrector_counts.iterations as usize))
    }

    /// Ends the run when its corrector iterations are spent (the last accepted point at
    /// `parameter`); `true` when it did.
    fn stop_if_budget_spent(&mut self, parameter: f64) -> bool {
        let spent = self.iterations_left() == Some(0);
        if let Some(budget) = self
            .options
            .max_total_corrector_iterations
            .filter(|_| spent)
        {
            self.finish(ContinuationTermination::IterationBudgetSpent { parameter, budget });
        }
        spent
    }

    pub(super) fn finish(&mut self, termination: ContinuationTermination) {
        if !self.finished() {
            self.termination = Some(termination);
            self.phase = Phase::Finished;
        }
    }

    /// The run's first point: `(x0, p0)` corrected at fixed `p0`, the tangent oriented by
    /// the options' direction, or for a resumed run corrected and oriented along `carried`.
    fn start(&mut self, x0: Vec<f64>, p0: f64, carried: Option<&[f64]>) {
        let mut x = x0;
        let mut p = p0;
        let orientation = (carried, self.options.direction);
        let corrected = match self.correct_start(&mut x, &mut p, orientation) {
            Ok(c) => c,
            Err(failure) => {
                self.problem.set_parameter(p0);
                self.finish(ContinuationTermination::StartFailed {
                    parameter: p0,
                    failure,
                });
                return;
            }
        };
        self.phase = Phase::Running;
        let point = self.start_point(x, p, corrected);
        self.after_accept(point, 0.0);
    }

    /// Begins a new segment of the branch at `(x, p)`: a correction at fixed `p`, the
    /// tangent oriented by `direction`, the initial step, `segment`'s metric. The corrected
    /// point is a new branch point when `emit`, else it replaces the last point (a
    /// repeat).
    fn begin_segment(
        &mut self,
        mut x: Vec<f64>,
        mut p: f64,
        direction: Direction,
        segment: Segment,
        emit: bool,
    ) {
        self.metric.theta = match (segment, self.options.restarts) {
            (Segment::Restart { .. }, Some(policy)) => policy.theta,
            _ => self.options.theta,
        };
        self.retrace = match segment {
            Segment::Restart { .. } if self.recent.len() >= 2 => {
                let mut earlier: Vec<Vec<f64>> = self.recent.iter().cloned().collect();
                let anchor = earlier.pop().unwrap_or_default();
                Some(Retrace { earlier, anchor })
            }
            _ => None,
        };
        self.segment = segment;
        self.segment_direction = direction;
        self.segment_points = 0;
        self.set_trust(&x, p, 0.0);
        let parameter = self.last.as_ref().map_or(p, |l| l.parameter);
        if self.stop_if_budget_spent(parameter) {
            return;
        }
        let corrected = match self.correct_start(&mut x, &mut p, (None, direction)) {
            Ok(c) => c,
            Err(failure) => {
                let parameter = self.last.as_ref().map_or(p, |l| l.parameter);
                self.problem.set_parameter(parameter);
                self.finish(ContinuationTermination::SegmentStartFailed {
                    parameter: p,
                    failure,
                });
                return;
            }
        };
        self.step = self.options.initial_step;
        self.consecutive_failures = 0;
        let point = self.start_point(x, p, corrected);
        if emit {
            self.emit(point, 0.0);
        } else {
            self.last = Some(point);
        }
    }

    /// The point of a segment's start corrected at fixed `p` (with the tangent just taken).
    fn start_point(&self, state: Vec<f64>, parameter: f64, corrected: Corrected) -> BranchPoint {
        BranchPoint {
            state,
            parameter,
            iterations: corrected.iterations,
            residual_norm: corrected.residual_norm,
            step: 0.0,
            tangent_parameter: self.tangent[self.metric.n],
            corner: false,
        }
    }

    /// The trust ball around `(x, p)` for the next attempts: radius `trust_factor` times
    /// the largest step they can take (twice the last step, at most `max_step`).
    fn set_trust(&mut self, x: &[f64], p: f64, step: f64) {
        let Some(factor) = self.options.trust_factor else {
            return;
        };
        self.trust.center.clear();
        self.trust.center.extend_from_slice(x);
        self.trust.center.push(p);
        let next = if step > 0.0 {
            (2.0 * step).min(self.options.max_step)
        } else {
            self.options.max_step
        };
        self.trust.radius = factor * next;
    }

    /// Makes `point` a branch point: the retrace test of a restarted segment, fold and
    /// corner events, the counters. Returns `false` when the point goes back along the
    /// branch (the run then ends without it).
    fn emit(&mut self, point: BranchPoint, chord: f64) -> bool {
        let joined = self.joined(&point.state, point.parameter);
        if let Some(retrace) = &self.retrace {
            let d = |a: &[f64], b: &[f64]| self.main_metric.distance(a, b);
            let back = retrace
                .earlier
                .iter()
                .any(|e| d(&joined, e) < 0.25 * d(e, &retrace.anchor));
            if back {
                // The point is dropped and the run ends here, whatever ended it before.
                let parameter = retrace.anchor[self.metric.n];
                self.termination = Some(ContinuationTermination::Retraced { parameter });
                self.phase = match self.exit_corner.take() {
                    Some((corner, failed)) => Phase::Retraced { corner, failed },
                    None => Phase::Finished,
                };
                return false;
            }
        }
        let index = self.points;
        if point.corner {
            let events = self.folds.push(point.parameter, 0.0, 0.0);
            self.events.extend(events);
            self.events.push(ContinuationEvent::Corner {
                index,
                parameter: point.parameter,
            });
            self.counters.corners += 1;
        } else {
            if std::mem::take(&mut self.replacing) {
                self.folds
                    .replace_last(point.parameter, point.tangent_parameter);
            } else {
                let events = self
                    .folds
                    .push(point.parameter, point.tangent_parameter, chord);
                self.events.extend(events);
            }
            self.last_tangent_parameter = point.tangent_parameter;
            self.set_trust(&point.state, point.parameter, point.step);
        }
        let window = self.options.restarts.map_or(0, |r| r.retrace_window);
        if window > 0 {
            if self.recent.len() > window {
                self.recent.pop_front();
            }
            self.recent.push_back(joined);
        }
        self.points += 1;
        self.segment_points += 1;
        self.last = Some(point.clone());
        self.pending.push_back(point);
        if self.points >= self.options.max_points {
            self.finish(ContinuationTermination::MaxPoints {
                points: self.points,
            });
        }
        true
    }

    fn joined(&self, x: &[f64], p: f64) -> Vec<f64> {
        let mut y = Vec::with_capacity(x.len() + 1);
        y.extend_from_slice(x);
        y.push(p);
        y
    }

    /// After a point was accepted: the piece bookkeeping of a piecewise-affine branch
    /// (which may cross corners and resume elsewhere), then the point itself, then the end
    /// of a restarted segment.
    fn after_accept(&mut self, point: BranchPoint, chord: f64) {
        let resume = if self.pieces.is_some() && !self.finished() {
            match self.track_pieces(&point) {
                Tracked::Resume(resume) => resume,
                Tracked::Ended => return,
            }
        } else {
            None
        };
        match resume {
            Some(Resume::Fresh(x, p, direction)) => {
                self.begin_segment(x, p, direction, Segment::Main, true);
                return;
            }
            Some(Resume::Repeat(direction)) => {
                let (x, p) = (point.state.clone(), point.parameter);
                if self.emit(point, chord) && !self.finished() {
                    self.begin_segment(x, p, direction, Segment::Main, false);
                }
                return;
            }
            None => {
                if !self.emit(point, chord) {
                    return;
                }
            }
        }
        if let Segment::Restart { points_left } = self.segment {
            let left = points_left.saturating_sub(1);
            self.segment = Segment::Restart { points_left: left };
            if left == 0 && !self.finished() {
                let direction = self.heading();
                if let Some(last) = self.last.clone() {
                    self.begin_segment(last.state, last.parameter, direction, Segment::Main, false);
                }
            }
        }
    }

    /// The direction the branch last moved in `p` (the last increment between points, or
    /// the last tangent).
    fn heading(&self) -> Direction {
        let k = self.recent.len();
        let n = self.metric.n;
        let heading = if k >= 2 {
            self.recent[k - 1][n] - self.recent[k - 2][n]
        } else {
            self.last_tangent_parameter
        };
        if heading >= 0.0 {
            Direction::Increasing
        } else {
            Direction::Decreasing
        }
    }

    /// Attempts steps until one is accepted or the run ends; accepted points (and corners)
    /// go to `pending`.
    fn advance(&mut self) {
        let n = self.metric.n;
        let Some(last) = self.last.clone() else {
            self.finish(ContinuationTermination::MaxPoints { points: 0 });
            return;
        };
        let mut x = vec![0.0; n];
        loop {
            if self.stop_if_budget_spent(last.parameter) {
                return;
            }
            let ds = self.step;
            for ((xi, si), di) in x.iter_mut().zip(&last.state).zip(&self.direction) {
                *xi = si + ds * di;
            }
            self.direction_weights();
            let mut p = last.parameter + ds * self.direction[n];
            let constraint = self.arclength_constraint(&last, self.direction[n], ds);
            let before = self.corrector_counts.iterations;
            let (corrected, smallest) = self.correct_at(&mut x, &mut p, constraint);
            let failure = match corrected {
                Ok(c) => {
                    if let Some((point, chord)) = self.accept(&last, x, p, ds, c, None) {
                        self.after_accept(point, chord);
                    }
                    return;
                }
                Err(failure) => failure,
            };
            self.reject(before, last.parameter);
            if self.finished() {
                return;
            }
            self.consecutive_failures += 1;
            let too_small = ds <= self.options.min_step;
            let too_many = self.consecutive_failures >= self.options.max_consecutive_failures;
            if !(too_small || too_many) {
                self.step = (0.5 * ds).max(self.options.min_step);
                continue;
            }
            if self.options.pass_corners {
                if let Some(accepted) = self.pass_corner(&last, ds) {
                    if let Some((point, chord)) = accepted {
                        self.after_accept(point, chord);
                    }
                    return;
                }
                if self.finished() {
                    return;
                }
            }
            let termination = if too_small {
                ContinuationTermination::StepTooSmall {
                    parameter: last.parameter,
                    step: ds,
                    residual_norm: smallest,
                    failure,
                }
            } else {
                ContinuationTermination::TooManyFailures {
                    parameter: last.parameter,
                    step: ds,
                    failures: self.consecutive_failures,
                    residual_norm: smallest,
                    failure,
                }
            };
            self.recover(last, termination);
            return;
        }
    }

    /// After the steps from `last` failed for good: a walk over the corners ahead (a
    /// piecewise-affine branch), else a restart (the restart policy), else the end.
    fn recover(&mut self, last: BranchPoint, termination: ContinuationTermination) {
        if self.stop_if_budget_spent(last.parameter) {
            return;
        }
        if self.pieces.is_some() {
            let remaining = self.options.max_points.saturating_sub(self.points);
            let travel = self.pieces.as_ref().map_or(1.0, |p| p.travel);
            let walk = self
                .walker()
                .and_then(|mut w| w.cross(&last.state, last.parameter, travel, remaining));
            self.problem.set_parameter(last.parameter);
            if let Some(walk) = walk {
                if !self.emit_corners(walk.corners) {
                    return;
                }
                let label = self.walker().and_then(|mut w| {
                    w.problem.set_parameter(walk.start_parameter);
                    w.piece(&walk.start)
                });
                if let Some(pieces) = self.pieces.as_mut() {
                    pieces.current = label;
                    pieces.travel = walk.direction.sign();
                }
                self.begin_segment(
                    walk.start,
                    walk.start_parameter,
                    walk.direction,
                    Segment::Main,
                    true,
                );
                return;
            }
        }
        if let Some(policy) = self.options.restarts {
            let stuck = matches!(self.segment, Segment::Restart { .. }) && self.segment_points == 0;
            if self.counters.restarts < policy.max_restarts as u64
                && self.last_tangent_parameter != 0.0
            {
                self.counters.restarts += 1;
                // A piecewise-affine branch crosses its corners exactly instead (above).
                let exit = self.options.exit_tangents && self.pieces.is_none();
                if exit && matches!(self.segment, Segment::Main) {
                    self.exit_corner = Some((last.clone(), self.direction.clone()));
                }
                let direction = match (stuck, self.segment_direction) {
                    (true, Direction::Increasing) => Direction::Decreasing,
                    (true, Direction::Decreasing) => Direction::Increasing,
                    _ => self.heading(),
                };
                if let Some(pieces) = self.pieces.as_mut() {
                    pieces.travel = direction.sign();
                }
                self.begin_segment(
                    last.state,
                    last.parameter,
                    direction,
                    Segment::Restart {
                        points_left: policy.points,
                    },
                    false,
                );
                return;
            }
        }
        self.finish(termination);
    }

    /// `w_x = (θ/n) s⁻² ⊙ d_x`: the state part of the normal of the arclength constraint
    /// along the current direction `d` (`s` the state scale, 1 without one).
    fn direction_weights(&mut self) {
        let n = self.metric.n;
        self.metric
            .state_normal(&self.direction[..n], &mut self.bordered.w);
    }

    /// The arclength constraint of a step `ds` from `last` along the direction whose
    /// parameter component is `d_p`, with the state normal already in `bordered.w`:
    /// `w · (x - x_last) + w_p (p - p_last) = ds`.
    fn arclength_constraint(&self, last: &BranchPoint, d_p: f64, ds: f64) -> Constraint {
        let w_p = self.metric.parameter_dot(d_p, 1.0);
        let w_dot_last: f64 = (self.bordered.w.iter().zip(&last.state))
            .map(|(w, x)| w * x)
            .sum::<f64>()
            + w_p * last.parameter;
        Constraint {
            arclength: true,
            w_p,
            target: w_dot_last + ds,
        }
    }

    /// Books a rejected attempt (begun at `before` corrector iterations) and restores the
    /// problem's parameter to the last accepted point's.
    fn reject(&mut self, before: u64, parameter: f64) {
        self.counters.rejected_steps += 1;
        self.counters.rejected_iterations += self.corrector_counts.iterations - before;
        self.problem.set_parameter(parameter);
    }
}

impl<'a, P, S> Continuation<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    P::Jacobian: DenseAssemble,
    S: Factorize<P::Jacobian> + ?Sized,
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
    S: Factorize<P::Jacobian> + ?Sized,
{
    type Item = BranchPoint;

    fn next(&mut self) -> Option<Self::Item> {
        loop {
            if let Some(point) = self.pending.pop_front() {
                return Some(point);
            }
            match std::mem::replace(&mut self.phase, Phase::Running) {
                Phase::Finished => {
                    self.phase = Phase::Finished;
                    // The reversals the branch ended on are zigzags (idempotent).
                    let undecided = self.folds.finish();
                    self.events.extend(undecided);
                    return None;
                }
                Phase::NotStarted { x0, p0 } => self.start(x0, p0, None),
                Phase::Resuming { x0, p0, carried } => self.start(x0, p0, Some(&carried)),
                Phase::Running => self.advance(),
                Phase::Retraced { corner, failed } => self.exit_after_retrace(corner, failed),
            }
        }
    }
}

impl<P, S> std::iter::FusedIterator for Continuation<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
}
