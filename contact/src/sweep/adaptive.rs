//! Harmonics chosen point by point along an SSN-HB branch to meet an accuracy target
//! ([`SolverSettings::accuracy`]): more where contact is strong, fewer in the linear tails.
//!
//! # The estimate of a point
//!
//! Each point of the branch, solved with `H` harmonics, is taken up at `H/2` (its
//! truncated coefficients corrected on the hyperplane through the point normal to the
//! branch's direction there, [`Continuation::resume`]; at the point's frequency by
//! globalized Newton when that fails), and the distance `d` between the two
//! ([`point_distance`]: the change of the observed dof's extremes relative to its largest
//! excursion, or of the frequency, whichever is larger) gives Richardson's estimate of the
//! error at `H`, `e = d / (2^p - 1)` with the harmonic-balance order `p` = [`HB_ORDER`]
//! (module [`crate::solve::accuracy`]; `e = 1.47 d`). Across the branch rather than at a
//! fixed frequency, the distance stays defined near a fold, where the two
//! discretisations' branches turn at different frequencies. Validated against the branch
//! at `H = 320` taken up the same way at every point of the paper's rod
//! (`ssn/examples/adaptive_sweep.rs`, docs/sweeps.md).
//!
//! # The harmonics of the next points
//!
//! The harmonics are taken from [`HARMONICS_LADDER`] (8 to 1024, ratios 1.5 and 4/3, so that a
//! change is worth a new problem). With the error model `e(H) ~ H^-p` the harmonics that
//! meet the target are `H* = H (e SAFETY / target)^(1/p)` ([`SAFETY`]):
//!
//! - `e > target`: the point is solved again at the first rung at or above `H*` (the
//!   branch taken up there from the point, see below) and estimated again; it is reported
//!   only once its estimate meets the target or the ladder's top is reached;
//! - `e <= LOWER_BELOW target` ([`LOWER_BELOW`]): the point is kept and the branch goes
//!   on at the first rung at or above `H*`, the hysteresis between both rules keeping
//!   the harmonics from flickering;
//! - otherwise the branch goes on at `H`.
//!
//! # Changing the harmonics on the way
//!
//! The core continuation knows nothing of harmonics: at a change, the sweep takes the
//! run's [`Resumption`] (last point, predictor direction, step, fold detector), lifts or
//! truncates the state and the direction's state part to the new harmonics
//! ([`resize_harmonics`]; the step scaling of the sweep makes the θ-norm independent of
//! `H`), and [`Continuation::resume`]s with the problem at the new harmonics, which
//! corrects the point across the branch (so a point near a fold is not carried to
//! another solution at its frequency). Folds and zigzags are thus detected across the
//! changes. A resumed start that the corrector's full steps cannot take up is solved
//! once by globalized Newton at its frequency and taken up from there; failing that,
//! the branch goes on at the old harmonics from that point.
//!
//! The branch starts at [`HARMONICS_LADDER`]`[0]` harmonics (the scene's `harmonics` is
//! ignored with a target), each point's harmonics and estimate are in
//! [`ResponsePoint::harmonics`] and [`ResponsePoint::error_estimate`].

use std::time::Instant;

use semismooth::continuation::{
    BranchPoint, Continuation, ContinuationCounters, ContinuationEvent, ContinuationOptions,
    ContinuationTermination, FoldDetector, Resumption,
};
use semismooth::polyalgorithm::SmoothingOf;
use semismooth::{Factorize, ParameterDependent, Residual};

use super::response::HbTip;
use super::{
    check_sweep, continuation_error, continuation_options, hb_solver, reference_amplitude,
    set_events, ssn_continuation, sweep_termination, FrequencyResponse, ResponsePoint,
    SweepTermination,
};
use crate::hb::{resize_harmonics, HbJacobian, SsnHb};
use crate::model::{StructuralModel, Structure};
use crate::settings::{default_hb_time_samples, SolverSettings, SweepSettings};
use crate::solve::accuracy::search::{
    check_target, MAX_RATIO, MAX_SEARCH_HARMONICS, MAX_SEARCH_UNKNOWNS, SAFETY,
};
use crate::solve::accuracy::HB_ORDER;
use crate::solve::{
    displacement_floor, hb_options, newton_options, RunCounters, RunError, HB_OUTPUT_POINTS,
};

/// The harmonics a branch may use, in increasing order. It starts at 8: at 4 the pair
/// with 2 harmonics is no Richardson pair (on the paper's rod inside the overhang a point
/// at 4 harmonics estimated at 2.6e-3 was 5.8e-2 off).
pub const HARMONICS_LADDER: [usize; 15] = [
    8, 12, 16, 24, 32, 48, 64, 96, 128, 192, 256, 384, 512, 768, 1024,
];

/// A point whose estimate is at most this fraction of the target lets the branch go on
/// with fewer harmonics (module documentation).
pub const LOWER_BELOW: f64 = 0.25;

/// What the harmonics chosen point by point achieved along a branch.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct BranchAccuracy {
    /// The relative accuracy asked of each point's observed displacement.
    pub target: f64,
    /// Points solved again with more harmonics.
    pub raises: usize,
    /// Changes to fewer harmonics.
    pub lowers: usize,
    /// Resumed starts that could not be corrected (the point kept its harmonics).
    pub failed_raises: usize,
    /// The largest harmonics the ladder allows for this model.
    pub max_harmonics: usize,
    /// Wall time of the estimates (the solves at `H/2`).
    pub estimate_seconds: f64,
    /// Work of the estimates.
    pub estimate_counters: RunCounters,
}

impl BranchAccuracy {
    /// The points of `points` whose estimate meets the target.
    pub fn met(&self, points: &[ResponsePoint]) -> usize {
        points
            .iter()
            .filter(|p| p.error_estimate.is_some_and(|e| e <= self.target))
            .count()
    }

    /// Nothing achieved yet towards `target` with at most `max_harmonics` harmonics.
    fn none_yet(target: f64, max_harmonics: usize) -> Self {
        Self {
            target,
            raises: 0,
            lowers: 0,
            failed_raises: 0,
            max_harmonics,
            estimate_seconds: 0.0,
            estimate_counters: RunCounters::default(),
        }
    }
}

/// `settings` with `h` harmonics and their default AFT samples.
pub fn at_harmonics(settings: &SolverSettings, h: usize) -> SolverSettings {
    SolverSettings {
        harmonics: h,
        time_samples: default_hb_time_samples(h),
        accuracy: None,
        estimate_error: false,
        ..settings.clone()
    }
}

/// Reconstruction points of the observed dof at `h` harmonics.
fn output_points(h: usize) -> usize {
    HB_OUTPUT_POINTS.max(default_hb_time_samples(h))
}

/// The first rung at or above `wanted`, at most `limit`.
fn rung(wanted: f64, limit: usize) -> usize {
    HARMONICS_LADDER
        .iter()
        .copied()
        .filter(|&h| h <= limit)
        .find(|&h| h as f64 >= wanted)
        .unwrap_or(limit)
}

/// `H* = h (e SAFETY / target)^(1/p)`.
fn wanted_harmonics(h: usize, estimate: f64, target: f64) -> f64 {
    h as f64 * (estimate * SAFETY / target).powf(1.0 / HB_ORDER)
}

/// A problem of the estimates: its harmonics, the problem, the observed dof's
/// reconstruction and the linear solver.
type HalfProblem = (usize, SsnHb, HbTip, Box<dyn Factorize<HbJacobian>>);

/// The solves at `H/2` that estimate the points' errors, with one problem per harmonics.
struct Estimator<'a> {
    rod: &'a Structure,
    settings: &'a SolverSettings,
    sweep: &'a SweepSettings,
    u_ref: f64,
    problems: Vec<HalfProblem>,
    seconds: f64,
    counters: RunCounters,
}

/// The relative distance of a branch point `(max, min, ω)` (the observed dof's extremes
/// and the frequency) from another solution of the same branch `reference`: the larger of
/// the extremes' change over the reference's largest excursion and the frequency's change
/// over its frequency. Measured between points of one hyperplane across the branch, it is
/// the distance between two discretisations' branches, defined at a fold as elsewhere.
pub fn point_distance((max, min, omega): (f64, f64, f64), reference: (f64, f64, f64)) -> f64 {
    let (ref_max, ref_min, ref_omega) = reference;
    let excursion = ref_max.abs().max(ref_min.abs());
    let change = (max - ref_max).abs().max((min - ref_min).abs());
    let displacement = if change == 0.0 {
        0.0
    } else if excursion > 0.0 {
        change / excursion
    } else {
        f64::INFINITY
    };
    displacement.max((omega - ref_omega).abs() / ref_omega.abs())
}

impl<'a> Estimator<'a> {
    /// No estimate made yet for the branch of `rod` swept with `settings` over `sweep`
    /// (reference amplitude `u_ref`).
    fn new(
        rod: &'a Structure,
        settings: &'a SolverSettings,
        sweep: &'a SweepSettings,
        u_ref: f64,
    ) -> Self {
        Self {
            rod,
            settings,
            sweep,
            u_ref,
            problems: Vec::new(),
            seconds: 0.0,
            counters: RunCounters::default(),
        }
    }

    /// The estimated relative error of the point `x` at `h` harmonics and `omega`, whose
    /// observed dof has the extremes `(max, min)` and whose branch goes on along
    /// `direction` (module documentation).
    fn estimate(
        &mut self,
        omega: f64,
        h: usize,
        x: &[f64],
        (max, min): (f64, f64),
        direction: Option<&[f64]>,
    ) -> Result<Option<f64>, RunError> {
        let half = h / 2;
        if half == 0 {
            return Ok(None);
        }
        let started = Instant::now();
        let model = &self.rod.model;
        let dofs = model.dofs();
        let settings = at_harmonics(self.settings, half);
        let slot = match self.problems.iter().position(|(k, ..)| *k == half) {
            Some(slot) => slot,
            None => {
                let problem = SsnHb::new(model, omega, &hb_options(&settings))?;
                let tip = HbTip::new(half, output_points(h), dofs, self.rod.observed_dof)?;
                let solver = hb_solver(settings.linear_solver);
                self.problems.push((half, problem, tip, solver));
                self.problems.len() - 1
            }
        };
        let (_, problem, tip, solver) = &mut self.problems[slot];
        let (found, work) = take_up_with(
            (self.rod, &settings, self.sweep, self.u_ref),
            problem,
            &mut **solver,
            (x, omega, h),
            direction,
        )?;
        self.counters = self.counters + work;
        self.seconds += started.elapsed().as_secs_f64();
        let Some((y, coarse_omega)) = found else {
            return Ok(None);
        };
        let (coarse_max, coarse_min) = tip.extremes(&y)?;
        let distance = point_distance((coarse_max, coarse_min, coarse_omega), (max, min, omega));
        Ok(Some(distance / (2f64.powf(HB_ORDER) - 1.0)))
    }
}

/// A branch point taken up on other harmonics: its state and frequency.
pub type BranchPointAt = (Vec<f64>, f64);

/// The point `x` (at `h` harmonics) and `omega` of an SSN-HB branch taken up on
/// `problem` (the same model at other harmonics, `settings`): corrected on the hyperplane
/// through the point normal to `direction` (its state part at `h` harmonics, then the
/// frequency component), else at `omega` by globalized Newton. The state on `problem`'s
/// harmonics and its frequency (`None` when neither converged), and the work.
fn take_up_with(
    (rod, settings, sweep, u_ref): (&Structure, &SolverSettings, &SweepSettings, f64),
    problem: &mut SsnHb,
    solver: &mut dyn Factorize<HbJacobian>,
    (x, omega, h): (&[f64], f64, usize),
    direction: Option<&[f64]>,
) -> Result<(Option<BranchPointAt>, RunCounters), RunError> {
    let model = &rod.model;
    let (dofs, rows) = (model.dofs(), model.row_count());
    let to = settings.harmonics;
    let mut y = resize_harmonics(x, h, to, dofs, rows);
    let mut counters = RunCounters::default();
    if let Some(direction) = direction {
        let n = x.len();
        let mut carried = resize_harmonics(&direction[..n], h, to, dofs, rows);
        carried.push(direction[n]);
        let method = ssn_continuation(model, problem, u_ref);
        let options = continuation_options(settings, sweep, rod.omega_1, dofs, u_ref, &method)?;
        let options = widened(options, omega);
        let resumption = Resumption {
            state: y.clone(),
            parameter: omega,
            direction: carried,
            step: options.initial_step,
            folds: FoldDetector::new(false),
            points: 0,
        };
        let mut run = Continuation::resume(problem, solver, resumption, options)
            .map_err(continuation_error)?;
        let first = run.next();
        let run_counters = run.counters();
        drop(run);
        let mut work = run_counters.work;
        work.factorizations += run_counters.dense_bordered_factorizations;
        counters = counters + RunCounters::from(work);
        if let Some(point) = first {
            return Ok((Some((point.state, point.parameter)), counters));
        }
    }
    problem.set_parameter(omega);
    let report = newton_at(settings, model, problem, solver, &mut y)?;
    counters = counters + RunCounters::from(report.counters);
    Ok((report.converged().then_some((y, omega)), counters))
}

/// The point `x` (at `h` harmonics) and `omega` of the SSN-HB branch of `structure` swept with
/// `settings` over `sweep`, taken up at `to` harmonics across the branch (normal to
/// `direction`, a tangent or secant at the point: state part at `h` harmonics, then the
/// frequency component) or, failing that, at its frequency: the state at `to` harmonics
/// and its frequency, `None` when neither converged. The reference of a point's error
/// that follows the same solution through a fold.
pub fn take_up(
    structure: &Structure,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    (x, omega, h): (&[f64], f64, usize),
    direction: &[f64],
    to: usize,
) -> Result<Option<BranchPointAt>, RunError> {
    let at = at_harmonics(settings, to);
    let mut problem = SsnHb::new(&structure.model, omega, &hb_options(&at))?;
    let mut solver = hb_solver(at.linear_solver);
    let u_ref = reference_amplitude(structure);
    let (found, _) = take_up_with(
        (structure, &at, sweep, u_ref),
        &mut problem,
        &mut *solver,
        (x, omega, h),
        Some(direction),
    )?;
    Ok(found)
}

/// The secant of `response` at its point `i` (from the point before to the point after,
/// one side at the ends), both carried to point `i`'s harmonics when they differ: the
/// state part, then the frequency component (`rows`: the rows of `G`, whose forces the state
/// holds). Panics if `i` is not a point of `response`.
pub fn secant(response: &FrequencyResponse, i: usize, dofs: usize, rows: usize) -> Vec<f64> {
    let points = &response.points;
    let last = points.len() - 1;
    let (a, b) = (i.saturating_sub(1), (i + 1).min(last));
    let at = |j: usize| match (points[j].harmonics, points[i].harmonics) {
        (Some(from), Some(to)) if from != to => {
            resize_harmonics(&points[j].state, from, to, dofs, rows)
        }
        _ => points[j].state.clone(),
    };
    let (xa, xb) = (at(a), at(b));
    let mut d: Vec<f64> = xb.iter().zip(&xa).map(|(u, v)| u - v).collect();
    d.push(points[b].omega - points[a].omega);
    d
}

/// Globalized Newton on `problem` from `x` with the scene's options, the tolerance raised
/// to the round-off level of the residual (as `ssn solve` judges a solve).
fn newton_at(
    settings: &SolverSettings,
    model: &StructuralModel,
    problem: &mut SsnHb,
    solver: &mut dyn Factorize<HbJacobian>,
    x: &mut [f64],
) -> Result<semismooth::newton::NewtonReport, RunError> {
    let floor = displacement_floor(model, problem.dim(), problem.displacement_len(), 0.0);
    Ok(newton_options(settings).with_state_floor(floor).solve(
        problem,
        solver,
        x,
        Some(SmoothingOf::new()),
    )?)
}

/// `options` whose parameter bounds hold `omega`: a take-up corrects the one point there (a
/// point landed on a bound carries the rounding of its interpolation, and a last point the
/// run could not land lies past it).
fn widened(mut options: ContinuationOptions, omega: f64) -> ContinuationOptions {
    options.parameter_min = options.parameter_min.min(omega);
    options.parameter_max = options.parameter_max.max(omega);
    options
}

/// The resumption `r` of a run at `from` harmonics carried to `to` harmonics.
fn carried(r: Resumption, from: usize, to: usize, dofs: usize, rows: usize) -> Resumption {
    let n = r.state.len();
    let state = resize_harmonics(&r.state, from, to, dofs, rows);
    let mut direction = resize_harmonics(&r.direction[..n], from, to, dofs, rows);
    direction.push(r.direction[n]);
    Resumption {
        state,
        direction,
        ..r
    }
}

/// What the first item of a resumed run is.
#[derive(Clone, Copy, PartialEq, Eq)]
enum First {
    /// A fresh run: its first point is a new point.
    New,
    /// The point just estimated, solved again with more harmonics: reported if it meets.
    Raised,
    /// The point just reported, at the new (fewer) harmonics: not reported again.
    Lowered,
}

/// A change of harmonics decided at a point: to `to` harmonics from `resumption`, taken at
/// `from` harmonics.
struct Switch {
    from: usize,
    to: usize,
    resumption: Resumption,
    first: First,
}

/// How one run of the continuation at fixed harmonics ended: the change of harmonics
/// decided at one of its points, its termination, whether it was resumed and how many
/// items it gave.
struct Segment {
    switch: Option<Switch>,
    ended: Option<ContinuationTermination>,
    resumed: bool,
    items: usize,
}

/// The state an adaptive branch carries from one run of the continuation to the next.
struct Adaptive<'a> {
    rod: &'a Structure,
    settings: &'a SolverSettings,
    sweep: &'a SweepSettings,
    progress: Option<&'a dyn Fn(usize, f64)>,
    u_ref: f64,
    limit: usize,
    h: usize,
    response: FrequencyResponse,
    accuracy: BranchAccuracy,
    estimator: Estimator<'a>,
    events: Vec<ContinuationEvent>,
    counters: ContinuationCounters,
    resumption: Option<Resumption>,
    first: First,
    // After a resumed start failed: the old harmonics and the resumption to go back to,
    // and the index of the point that may not be raised again.
    fallback: Option<(usize, Resumption)>,
    no_raise_at: Option<usize>,
    // The start carried to new harmonics, until taken up there (a globalized solve at
    // its frequency is tried once when the continuation's start fails).
    unsolved: Option<Resumption>,
    // Work of the solves at new harmonics.
    switch_work: RunCounters,
}

/// `Err` unless `target` is a relative accuracy, the method SSN-HB and the sweep valid.
fn check_adaptive(
    settings: &SolverSettings,
    sweep: &SweepSettings,
    target: f64,
) -> Result<(), RunError> {
    check_target(target)?;
    if !settings.method.adapts_harmonics() {
        return Err(RunError::Unsupported {
            method: settings.method.name(),
            what: "harmonics chosen point by point (ssn-hb)",
        });
    }
    check_sweep(sweep)
}

/// The largest rung of the ladder for a model of `width` unknowns per harmonic (at least
/// the ladder's first).
fn harmonics_limit(width: usize) -> usize {
    let by_size = (MAX_SEARCH_UNKNOWNS / width.max(1)).saturating_sub(1) / 2;
    rung(
        MAX_SEARCH_HARMONICS.min(by_size) as f64,
        MAX_SEARCH_HARMONICS.min(by_size),
    )
    .max(HARMONICS_LADDER[0])
}

/// The SSN-HB branch of [`super::frequency_response`] with the harmonics chosen point by
/// point for the relative accuracy `target` (module documentation), without its
/// stability and contacts.
pub(crate) fn adaptive_branch(
    rod: &Structure,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    target: f64,
    progress: Option<&dyn Fn(usize, f64)>,
) -> Result<FrequencyResponse, RunError> {
    check_adaptive(settings, sweep, target)?;
    let started = Instant::now();
    let model = &rod.model;
    let u_ref = reference_amplitude(rod);
    let limit = harmonics_limit(model.dofs() + model.contact_count());
    let omega_from = sweep.omega_ratio_from * rod.omega_1;
    let h = HARMONICS_LADDER[0];
    let mut problem = SsnHb::new(model, omega_from, &hb_options(&at_harmonics(settings, h)))?;
    let mut solver = hb_solver(settings.linear_solver);
    let mut x = vec![0.0; problem.dim()];
    let report = newton_options(settings).solve(
        &mut problem,
        &mut *solver,
        &mut x,
        Some(SmoothingOf::new()),
    )?;
    let mut response = FrequencyResponse::empty(settings.method, rod.omega_1, sweep, u_ref);
    response.counters = RunCounters::from(report.counters);
    response.initial_iterations = report.iterations;
    let accuracy = BranchAccuracy::none_yet(target, limit);
    if !report.converged() {
        response.termination = SweepTermination::StartNotConverged {
            termination: report.termination.clone(),
            iterations: report.iterations,
            residual_norm: report.residual_norm(),
        };
        response.accuracy = Some(accuracy);
        response.solve_seconds = started.elapsed().as_secs_f64();
        return Ok(response);
    }
    let mut adaptive = Adaptive {
        rod,
        settings,
        sweep,
        progress,
        u_ref,
        limit,
        h,
        response,
        accuracy,
        estimator: Estimator::new(rod, settings, sweep, u_ref),
        events: Vec::new(),
        counters: ContinuationCounters::default(),
        resumption: None,
        first: First::New,
        fallback: None,
        no_raise_at: None,
        unsolved: None,
        switch_work: RunCounters::default(),
    };
    let termination = loop {
        let segment = adaptive.segment(&mut problem, &mut *solver, (&x, omega_from))?;
        if adaptive.retry_unsolved(&segment, &mut problem, &mut *solver)? {
            continue;
        }
        let Some(switch) = adaptive.next_switch(segment.switch, segment.resumed, segment.items)
        else {
            break segment.ended;
        };
        problem = adaptive.apply(switch)?;
    };
    Ok(adaptive.finish(termination, started))
}

impl Adaptive<'_> {
    /// One run of the continuation at the current harmonics, from the pending resumption
    /// or else from `x` at `omega_from`, until it ends or a point decides a change of
    /// harmonics.
    fn segment(
        &mut self,
        problem: &mut SsnHb,
        solver: &mut dyn Factorize<HbJacobian>,
        (x, omega_from): (&[f64], f64),
    ) -> Result<Segment, RunError> {
        let (model, h) = (&self.rod.model, self.h);
        let method = ssn_continuation(model, problem, self.u_ref);
        let options = continuation_options(
            &at_harmonics(self.settings, h),
            self.sweep,
            self.rod.omega_1,
            model.dofs(),
            self.u_ref,
            &method,
        )?;
        let resumed = self.resumption.is_some();
        let mut run = match self.resumption.take() {
            None => Continuation::new(problem, solver, x, omega_from, options),
            Some(r) => Continuation::resume(problem, solver, r, options),
        }
        .map_err(continuation_error)?;
        let mut tip = HbTip::new(h, output_points(h), model.dofs(), self.rod.observed_dof)?;
        let mut switch: Option<Switch> = None;
        let mut items = 0;
        while let Some(point) = run.next() {
            items += 1;
            if items == 1 && resumed && self.first == First::Lowered {
                continue;
            }
            // Where the run stands at this point: the direction of its estimate, and the
            // start of a change of harmonics decided here (taken once, not cloned again).
            let here = run.resumption();
            let running = run.termination().is_none();
            switch = self.point(&mut tip, point, here, running)?;
            if switch.is_some() {
                break;
            }
        }
        self.counters += run.counters();
        self.events.extend(run.events().iter().cloned());
        let ended = run.termination().cloned();
        Ok(Segment {
            switch,
            ended,
            resumed,
            items,
        })
    }

    /// Estimates the branch point `point` and reports it, unless the estimate asks for
    /// more harmonics; the change of harmonics decided there, if any (module
    /// documentation). `here` is the run's resumption at the point, `running` whether the
    /// run goes on after it.
    fn point(
        &mut self,
        tip: &mut HbTip,
        point: BranchPoint,
        mut here: Option<Resumption>,
        running: bool,
    ) -> Result<Option<Switch>, RunError> {
        let (h, target, limit) = (self.h, self.accuracy.target, self.limit);
        let omega = point.parameter;
        let (max, min) = tip.extremes(&point.state)?;
        let index = self.response.points.len();
        let direction = here.as_ref().map(|r| r.direction.as_slice());
        let estimate = self
            .estimator
            .estimate(omega, h, &point.state, (max, min), direction)?;
        let wanted = estimate.map(|e| wanted_harmonics(h, e, target));
        // A last point the run could not land exactly on the bound lies past it: the
        // continuation cannot resume there, so it is reported at these harmonics.
        let (lo, hi) = self.sweep_bounds();
        let resumable = (lo..=hi).contains(&omega);
        let raise = estimate.is_some_and(|e| e > target)
            && h < limit
            && self.no_raise_at != Some(index)
            && resumable;
        if raise {
            if let Some(r) = here.take() {
                let wanted = wanted
                    .unwrap_or(f64::INFINITY)
                    .clamp(h as f64 + 1.0, (MAX_RATIO * h as f64).max(h as f64 + 1.0));
                return Ok(Some(Switch {
                    from: h,
                    to: rung(wanted, limit),
                    resumption: r,
                    first: First::Raised,
                }));
            }
        }
        let nt = default_hb_time_samples(h);
        let mut record = ResponsePoint::new(omega, (max, min), point.iterations, point.state);
        record.harmonics = Some(h);
        record.time_samples = Some(nt);
        record.error_estimate = estimate;
        self.response.points.push(record);
        if let Some(report) = self.progress {
            report(index, omega / self.rod.omega_1);
        }
        let lower = estimate.is_some_and(|e| e <= LOWER_BELOW * target) && running;
        if let (true, Some(w)) = (lower, wanted) {
            let to = rung(w.max(h as f64 / MAX_RATIO), limit);
            if to < h {
                if let Some(r) = here.take() {
                    return Ok(Some(Switch {
                        from: h,
                        to,
                        resumption: r,
                        first: First::Lowered,
                    }));
                }
            }
        }
        Ok(None)
    }

    /// The sweep's frequency interval, as the continuation's bounds.
    fn sweep_bounds(&self) -> (f64, f64) {
        let (a, b) = (self.sweep.omega_ratio_from, self.sweep.omega_ratio_to);
        (a.min(b) * self.rod.omega_1, a.max(b) * self.rod.omega_1)
    }

    /// After a resumed start at new harmonics that gave nothing: the point there by
    /// globalized Newton at its frequency, once; `true` when it converged and the
    /// continuation is to be resumed from it.
    fn retry_unsolved(
        &mut self,
        segment: &Segment,
        problem: &mut SsnHb,
        solver: &mut dyn Factorize<HbJacobian>,
    ) -> Result<bool, RunError> {
        if segment.switch.is_some() || !segment.resumed || segment.items != 0 {
            return Ok(false);
        }
        let Some(mut retry) = self.unsolved.take() else {
            return Ok(false);
        };
        // Not taken up by the corrector's full steps (on the hyperplane across the
        // branch, then at the point's frequency): the point at the new harmonics
        // by globalized Newton at its frequency, then taken up from there.
        problem.set_parameter(retry.parameter);
        let report = newton_at(
            self.settings,
            &self.rod.model,
            problem,
            solver,
            &mut retry.state,
        )?;
        self.switch_work = self.switch_work + RunCounters::from(report.counters);
        if report.converged() {
            self.resumption = Some(retry);
            return Ok(true);
        }
        Ok(false)
    }

    /// The change of harmonics after a run: the one decided at a point, else the way
    /// back to the old harmonics when a resumed start gave nothing; `None` ends the branch.
    fn next_switch(
        &mut self,
        switch: Option<Switch>,
        resumed: bool,
        items: usize,
    ) -> Option<Switch> {
        match switch {
            Some(switch) => Some(switch),
            None if resumed && items == 0 && self.first == First::Raised => {
                // The raised start could not be corrected: back to the old harmonics.
                let (old, back) = self.fallback.take()?;
                self.accuracy.failed_raises += 1;
                self.no_raise_at = Some(self.response.points.len());
                Some(Switch {
                    from: old,
                    to: old,
                    resumption: back,
                    first: First::New,
                })
            }
            None if resumed && items == 0 && self.first == First::Lowered => {
                // The lowered start could not be corrected: on with the old harmonics.
                let (old, back) = self.fallback.take()?;
                Some(Switch {
                    from: old,
                    to: old,
                    resumption: back,
                    first: First::Lowered,
                })
            }
            None => None,
        }
    }

    /// Counts `switch`, carries its resumption to its harmonics and makes it the next
    /// start; the problem at the new harmonics.
    fn apply(&mut self, switch: Switch) -> Result<SsnHb, RunError> {
        match switch.first {
            First::Raised => self.accuracy.raises += 1,
            First::Lowered => self.accuracy.lowers += 1,
            First::New => {}
        }
        // A change (not a return to the old harmonics) can be undone once.
        self.fallback = (switch.first != First::New && switch.from != switch.to)
            .then(|| (switch.from, switch.resumption.clone()));
        let model = &self.rod.model;
        let (dofs, rows) = (model.dofs(), model.row_count());
        let to = switch.to;
        let resumed_at = switch.resumption.parameter;
        let carried = carried(switch.resumption, switch.from, to, dofs, rows);
        self.h = to;
        let problem = SsnHb::new(
            model,
            resumed_at,
            &hb_options(&at_harmonics(self.settings, to)),
        )?;
        self.first = match switch.first {
            // The fallback's first item is the point itself at the old harmonics.
            First::New => {
                self.unsolved = None;
                First::Raised
            }
            other => {
                self.unsolved = Some(carried.clone());
                other
            }
        };
        self.resumption = Some(carried);
        Ok(problem)
    }

    /// The response with the branch's events, work, termination and accuracy.
    fn finish(
        self,
        termination: Option<ContinuationTermination>,
        started: Instant,
    ) -> FrequencyResponse {
        let Adaptive {
            mut response,
            mut accuracy,
            estimator,
            events,
            counters,
            switch_work,
            ..
        } = self;
        set_events(&mut response, &events);
        let mut total = counters.work;
        total.factorizations += counters.dense_bordered_factorizations;
        response.counters =
            response.counters + RunCounters::from(total) + estimator.counters + switch_work;
        response.restarts = counters.restarts as usize;
        response.corners = counters.corners as usize;
        response.continuation = counters;
        response.termination = sweep_termination(termination);
        response.output_points = response
            .points
            .iter()
            .filter_map(|p| p.harmonics)
            .map(output_points)
            .max()
            .unwrap_or(HB_OUTPUT_POINTS);
        accuracy.estimate_seconds = estimator.seconds;
        accuracy.estimate_counters = estimator.counters;
        response.accuracy = Some(accuracy);
        response.solve_seconds = started.elapsed().as_secs_f64();
        response
    }
}
