//! Frequency-response curves: pseudo-arclength continuation in the forcing frequency of a
//! scene's periodic problem.
//!
//! [`frequency_response`] solves at `omega_from = omega_ratio_from * omega_1` by globalized
//! Newton from zero, then follows the branch with the core's
//! [`Continuation`] until the frequency leaves
//! `[omega_from, omega_to]` (through folds, where the frequency turns back). Each point is a
//! [`ResponsePoint`] record: its frequency, the observed dof over one period reduced to
//! `observed_max`, `observed_min` and the amplitude `max_t |u(t)|` (with contact the maximum
//! sits at the gap along the contact branch, so the negative excursion carries the
//! information), its state, stability, contacts and friction points.
//!
//! # What a step length means
//!
//! The continuation measures steps in its θ-weighted norm. Here it is given a state scale
//! `s_i` and a frequency scale `s_ω` such that with `θ = 1/2` a step `ds` is the Euclidean
//! arclength in the plane
//!
//! ```text
//! ds² = (Δω / ω_1)² + |ΔX|² / (N u_ref²),
//! ```
//!
//! `N` the number of dofs, `|ΔX|` the 2-norm of the change of all displacement coefficients
//! (SSN-HB's force coefficients count divided by `c`, LCP forces divided by `κ`, LCP gaps
//! as displacements), and `u_ref` the root-mean-square over the dofs of the linear response
//! (contacts removed) at `ω_1` ([`FrequencyResponse::reference_amplitude`]): `s_i = u_i
//! sqrt(θ N / n) u_ref` (`u_i` = 1, `c` or `κ`, `n` unknowns) and `s_ω = sqrt(1 - θ) ω_1`.
//! The linear resonance is thus at distance about 1 from zero in both directions, whatever
//! `H`, `Nt` or the mesh: `[sweep] step = 0.01` means about one percent of `ω_1` on flat
//! parts of the curve and one percent of the resonant amplitude on steep ones.
//!
//! # Robustness on piecewise-smooth branches
//!
//! The contact branches are only piecewise smooth (the set of active AFT samples or time
//! nodes changes along them), with corners and folds at corners. The sweep turns on the
//! core continuation's measures for such branches:
//!
//! - a trust ball of `TRUST_FACTOR` (3) times the largest next step around the last point
//!   ([`ContinuationOptions::trust_factor`]): without it Newton sometimes converged on the
//!   far side of an overhang and skipped both folds;
//! - the corner passes ([`ContinuationOptions::pass_corners`]) and restarts with a
//!   state-heavy metric ([`RestartPolicy`], its defaults), whose retrace test ends a sweep
//!   that could only go back along the branch ("stalled at omega_ratio ...");
//! - penalty HB is [`PiecewiseAffine`](semismooth::continuation::PiecewiseAffine) (its
//!   switching functions are the gaps at the AFT samples): its corners are crossed exactly
//!   ([`Continuation::with_affine_pieces`]), and its folds are corners.
//!
//! The corrector tolerance is `CORRECTOR_TOLERANCE_FACTOR` (0.1) times the scene's Newton
//! tolerance for SSN-HB and lcp-ssn (for SSN-HB at least the round-off floor of its
//! residual, which large models reach), so each point is a fixed point of a Newton solve at
//! that tolerance. For penalty HB it is the scene's tolerance or the rounding floor of
//! `|F|`, `ε k_p max(|g|, u_ref)` (the penalty force is `k_p` times gaps computed to
//! `ε |u|`), whichever is larger.
//!
//! # Methods
//!
//! - `ssn-hb`, `penalty-hb`: the harmonic-balance problems ([`SsnHb`], [`PenaltyHb`]) with the
//!   scene's linear solver (`structured`: [`StructuredHbSolver`], `dense`: [`FaerDenseLu`]).
//! - `lcp-ssn`: the periodic LCP as the equation [`FrequencyLcp`] in the gaps and forces
//!   `y = (w, z)` at the `Nt` time nodes, `w - q(ω) - A(ω) z = 0`, `min(z, κ w) = 0`
//!   (`κ` = the scene's `c`, default the contact stiffness scale; the force unit of the
//!   arclength), with the active-block solver [`FrequencyLcpSolver`] and the analytic
//!   `dF/dω`. It starts from the one-call solve's mesh-sequenced min-map solve at `omega_from`.
//!   The observed extremes are taken on the `Nt` nodes (`u = g - w` when the observed dof
//!   is a contact, else from the LCP of the point's frequency with that dof observed). The
//!   discrete LCP branch has a small fold at many changes of the active set (a node
//!   entering or leaving contact), reported in `corner_folds` (see below). Known limit: a contact on a
//!   node with mass (the ill-posed case without an impact law, module `lcp`): the branch
//!   has a corner right after the contact onset that neither the arclength, the corner
//!   passes nor the restarts turn, and the sweep stops there with `converged = false`.
//! - `lcp-lemke`, `march`: [`RunError::Unsupported`]. Lemke's pivoting and time
//!   marching are no equation in `ω` to continue; solve frequency by frequency with
//!   `ssn solve`.
//!
//! # Folds and corners
//!
//! The continuation reports the reversals of the frequency. On piecewise-smooth branches
//! most of them are corners, not turning points: fine steps resolve micro-zigzags of about
//! 1e-4 `ω_1` where AFT samples enter contact, and a penalty branch turns back a little at
//! many of its corners. The sweep sets the core's
//! [`ContinuationOptions::fold_excursion`] to [`TURNING_POINT_EXCURSION`] (in `ω_1`, the
//! θ-length of a frequency step here): a reversal the branch leaves by at least that much
//! is a fold (`folds`), the others are zigzags (`corner_folds`).
//!
//! # What a branch keeps
//!
//! Each point keeps the method's full state unless [`frequency_response_storing`] is asked
//! for [`StateStorage::ContactForces`]: an SSN-HB branch then keeps `m (2H + 1)` numbers a
//! point instead of `(2H + 1)(N + m)`, and its analyses read full states recovered by
//! [`StateRecovery`] (module `storage`; measurements in `docs/finite_element_models.md`).
//!
//! Measured branch sizes, timings and limits are in `docs/sweeps.md` and
//! `examples/lcp_sweep.rs`.

pub mod adaptive;
pub mod branch;
mod contacts;
pub mod doubling;
pub mod fold_accuracy;
mod frictional;
pub mod peak;
mod response;
mod storage;

use std::time::Instant;

use semismooth::continuation::{
    Continuation, ContinuationError, ContinuationEvent, ContinuationOptions,
    ContinuationTermination, Direction, Predictor, RestartPolicy,
};
use semismooth::linalg::FaerDenseLu;
use semismooth::newton::{StateFloor, WorkCounters};
use semismooth::polyalgorithm::SmoothingOf;
use semismooth::{Factorize, GeneralizedJacobian, LinearSolve, ParameterDependent, Residual};

use response::{extremes, HbTip};
pub use response::{
    FrequencyResponse, ResponsePoint, StateStorage, SweepTermination, TURNING_POINT_EXCURSION,
};
use storage::Compaction;
pub use storage::StateRecovery;

use crate::hb::{HbError, HbJacobian, PenaltyHb, PenaltyHbOptions, SsnHb, StructuredHbSolver};
use crate::lcp::{solve_min_map_sequenced, FrequencyLcp, FrequencyLcpSolver};
use crate::model::{StructuralModel, Structure};
use crate::settings::{LinearSolverChoice, SolverSettings, SweepSettings};
use crate::solve::{
    lcp_options, newton_options, penalty_options, HarmonicProblem, RunCounters, RunError,
    HB_OUTPUT_POINTS,
};
use crate::stability::Undecided;
use branch::branch_stability;
pub(crate) use branch::Reconstruction;
pub use branch::{BifurcationEvent, BranchStability, PointStability};

/// Weight `θ` of the state in the arclength (module documentation: with the scaling used
/// here any `θ` in `(0, 1)` gives the same geometry; `1/2` keeps both parts of the θ-norm
/// of order one).
pub(crate) const THETA: f64 = 0.5;

/// Largest number of corrector iterations per attempted step.
pub(crate) const MAX_CORRECTOR_ITERATIONS: usize = 12;

/// The corrector's tolerance on `|F|` relative to the scene's Newton tolerance: one decade
/// tighter, so that every branch point is a fixed point of a Newton solve at the scene's
/// tolerance even where the Jacobian is ill-conditioned (near folds).
pub(crate) const CORRECTOR_TOLERANCE_FACTOR: f64 = 0.1;

/// Corrector iterations the step control aims at.
pub(crate) const TARGET_ITERATIONS: usize = 4;

/// The corrector may not leave the θ-ball of this many largest next steps around the last
/// accepted point ([`ContinuationOptions::trust_factor`]).
pub(crate) const TRUST_FACTOR: f64 = 3.0;

/// Failed steps in a row (each halving the step) after which a penalty-HB branch crosses
/// the corner ahead exactly.
pub(crate) const PENALTY_MAX_FAILURES: usize = 3;

/// The structured or dense linear solver of a harmonic-balance scene.
fn hb_solver(choice: LinearSolverChoice) -> Box<dyn Factorize<HbJacobian>> {
    match choice.condensed() {
        Some(condensed) => Box::new(StructuredHbSolver::new().with_condensed_solve(condensed)),
        None => Box::new(FaerDenseLu::new()),
    }
}

/// Root mean square over the dofs of the linear response (contacts removed) at `ω_1`
/// (`0.95 ω_1`, then `0.5 ω_1` if that is singular, e.g. undamped); `1` if all fail.
fn reference_amplitude(rod: &Structure) -> f64 {
    let mut model = rod.model.clone();
    model.contacts.clear();
    model.friction.clear();
    model.frictional_contacts.clear();
    let dofs = model.dofs().max(1);
    let options = PenaltyHbOptions {
        harmonics: 1,
        time_samples: None,
        penalty_stiffness: 1.0,
    };
    let Ok(mut problem) = PenaltyHb::new(&model, rod.omega_1, &options) else {
        return 1.0;
    };
    for ratio in [1.0, 0.95, 0.5] {
        if problem.set_omega(ratio * rod.omega_1).is_err() {
            continue;
        }
        let n = problem.dim();
        let x = vec![0.0; n];
        let mut r = vec![0.0; n];
        let mut jac = problem.new_jacobian();
        if problem.jacobian(&x, &mut jac).is_err() || problem.residual(&x, &mut r).is_err() {
            continue;
        }
        let mut solver = StructuredHbSolver::new();
        if solver.factor(&jac).is_err() || solver.solve_in_place(&mut r).is_err() {
            continue;
        }
        let rms = (r.iter().map(|v| v * v).sum::<f64>() / dofs as f64).sqrt();
        if rms.is_finite() && rms > 0.0 {
            return rms;
        }
    }
    1.0
}

fn invalid(name: &'static str, value: f64, allowed: &'static str) -> RunError {
    RunError::InvalidSetting {
        name,
        value,
        allowed,
    }
}

fn check_sweep(sweep: &SweepSettings) -> Result<(), RunError> {
    for (name, value) in [
        ("sweep.omega_ratio_from", sweep.omega_ratio_from),
        ("sweep.omega_ratio_to", sweep.omega_ratio_to),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(invalid(name, value, "finite and > 0"));
        }
    }
    if sweep.omega_ratio_to == sweep.omega_ratio_from {
        return Err(invalid(
            "sweep.omega_ratio_to",
            sweep.omega_ratio_to,
            "a value different from omega_ratio_from",
        ));
    }
    Ok(())
}

/// What a method's branch needs from the continuation beyond the common settings.
struct MethodContinuation {
    /// Per unknown: 1 for displacements, the force unit for forces.
    units: Vec<f64>,
    /// Rounding floor of `|F|` in proportion to the state's displacements (off where
    /// negligible): the corrector tolerance is at least this.
    floor: StateFloor,
    /// The branch is piecewise affine and its corners are crossed exactly.
    affine_pieces: bool,
    /// Corners that the passes cannot turn are left along the exit piece's tangent
    /// ([`ContinuationOptions::exit_tangents`]).
    exit_tangents: bool,
}

/// SSN-HB's units (force coefficients count divided by `c`) and the round-off floor that
/// `ssn solve` judges a solve against (large models reach 1e-10 in force units).
fn ssn_continuation(model: &StructuralModel, problem: &SsnHb, u_ref: f64) -> MethodContinuation {
    let split = problem.displacement_len();
    let c = problem.c();
    let units = (0..problem.dim())
        .map(|i| if i < split { 1.0 } else { c })
        .collect();
    MethodContinuation {
        units,
        floor: StateFloor {
            per_unit: crate::solve::roundoff_floor(model, problem.dim(), 1.0, 0.0),
            entries: Some(split),
            cap: largest_gap(model, u_ref),
        },
        affine_pieces: false,
        // The last resort of a restart that went back along the branch (the paths of
        // sweeps that end otherwise are unchanged).
        exit_tangents: true,
    }
}

/// Penalty HB's units and rounding floor: the penalty force is `k_p` times gaps computed
/// to `ε |u|` (`|u|` at most the larger of the gap and `u_ref` in contact); its branch is
/// piecewise affine.
fn penalty_continuation(
    model: &StructuralModel,
    problem: &PenaltyHb,
    options: &PenaltyHbOptions,
    u_ref: f64,
) -> MethodContinuation {
    MethodContinuation {
        units: vec![1.0; problem.dim()],
        floor: StateFloor {
            per_unit: f64::EPSILON * options.penalty_stiffness,
            entries: None,
            cap: largest_gap(model, u_ref),
        },
        affine_pieces: !model.has_friction(),
        exit_tangents: false,
    }
}

/// The largest contact gap, and at least `u_ref`.
fn largest_gap(model: &StructuralModel, u_ref: f64) -> f64 {
    model
        .contacts
        .iter()
        .map(|c| c.gap.abs())
        .fold(u_ref, f64::max)
}

/// Maps the sweep settings onto continuation options in `ω` (absolute).
fn continuation_options(
    settings: &SolverSettings,
    sweep: &SweepSettings,
    omega_1: f64,
    dofs: usize,
    u_ref: f64,
    method: &MethodContinuation,
) -> Result<ContinuationOptions, RunError> {
    let (lo, hi) = if sweep.omega_ratio_to > sweep.omega_ratio_from {
        (sweep.omega_ratio_from, sweep.omega_ratio_to)
    } else {
        (sweep.omega_ratio_to, sweep.omega_ratio_from)
    };
    // Halving from max_step down to min_step, plus one attempt at min_step.
    let halvings = (sweep.max_step / sweep.min_step).log2().ceil().max(0.0) as usize + 2;
    let n = method.units.len().max(1);
    // s_i = u_i sqrt(θ N / n) u_ref: (θ/n)|ΔX/s|² = |ΔX|² / (N u_ref²).
    let base = (THETA * dofs as f64 / n as f64).sqrt() * u_ref;
    let options = ContinuationOptions {
        initial_step: sweep.step,
        min_step: sweep.min_step,
        max_step: sweep.max_step,
        target_iterations: TARGET_ITERATIONS,
        max_corrector_iterations: MAX_CORRECTOR_ITERATIONS,
        corrector_tolerance: if method.affine_pieces {
            // |F| cannot be computed below its rounding floor (`corrector_state_floor`: a
            // stiff penalty puts it near the scene's tolerance).
            settings.tolerance
        } else {
            CORRECTOR_TOLERANCE_FACTOR * settings.tolerance
        },
        corrector_state_floor: method.floor,
        parameter_min: lo * omega_1,
        parameter_max: hi * omega_1,
        max_points: sweep.max_points,
        max_consecutive_failures: if method.affine_pieces {
            // A failed step on a piecewise-affine branch is a corner, crossed exactly.
            PENALTY_MAX_FAILURES
        } else {
            halvings.clamp(3, 64)
        },
        theta: THETA,
        state_scale: Some(method.units.iter().map(|u| u * base).collect()),
        // (1 - θ) Δω² / s_ω² = (Δω / ω_1)².
        parameter_scale: (1.0 - THETA).sqrt() * omega_1,
        direction: if sweep.omega_ratio_to > sweep.omega_ratio_from {
            Direction::Increasing
        } else {
            Direction::Decreasing
        },
        predictor: Predictor::Secant,
        refine_folds: true,
        // With the scaling above a θ-length in the parameter is |Δω| / ω_1.
        fold_excursion: TURNING_POINT_EXCURSION,
        trust_factor: Some(TRUST_FACTOR),
        restarts: Some(RestartPolicy::default()),
        exit_tangents: method.exit_tangents,
        ..ContinuationOptions::default()
    };
    options.validate().map_err(continuation_error)?;
    Ok(options)
}

fn continuation_error(e: ContinuationError) -> RunError {
    match e {
        ContinuationError::InvalidOption {
            name,
            value,
            allowed,
        } => {
            let name = match name {
                "initial_step" => "sweep.step",
                "min_step" => "sweep.min_step",
                "max_step" => "sweep.max_step",
                "max_points" => "sweep.max_points",
                "corrector_tolerance" => "solver.tolerance",
                "parameter_max" | "parameter_min" => "sweep.omega_ratio_to",
                other => other,
            };
            invalid(name, value, allowed)
        }
        ContinuationError::DimensionMismatch { expected, found } => {
            RunError::HarmonicBalance(HbError::DimensionMismatch {
                what: "continuation state",
                expected,
                found,
            })
        }
        ContinuationError::Newton(e) => RunError::Newton(e),
        ContinuationError::InvalidStart { parameter, .. } => invalid(
            "sweep.omega_ratio_from",
            parameter,
            "within the sweep interval",
        ),
        other => RunError::Continuation(other),
    }
}

/// Reduces a state to the observed dof's `(max, min)` over one period.
type TipMeasure<'m, P> = dyn FnMut(&P, &[f64], f64) -> Result<(f64, f64), RunError> + 'm;

/// Everything [`follow`] needs besides the problem, the solver and the measure.
struct Setup<'a> {
    settings: &'a SolverSettings,
    sweep: &'a SweepSettings,
    omega_1: f64,
    u_ref: f64,
    dofs: usize,
    method: MethodContinuation,
    output_points: usize,
    started: Instant,
    /// Starting guess of the Newton solve at `omega_from` (zero when `None`) and the work
    /// spent computing it.
    start: Option<(Vec<f64>, WorkCounters)>,
    /// Bounds of the frequency in place of the sweep's `[omega_from, omega_to]` (a branch
    /// that starts inside the sweep's range).
    bounds: Option<(f64, f64)>,
    /// What the points keep of their states (`None`: the full states).
    compaction: Option<Compaction<'a>>,
}

/// Newton at `omega_from` (the problem's `smoothing` offered to the polyalgorithm), then the
/// continuation to the end of the sweep (module documentation); every accepted point is
/// measured and reported to `progress`.
fn follow<P, S>(
    (problem, smoothing): (&mut P, Option<SmoothingOf<P>>),
    solver: &mut S,
    setup: Setup<'_>,
    measure: &mut TipMeasure<'_, P>,
    configure: impl FnOnce(Continuation<'_, P, S>) -> Continuation<'_, P, S>,
    progress: Option<&dyn Fn(usize, f64)>,
) -> Result<FrequencyResponse, RunError>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    let (settings, sweep, omega_1) = (setup.settings, setup.sweep, setup.omega_1);
    let n = problem.dim();
    let mut options = continuation_options(
        settings,
        sweep,
        omega_1,
        setup.dofs,
        setup.u_ref,
        &setup.method,
    )?;
    if let Some((lo, hi)) = setup.bounds {
        (options.parameter_min, options.parameter_max) = (lo, hi);
    }

    let omega_from = sweep.omega_ratio_from * omega_1;
    problem.set_parameter(omega_from);
    let (mut x, mut work) = setup
        .start
        .unwrap_or_else(|| (vec![0.0; n], WorkCounters::default()));
    let report = newton_options(settings).solve(problem, solver, &mut x, smoothing)?;
    work += report.counters;
    let mut response = FrequencyResponse::empty(settings.method, omega_1, sweep, setup.u_ref);
    response.counters = RunCounters::from(work);
    response.initial_iterations = report.iterations;
    response.output_points = setup.output_points;
    if !report.converged() {
        response.termination = SweepTermination::StartNotConverged {
            termination: report.termination.clone(),
            iterations: report.iterations,
            residual_norm: report.residual_norm(),
        };
        response.solve_seconds = setup.started.elapsed().as_secs_f64();
        return Ok(response);
    }

    let mut compaction = setup.compaction;
    if let Some(compaction) = &mut compaction {
        compaction.verify(omega_from, &x);
    }
    let mut continuation = configure(
        Continuation::new(problem, solver, &x, omega_from, options).map_err(continuation_error)?,
    );
    while let Some(point) = continuation.next() {
        let omega = point.parameter;
        let (max, min) = measure(continuation.problem(), &point.state, omega)?;
        let state = match &compaction {
            Some(compaction) => compaction.keep(point.state),
            None => point.state,
        };
        let mut record = ResponsePoint::new(omega, (max, min), point.iterations, state);
        if settings.method.is_harmonic_balance() {
            record.harmonics = Some(settings.harmonics);
            record.time_samples = Some(settings.time_samples);
        }
        response.points.push(record);
        if let Some(report) = progress {
            report(response.points.len() - 1, omega / omega_1);
        }
    }
    let c = continuation.counters();
    set_events(&mut response, continuation.events());
    let termination = continuation.termination().cloned();
    drop(continuation);
    let mut total = work;
    total += c.work;
    total.factorizations += c.dense_bordered_factorizations;
    response.counters = RunCounters::from(total);
    response.restarts = c.restarts as usize;
    response.corners = c.corners as usize;
    response.continuation = c;
    response.termination = sweep_termination(termination);
    response.state_storage = compaction.map_or(StateStorage::Full, |c| c.storage());
    response.solve_seconds = setup.started.elapsed().as_secs_f64();
    Ok(response)
}

/// The folds (`fold_excursion` confirmed) and zigzags of a branch's `events`, in branch
/// order, into `response`.
fn set_events(response: &mut FrequencyResponse, events: &[ContinuationEvent]) {
    let mut reversals: Vec<(usize, f64, bool)> = events
        .iter()
        .filter_map(|event| match event {
            ContinuationEvent::Fold { index, parameter } => Some((*index, *parameter, true)),
            ContinuationEvent::Zigzag { index, parameter } => Some((*index, *parameter, false)),
            _ => None,
        })
        .collect();
    reversals.sort_by_key(|e| e.0);
    for (index, omega, fold) in reversals {
        if fold {
            response.folds.push(omega);
            response.fold_indices.push(index);
        } else {
            response.corner_folds.push(omega);
            response.corner_fold_indices.push(index);
        }
    }
}

/// A sweep's termination from its continuation's.
fn sweep_termination(termination: Option<ContinuationTermination>) -> SweepTermination {
    match termination {
        Some(
            ContinuationTermination::StartFailed { failure, .. }
            | ContinuationTermination::SegmentStartFailed { failure, .. },
        ) => SweepTermination::StartNotCorrected(failure),
        Some(t) => SweepTermination::Branch(t),
        None => SweepTermination::Unexplained,
    }
}

/// What a sweep reports while it runs ([`frequency_response`]'s `progress`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum SweepProgress {
    /// The branch has `points` points, the last at `omega_ratio` (units of `omega_1`).
    Branch {
        /// Points accepted so far.
        points: usize,
        /// Frequency of the last one, in units of `omega_1`.
        omega_ratio: f64,
    },
    /// The stability of `done` of the branch's `total` points is known.
    Stability {
        /// Points analysed.
        done: usize,
        /// Points of the branch.
        total: usize,
    },
}

/// Frequency-response curve of the structure with the scene's method (module documentation):
/// globalized Newton at `omega_ratio_from`, then pseudo-arclength continuation in `ω` up to
/// `omega_ratio_to`. `progress` hears of each accepted point, then of each point whose
/// stability is computed.
///
/// `Err` when the sweep could not start (bad settings, unsupported method, a model the
/// method cannot build); a branch that stopped early is an `Ok` curve with
/// `converged = false` and the reason in `termination`.
///
/// With [`SolverSettings::accuracy`] an SSN-HB branch chooses its harmonics point by point
/// to meet it ([`adaptive`]; the scene's `harmonics` is then ignored).
///
/// Each point then gets its stability and contact diagnostics
/// ([`crate::sweep::branch::branch_stability`], in [`ResponsePoint::stability`]) unless
/// [`SweepSettings::stability`] is off (the points are then undecided with
/// [`Undecided::NotRequested`], their contact diagnostics still computed); a failure there
/// leaves the points undecided with the reason.
pub fn frequency_response(
    structure: &Structure,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    progress: Option<&dyn Fn(SweepProgress)>,
) -> Result<FrequencyResponse, RunError> {
    frequency_response_storing(structure, settings, sweep, StateStorage::Full, progress)
}

/// [`frequency_response`] keeping of each point's state what `storage` says: with
/// [`StateStorage::ContactForces`] an SSN-HB branch (without an accuracy target) keeps
/// `m (2H + 1)` numbers a point instead of `(2H + 1)(N + m)`, and the stability, contact
/// reports, peak search and period doubling read full states recovered point by point
/// ([`StateRecovery`], one factorization of the dynamic blocks per point and analysis).
/// The frequencies, observed extremes and folds are those of [`frequency_response`]
/// (taken before the states are reduced); the quantities read from recovered states differ
/// from them by the corrector's residual in the equations of motion (module `storage`).
pub fn frequency_response_storing(
    structure: &Structure,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    storage: StateStorage,
    progress: Option<&dyn Fn(SweepProgress)>,
) -> Result<FrequencyResponse, RunError> {
    let branch_progress = progress.map(|report| {
        move |points: usize, omega_ratio: f64| {
            report(SweepProgress::Branch {
                points: points + 1,
                omega_ratio,
            })
        }
    });
    let branch_progress = branch_progress.as_ref().map(|p| p as &dyn Fn(usize, f64));
    let mut response = match settings.accuracy {
        Some(target) if settings.method.adapts_harmonics() => {
            adaptive::adaptive_branch(structure, settings, sweep, target, branch_progress)?
        }
        _ => follow_branch_storing(structure, settings, sweep, storage, branch_progress)?,
    };
    contacts::set_branch_reports(structure, settings, &mut response)?;
    frictional::set_frictional_summaries(structure, settings, &mut response)?;
    if settings.method.is_harmonic_balance() {
        response.located_peak = peak::locate_peak(structure, settings, &response);
    }
    let started = Instant::now();
    let total = response.points.len();
    let stability_progress =
        progress.map(|report| move |done: usize| report(SweepProgress::Stability { done, total }));
    let stability = branch_stability(
        structure,
        settings,
        &response,
        sweep.stability,
        stability_progress.as_ref().map(|p| p as &dyn Fn(usize)),
    )
    .unwrap_or_else(|err| BranchStability::not_decided(total, Undecided::Failed(err)));
    response.set_stability(stability);
    response.stability_seconds = started.elapsed().as_secs_f64();
    if sweep.stability && sweep.period_two && settings.method == crate::settings::Method::SsnHb {
        response.period_two = doubling::period_two_branches(structure, settings, sweep, &response);
    }
    Ok(response)
}

/// The branch of [`frequency_response`] without its stability.
pub(crate) fn follow_branch(
    rod: &Structure,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    progress: Option<&dyn Fn(usize, f64)>,
) -> Result<FrequencyResponse, RunError> {
    follow_branch_storing(rod, settings, sweep, StateStorage::Full, progress)
}

/// The branch of [`frequency_response_storing`] without its stability.
fn follow_branch_storing(
    rod: &Structure,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    storage: StateStorage,
    progress: Option<&dyn Fn(usize, f64)>,
) -> Result<FrequencyResponse, RunError> {
    check_sweep(sweep)?;
    let started = Instant::now();
    let model = &rod.model;
    let tip = rod.observed_dof;
    let dofs = model.dofs();
    let omega_1 = rod.omega_1;
    // The problems are built at the start of the branch (`follow` solves there first).
    let omega_from = sweep.omega_ratio_from * omega_1;
    let u_ref = reference_amplitude(rod);
    let output_points = HB_OUTPUT_POINTS.max(settings.time_samples);
    let setup = |method: MethodContinuation, output_points: usize| Setup {
        settings,
        sweep,
        omega_1,
        u_ref,
        dofs,
        method,
        output_points,
        started,
        start: None,
        bounds: None,
        compaction: None,
    };
    let formulation = crate::solve::formulation::of(settings.method);
    if let Some(what) = formulation.continuation_refusal() {
        return Err(RunError::Unsupported {
            method: formulation.name(),
            what,
        });
    }
    match formulation
        .harmonic_problem(model, omega_from, settings)
        .transpose()?
    {
        Some(HarmonicProblem::Ssn(mut problem)) => {
            let mut tip_rec = HbTip::new(settings.harmonics, output_points, dofs, tip)?;
            let mut measure = |_: &SsnHb, x: &[f64], _: f64| tip_rec.extremes(x);
            let method = ssn_continuation(model, &problem, u_ref);
            let split = problem.displacement_len();
            follow(
                (&mut problem, Some(SmoothingOf::new())),
                &mut *hb_solver(settings.linear_solver),
                Setup {
                    compaction: Compaction::of(storage, model, settings, split),
                    ..setup(method, output_points)
                },
                &mut measure,
                |c| c,
                progress,
            )
        }
        Some(HarmonicProblem::Penalty(mut problem)) => {
            let options = penalty_options(settings, model);
            let mut tip_rec = HbTip::new(settings.harmonics, output_points, dofs, tip)?;
            let mut measure = |_: &PenaltyHb, x: &[f64], _: f64| tip_rec.extremes(x);
            let method = penalty_continuation(model, &problem, &options, u_ref);
            follow(
                (&mut problem, None),
                &mut *hb_solver(settings.linear_solver),
                setup(method, output_points),
                &mut measure,
                // With friction (regularised, smooth) the branch is not piecewise affine.
                |c| {
                    if !model.has_friction() {
                        c.with_affine_pieces()
                    } else {
                        c
                    }
                },
                progress,
            )
        }
        // The periodic LCP by its min map, the one continuable time-domain formulation.
        None => follow_lcp(rod, settings, omega_from, setup, progress),
    }
}

/// The branch of the periodic LCP solved by SSN (`lcp-ssn`), from the sequenced min-map
/// solve at `omega_from`; `setup` completes [`follow`]'s setup with the continuation's
/// method and the output points.
fn follow_lcp<'a>(
    rod: &Structure,
    settings: &SolverSettings,
    omega_from: f64,
    setup: impl FnOnce(MethodContinuation, usize) -> Setup<'a>,
    progress: Option<&dyn Fn(usize, f64)>,
) -> Result<FrequencyResponse, RunError> {
    let model = &rod.model;
    if model.contacts.is_empty() {
        return Err(RunError::Unsupported {
            method: "lcp-ssn",
            what: "a [contact] section (the periodic LCP is posed on the contact \
                   forces; sweep a linear scene with ssn-hb or penalty-hb)",
        });
    }
    let kappa = settings.c.unwrap_or(model.contact_stiffness_scale());
    // u_tip = g - w on the nodes when the tip is a contact dof; otherwise the tip is
    // observed by the LCPs the problem builds.
    let contacts = model.contact_count();
    let (lcp_options, tip_contact) = lcp_options(rod, settings);
    // Start: the one-call solve's sequenced min-map solve at omega_from, y0 = (q + A z, z).
    let mut problem = FrequencyLcp::new(model, omega_from, lcp_options, kappa)?;
    let finest = problem.current()?;
    let sequenced = solve_min_map_sequenced(model, omega_from, &finest, &newton_options(settings))?;
    let start_counters = sequenced.levels.iter().map(|l| l.report.counters).sum();
    let y0 = problem.state_from_forces(&sequenced.z)?;
    let half = problem.half();
    let units = (0..problem.dim())
        .map(|i| if i < half { 1.0 } else { kappa })
        .collect();
    let gap = tip_contact.map_or(0.0, |c| model.contacts[c].gap);
    let time_samples = settings.time_samples;
    let mut measure = |p: &FrequencyLcp, y: &[f64], omega: f64| -> Result<(f64, f64), RunError> {
        match tip_contact {
            Some(c) => {
                let tip: Vec<f64> = (0..time_samples)
                    .map(|n| gap - y[n * contacts + c])
                    .collect();
                Ok(extremes(&tip))
            }
            None => {
                let lcp = p.lcp_at(omega)?;
                let u = lcp.displacements(&y[half..])?;
                Ok(extremes(&u[0]))
            }
        }
    };
    let method = MethodContinuation {
        units,
        floor: StateFloor::OFF,
        affine_pieces: false,
        exit_tangents: false,
    };
    let setup = Setup {
        start: Some((y0, start_counters)),
        ..setup(method, settings.time_samples)
    };
    follow(
        (&mut problem, None),
        &mut FrequencyLcpSolver::new(),
        setup,
        &mut measure,
        |c| c,
        progress,
    )
}
