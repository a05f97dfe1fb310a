//! Frequency-response curves: pseudo-arclength continuation in the forcing frequency of a
//! scene's periodic problem (issue 6).
//!
//! [`frequency_response`] solves at `omega_from = omega_ratio_from * omega_1` by globalized
//! Newton from zero, then follows the branch with [`semismooth::continuation`] until the
//! frequency leaves `[omega_from, omega_to]` (through folds, where the frequency turns back).
//! Each point is reduced to the tip over one period: `tip_max`, `tip_min` and the amplitude
//! `max_t |u_tip(t)|` (with contact the maximum sits at the gap along the contact branch, so
//! the negative excursion carries the information).
//!
//! # What a step length means
//!
//! The continuation measures steps in a θ-weighted norm of its unknowns. It runs here on
//! scaled unknowns (the problem is wrapped, the core is untouched), chosen so that with
//! `θ = 1/2` a step `ds` is the Euclidean arclength in the plane
//!
//! ```text
//! ds² = (Δω / ω_1)² + |ΔX|² / (N u_ref²),
//! ```
//!
//! `N` the number of dofs, `|ΔX|` the 2-norm of the change of all displacement coefficients
//! (SSN-HB's force coefficients count divided by `c`, LCP forces divided by `κ`, LCP gaps
//! as displacements), and `u_ref` the root-mean-square over the dofs of the linear response
//! (contacts removed) at `ω_1` ([`FrequencyResponse::reference_amplitude`]). The linear
//! resonance is thus at distance about 1 from zero in both directions, whatever `H`, `Nt`
//! or the mesh: `[sweep] step = 0.01` means about one percent of `ω_1` on flat parts of the
//! curve and one percent of the resonant amplitude on steep ones, for `H = 5` as for
//! `H = 50`.
//!
//! # Robustness on piecewise-smooth branches
//!
//! The contact branches are only piecewise smooth (the set of active AFT samples changes
//! along them), with corners and folds at corners. Three measures on this side of the core:
//!
//! - a trust ball: the corrector may not leave the θ-ball of radius
//!   [`TRUST_FACTOR`]` x` (largest next step) around the last point (outside it the residual
//!   is NaN, so the attempt fails and the step is halved) — without it Newton sometimes
//!   converged on the far side of an overhang and skipped both folds;
//! - restarts: when the continuation stops on a failed step, it is restarted from the last
//!   point for [`RESTART_POINTS`] points with `θ = `[`THETA_RESTART`] (the arclength then
//!   measures mostly the state, so a branch that reverses in `ω` at a corner is still cut by
//!   the constraint), heading the way `ω` last moved, or the other way when that restart
//!   cannot make a single step; at most [`MAX_RESTARTS`] times;
//! - corner steps (lcp-ssn only, before the restart): where the branch turns by more than
//!   90 degrees at a corner, no arclength hyperplane normal to the incoming direction cuts
//!   the outgoing piece, so every step length fails and a plain restart retraces the
//!   incoming piece. The problem then extrapolates its current piece to the first switch
//!   of the min ahead, and the continuation restarts just past that corner on the
//!   outgoing piece ([`FrequencyLcp::corner_step`]), when that start is within one largest
//!   step, inside the sweep interval, and not within one smallest step of an earlier
//!   corner start (a cycle of pieces); at most [`MAX_CORNER_STEPS`] times, counted in
//!   `restarts` but not against [`MAX_RESTARTS`];
//! - folds are the reversals of `ω` along the accepted points (the core's fold events,
//!   from sign changes of the tangent, also fire where a sharply turning branch flips the
//!   tangent's orientation without any reversal); the core's interpolated fold frequency
//!   is used when it lies beyond the extreme point.
//!
//! The corrector tolerance is [`CORRECTOR_TOLERANCE_FACTOR`] times the scene's Newton
//! tolerance for SSN-HB, so each point is a fixed point of a Newton solve at that
//! tolerance; for penalty HB it is the scene's tolerance itself (a stiff penalty puts the
//! rounding floor of `|F|` within a decade of it).
//!
//! Known limit: penalty-HB branches with a stiff penalty (`k_p >= 1e3` times the contact
//! stiffness scale, the scenes' default is `1e5`) reverse in `ω` many times by small amounts
//! near the contact onset of the canonical rod, and the continuation stalls there
//! (`converged = false`, the reason in `termination`); SSN-HB passes.
//!
//! # Methods
//!
//! - `ssn-hb`, `penalty-hb`: the harmonic-balance problems ([`SsnHb`], [`PenaltyHb`]) with the
//!   scene's linear solver (`structured`: [`StructuredHbSolver`], `dense`: [`FaerDenseLu`]).
//! - `lcp-ssn`: the periodic LCP as the equation [`FrequencyLcp`] in the gaps and forces
//!   `y = (w, z)` at the `Nt` time nodes, `w - q(ω) - A(ω) z = 0`, `min(z, κ w) = 0`
//!   (`κ` = the scene's `c`, default the contact stiffness scale; the force unit of the
//!   arclength), with the active-block solver [`FrequencyLcpSolver`] and the analytic
//!   `dF/dω`; the LCP is rebuilt at each new `ω` (`Nt/2 + 1` sparse LUs, two cached). It
//!   starts from the runner's mesh-sequenced min-map solve at `omega_from`. The tip
//!   extremes are taken on the `Nt` nodes (`u_tip = g - w` when the tip is a contact).
//!   (An earlier attempt on the min-map in `z` alone stalled at the contact onset, where
//!   `z` leaves zero at a corner and the free response is invisible to the arclength; in
//!   `(w, z)` the free response moves `w` and the onset is an ordinary switch of the min.)
//!
//!   The discrete LCP branch has a small fold at many changes of the active set (a node
//!   entering or leaving contact): on the canonical rod with the modified mass the
//!   overhang carries 34 / 60 / 66 reversals of `ω` at `Nt = 128 / 256 / 512`, of width
//!   about 1e-3 / 3e-4 / 1e-4 `ω_1`, all reported in `folds` (every point is a solution
//!   of the LCP at its `ω`, checked in tests/lcp_sweep.rs). The outermost folds and the
//!   peak converge at second order to SSN-HB at high `H` (highest fold 1.03059 / 1.02965 /
//!   1.02942 `ω_1` against 1.02935 at `H = 40`; peak 0.54519 / 0.54342 / 0.54302 against
//!   0.54305).
//!
//!   Measured (canonical rod, modified mass, `[0.5, 2] ω_1`, one run of
//!   `cargo run --release --example lcp_sweep -- 128 256 512`): ssn-hb `H = 20` 73 points,
//!   225 corrector iterations, 0.033 s (`H = 40`: 0.069 s); lcp-ssn `Nt = 128` 175 points,
//!   618 iterations, 0.25 s; `Nt = 256` 324 points, 1224 iterations, 1.02 s; `Nt = 512`
//!   762 points, 3286 iterations, 6.7 s (about 2 ms per corrector iteration, 1.3 ms of
//!   which rebuild the LCP at the new `ω`: `Nt/2 + 1` sparse LUs and the dense `A`).
//!
//!   Known limits (`converged = false`, the reason in `termination`): at `Nt = 1024` the
//!   overhang has a corner every few points where the branch turns by more than 90
//!   degrees; corner steps carry it from 1.0167 to 1.0270 `ω_1` (106 of them on
//!   `[1, 1.04] ω_1`), where the pieces met by the first switch ahead close into a cycle
//!   (two nodes switching almost together) and the sweep stops. With the consistent mass
//!   (massive contact node) the first sharp corner comes right after the contact onset
//!   (0.9825 `ω_1` at `Nt = 128`) and the pieces cycle near 0.9886 `ω_1`, where the sweep
//!   stops; likewise for any contact on a node with mass (mid-span node 10 of the modified
//!   mass rod, alone or with the tip as in `two_contacts.toml`: stops at 0.981 / 0.980
//!   `ω_1`, where SSN-HB `H = 20` passes). There several nodes graze almost together at
//!   the onset (node 10, `Nt = 128`: gaps 8e-5, 1.5e-4, 7e-4 at nodes 8, 9, 7), and the
//!   corrector's first contact point already has node 7 in contact, not node 8; the pieces
//!   then lead back to the free response at the onset, which is retraced. Without an
//!   impact law the trapezoidal periodic LCP of a massive contact node is the ill-posed
//!   case (module `lcp`).
//! - `lcp-lemke`, `march`: [`RunError::Unsupported`]. Lemke's pivoting and time
//!   marching are no equation in `ω` to continue; solve frequency by frequency with
//!   `ssn solve`.

use std::cell::RefCell;
use std::rc::Rc;
use std::time::Instant;

use semismooth::continuation::{
    Continuation, ContinuationCounters, ContinuationError, ContinuationEvent, ContinuationOptions,
    ContinuationTermination, Direction, Predictor,
};
use semismooth::harmonic::{Aft, FourierBasis};
use semismooth::linalg::{FaerDenseLu, LinearSolveError};
use semismooth::newton::{self, NewtonReport};
use semismooth::{GeneralizedJacobian, LinearSolve, ParameterDependent, Residual};
use serde_json::json;

use crate::hb::{HbError, HbOptions, PenaltyHb, PenaltyHbOptions, SsnHb, StructuredHbSolver};
use crate::lcp::{
    solve_min_map_sequenced, FrequencyLcp, FrequencyLcpSolver, PeriodicLcp, PeriodicLcpOptions,
};
use crate::rod::RodModel;
use crate::runner::{newton_options, RunCounters, RunError, HB_OUTPUT_POINTS};
use crate::scene::{
    LinearSolverChoice, Method, SolverSettings, SweepSettings, DEFAULT_RELATIVE_PENALTY,
};

/// Weight `θ` of the state in the arclength (see the module documentation: with the scaling
/// used here any `θ` in `(0, 1)` gives the same geometry; `1/2` keeps both parts of the
/// θ-norm of order one).
pub const THETA: f64 = 0.5;

/// Largest number of corrector iterations per attempted step.
pub const MAX_CORRECTOR_ITERATIONS: usize = 12;

/// The corrector's tolerance on `|F|` relative to the scene's Newton tolerance: one decade
/// tighter, so that every branch point is a fixed point of a Newton solve at the scene's
/// tolerance even where the Jacobian is ill-conditioned (near folds).
pub const CORRECTOR_TOLERANCE_FACTOR: f64 = 0.1;

/// Corrector iterations the step control aims at.
pub const TARGET_ITERATIONS: usize = 4;

/// The corrector may not leave the θ-ball of radius `TRUST_FACTOR * ds_max` around the last
/// accepted point, `ds_max` the largest step the next attempt can take (see `Trust`).
pub const TRUST_FACTOR: f64 = 3.0;

/// `θ` of the short segments restarted after a failed step: nearly all weight on the state,
/// so that the arclength constraint still cuts a branch that reverses in `ω` at a corner
/// (a fold where the contact's active set changes) while its state moves on.
pub const THETA_RESTART: f64 = 0.95;

/// Points of a restarted segment before the main metric is taken again.
pub const RESTART_POINTS: usize = 4;

/// Restarts allowed per sweep.
pub const MAX_RESTARTS: usize = 20;

/// Restarts past a corner (problems with a corner step, see `follow`) allowed per sweep,
/// counted apart from [`MAX_RESTARTS`]: fine LCP meshes have a sharp corner every few
/// points of their overhang.
pub const MAX_CORNER_STEPS: usize = 200;

/// A frequency-response curve: one entry per branch point, in branch order (the frequency
/// is not monotone across folds).
#[derive(Debug, Clone, PartialEq)]
pub struct FrequencyResponse {
    /// Method used.
    pub method: Method,
    /// First natural frequency of the rod (the curve's frequency unit).
    pub omega_1: f64,
    /// Forcing frequency `ω` of each point (absolute).
    pub omega: Vec<f64>,
    /// `max_t u_tip(t)` over one period.
    pub tip_max: Vec<f64>,
    /// `min_t u_tip(t)` over one period.
    pub tip_min: Vec<f64>,
    /// `max_t |u_tip(t)|` over one period.
    pub amplitude: Vec<f64>,
    /// Corrector iterations of each point (the first: those of the start correction).
    pub iterations: Vec<usize>,
    /// Frequencies `ω` (absolute) where the branch turns back, in branch order.
    pub folds: Vec<f64>,
    /// Index of the extreme point at each fold (same order as `folds`).
    pub fold_indices: Vec<usize>,
    /// Whether the branch reached `omega_ratio_to` (the bound at the end of the sweep).
    pub converged: bool,
    /// Why the continuation stopped, in words.
    pub termination: String,
    /// Wall time of the whole computation after the rod was built (reference amplitude,
    /// initial Newton solve, continuation, tip reconstructions).
    pub solve_seconds: f64,
    /// Work counters (initial Newton solve + continuation).
    pub counters: RunCounters,
    /// The continuation's own counters (corrector iterations, rejected steps).
    pub continuation: ContinuationCounters,
    /// Iterations of the initial globalized Newton solve at `omega_from`.
    pub initial_iterations: usize,
    /// Continuation restarts after failed steps, corner steps included (module
    /// documentation).
    pub restarts: usize,
    /// `u_ref` of the step scaling (module documentation).
    pub reference_amplitude: f64,
    /// Tip samples per period used for `tip_max`, `tip_min`, `amplitude`.
    pub output_points: usize,
    /// The method's unknowns at each point (HB coefficients `[U; Lambda]` or `U`, LCP
    /// `[w; z]`), unscaled, for warm starts and re-solves.
    pub states: Vec<Vec<f64>>,
}

impl FrequencyResponse {
    /// Number of branch points.
    pub fn points(&self) -> usize {
        self.omega.len()
    }

    /// `ω / ω_1` of each point.
    pub fn omega_ratio(&self) -> Vec<f64> {
        self.omega.iter().map(|w| w / self.omega_1).collect()
    }

    /// Index and value of the largest amplitude (`None` for an empty curve).
    pub fn peak(&self) -> Option<(usize, f64)> {
        self.amplitude
            .iter()
            .copied()
            .enumerate()
            .fold(None, |best, (i, a)| match best {
                Some((_, b)) if b >= a => best,
                _ => Some((i, a)),
            })
    }

    /// The JSON object of `ssn sweep --json` (issue 6): `points`, `omega`, `tip_max`,
    /// `tip_min`, `amplitude`, `folds`, `converged`, `solve_seconds`, `termination`,
    /// `counters`. Non-finite numbers (never produced by a converged branch) become `null`.
    pub fn to_json(&self) -> serde_json::Value {
        let c = &self.counters;
        json!({
            "points": self.points(),
            "omega": self.omega,
            "tip_max": self.tip_max,
            "tip_min": self.tip_min,
            "amplitude": self.amplitude,
            "folds": self.folds,
            "converged": self.converged,
            "solve_seconds": self.solve_seconds,
            "termination": self.termination,
            "counters": {
                "residual_evaluations": c.residual_evaluations,
                "jacobian_evaluations": c.jacobian_evaluations,
                "factorizations": c.factorizations,
                "linear_solves": c.linear_solves,
                "line_search_backtracks": c.line_search_backtracks,
                "ffts": c.ffts,
                "corrector_iterations": self.continuation.corrector_iterations,
                "rejected_steps": self.continuation.rejected_steps,
                "restarts": self.restarts,
            },
        })
    }
}

/// The ball around the last accepted point outside which the scaled problem refuses to
/// evaluate (its residual is NaN there, which makes the corrector fail and the step halve).
///
/// Pseudo-arclength lands at θ-distance about `ds` from the last point; a corrector that
/// wanders much farther has left for another part of the branch (on these piecewise-smooth
/// problems Newton can converge on the far side of an overhang, skipping the folds).
#[derive(Debug, Default)]
struct Trust {
    center: Vec<f64>,
    center_q: f64,
    radius: f64,
}

/// `F(s ⊙ y, ω_unit q)`: the problem in scaled unknowns `y` and parameter `q`.
struct Scaled<'a, P: ?Sized> {
    inner: &'a mut P,
    scale: &'a [f64],
    omega_unit: f64,
    x: Vec<f64>,
    trust: Rc<RefCell<Trust>>,
}

impl<P: ParameterDependent + ?Sized> Scaled<'_, P> {
    fn unscale(&mut self, y: &[f64]) {
        for ((x, y), s) in self.x.iter_mut().zip(y).zip(self.scale) {
            *x = y * s;
        }
    }

    /// θ-distance of `(y, q)` from the trust center, within the radius.
    fn trusted(&self, y: &[f64]) -> bool {
        let trust = self.trust.borrow();
        if trust.center.len() != y.len() {
            return true;
        }
        let q = self.inner.parameter() / self.omega_unit;
        let dy: f64 = y
            .iter()
            .zip(&trust.center)
            .map(|(a, b)| (a - b) * (a - b))
            .sum();
        let dq = q - trust.center_q;
        let d2 = THETA / y.len() as f64 * dy + (1.0 - THETA) * dq * dq;
        d2 <= trust.radius * trust.radius
    }
}

impl<P: ParameterDependent + ?Sized> Residual for Scaled<'_, P> {
    fn dim(&self) -> usize {
        self.inner.dim()
    }
    fn residual(&mut self, y: &[f64], out: &mut [f64]) {
        if !self.trusted(y) {
            out.fill(f64::NAN);
            return;
        }
        self.unscale(y);
        self.inner.residual(&self.x, out);
    }
    fn fft_count(&self) -> u64 {
        self.inner.fft_count()
    }
}

impl<P: GeneralizedJacobian + ParameterDependent + ?Sized> GeneralizedJacobian for Scaled<'_, P> {
    type Jacobian = P::Jacobian;
    fn new_jacobian(&self) -> P::Jacobian {
        self.inner.new_jacobian()
    }
    /// The Jacobian in `y` is `J(x) diag(s)`; the column scaling is applied by
    /// [`ScaledSolver`], so `J(x)` itself is stored.
    fn jacobian(&mut self, y: &[f64], jac: &mut P::Jacobian) {
        self.unscale(y);
        self.inner.jacobian(&self.x, jac);
    }
}

impl<P: ParameterDependent + ?Sized> ParameterDependent for Scaled<'_, P> {
    fn parameter(&self) -> f64 {
        self.inner.parameter() / self.omega_unit
    }
    fn set_parameter(&mut self, q: f64) {
        self.inner.set_parameter(q * self.omega_unit);
    }
    /// `dF/dq = ω_unit dF/dω`.
    fn residual_parameter_derivative(&mut self, y: &[f64], out: &mut [f64]) {
        self.unscale(y);
        self.inner.residual_parameter_derivative(&self.x, out);
        for o in out.iter_mut() {
            *o *= self.omega_unit;
        }
    }
}

/// Solves `J diag(s) dy = r` as `dy = (J^{-1} r) / s` with the inner solver's factorization.
struct ScaledSolver<'a, S: ?Sized> {
    inner: &'a mut S,
    scale: &'a [f64],
}

impl<J: ?Sized, S: LinearSolve<J> + ?Sized> LinearSolve<J> for ScaledSolver<'_, S> {
    fn factor(&mut self, jac: &J) -> Result<(), LinearSolveError> {
        self.inner.factor(jac)
    }
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        self.inner.solve_in_place(rhs)?;
        for (r, s) in rhs.iter_mut().zip(self.scale) {
            *r /= s;
        }
        Ok(())
    }
}

/// Root mean square over the dofs of the linear response (contacts removed) at `ω_1`
/// (`0.95 ω_1`, then `0.5 ω_1` if that is singular, e.g. undamped); `1` if all fail.
fn reference_amplitude(rod: &RodModel) -> f64 {
    let mut model = rod.model.clone();
    model.contacts.clear();
    let dofs = model.dofs().max(1);
    for ratio in [1.0, 0.95, 0.5] {
        model.forcing.omega = ratio * rod.omega_1;
        let options = PenaltyHbOptions {
            harmonics: 1,
            time_samples: None,
            penalty_stiffness: 1.0,
        };
        let Ok(mut problem) = PenaltyHb::new(&model, &options) else {
            continue;
        };
        let n = problem.dim();
        let x = vec![0.0; n];
        let mut r = vec![0.0; n];
        let mut jac = problem.new_jacobian();
        problem.jacobian(&x, &mut jac);
        problem.residual(&x, &mut r);
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
    RunError::HarmonicBalance(HbError::InvalidOption {
        name,
        value,
        allowed,
    })
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

/// Maps the sweep settings onto continuation options in the scaled unknowns.
fn continuation_options(
    settings: &SolverSettings,
    sweep: &SweepSettings,
    q_unit: f64,
) -> Result<ContinuationOptions, RunError> {
    let (lo, hi) = if sweep.omega_ratio_to > sweep.omega_ratio_from {
        (sweep.omega_ratio_from, sweep.omega_ratio_to)
    } else {
        (sweep.omega_ratio_to, sweep.omega_ratio_from)
    };
    // Halving from max_step down to min_step, plus one attempt at min_step.
    let halvings = (sweep.max_step / sweep.min_step).log2().ceil().max(0.0) as usize + 2;
    let options = ContinuationOptions {
        initial_step: sweep.step,
        min_step: sweep.min_step,
        max_step: sweep.max_step,
        target_iterations: TARGET_ITERATIONS,
        max_corrector_iterations: MAX_CORRECTOR_ITERATIONS,
        corrector_tolerance: match settings.method {
            // A stiff penalty puts the rounding floor of |F| near the tolerance itself.
            Method::PenaltyHb => settings.tolerance,
            _ => CORRECTOR_TOLERANCE_FACTOR * settings.tolerance,
        },
        parameter_min: lo / q_unit,
        parameter_max: hi / q_unit,
        max_points: sweep.max_points,
        max_consecutive_failures: halvings.clamp(3, 64),
        theta: THETA,
        direction: if sweep.omega_ratio_to > sweep.omega_ratio_from {
            Direction::Increasing
        } else {
            Direction::Decreasing
        },
        predictor: Predictor::Secant,
        refine_folds: true,
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
        // Handled by the caller (a non-converged curve); kept total here.
        ContinuationError::StartNotConverged { parameter, .. } => invalid(
            "sweep.omega_ratio_from",
            parameter,
            "a frequency where the start point can be corrected",
        ),
    }
}

fn newton_termination(report: &NewtonReport) -> String {
    use newton::Termination as T;
    match &report.termination {
        T::Converged => "converged".into(),
        T::MaxIterations => "max-iterations".into(),
        T::Stalled => "stalled".into(),
        T::LineSearchFailed => "line-search-failed".into(),
        T::SingularJacobian(e) => format!("singular-jacobian: {e}"),
        T::NonFinite => "non-finite".into(),
    }
}

/// Reduces a state to `(tip_max, tip_min)` over one period.
type TipMeasure<'m, P> = dyn FnMut(&P, &[f64]) -> Result<(f64, f64), RunError> + 'm;

/// A start on the next piece of a piecewise-smooth branch past a corner ahead of the last
/// point `(x, ω)` reached from `(x_prev, ω_prev)` (unscaled): `(x', ω', increasing)`.
/// Called after a failed step (see [`FrequencyLcp::corner_step`]).
type CornerStep<'m, P> =
    dyn FnMut(&mut P, &[f64], f64, &[f64], f64) -> Option<(Vec<f64>, f64, bool)> + 'm;

/// Everything `follow` needs besides the problem and the solver.
struct Setup<'a> {
    settings: &'a SolverSettings,
    sweep: &'a SweepSettings,
    omega_1: f64,
    u_ref: f64,
    dofs: usize,
    /// Per unknown: 1 for displacements, the force unit for forces.
    units: Vec<f64>,
    output_points: usize,
    started: Instant,
    /// Starting guess of the Newton solve at `omega_from` (zero when `None`) and the work
    /// spent computing it.
    start: Option<(Vec<f64>, RunCounters)>,
}

fn follow<P, S>(
    problem: &mut P,
    solver: &mut S,
    setup: Setup<'_>,
    measure: &mut TipMeasure<'_, P>,
    mut corner: Option<&mut CornerStep<'_, P>>,
    progress: Option<&dyn Fn(usize, f64)>,
) -> Result<FrequencyResponse, RunError>
where
    P: GeneralizedJacobian + ParameterDependent,
    S: LinearSolve<P::Jacobian>,
{
    let Setup {
        settings,
        sweep,
        omega_1,
        u_ref,
        dofs,
        units,
        output_points,
        started,
        start,
    } = setup;
    let n = problem.dim();
    // q = (ω/ω_1) / sqrt(1 - θ): (1 - θ) Δq² = Δ(ω/ω_1)².
    let q_unit = (1.0 - THETA).sqrt();
    let omega_unit = q_unit * omega_1;
    let options = continuation_options(settings, sweep, q_unit)?;
    // x = s ⊙ y with s² = θ N u_ref² / n: (θ/n)|Δy|² = |ΔX|² / (N u_ref²).
    let base = (THETA * dofs as f64 / n as f64).sqrt() * u_ref;
    let scale: Vec<f64> = units.iter().map(|u| u * base).collect();

    let omega_from = sweep.omega_ratio_from * omega_1;
    problem.set_parameter(omega_from);
    let (mut x, start_counters) = start.unwrap_or_else(|| (vec![0.0; n], RunCounters::default()));
    let report = newton::solve(problem, solver, &mut x, &newton_options(settings))?;
    let mut counters = RunCounters::from(report.counters);
    add_run_counters(&mut counters, &start_counters);
    let mut response = FrequencyResponse {
        method: settings.method,
        omega_1,
        omega: Vec::new(),
        tip_max: Vec::new(),
        tip_min: Vec::new(),
        amplitude: Vec::new(),
        iterations: Vec::new(),
        folds: Vec::new(),
        fold_indices: Vec::new(),
        converged: false,
        termination: String::new(),
        solve_seconds: 0.0,
        counters,
        continuation: ContinuationCounters::default(),
        initial_iterations: report.iterations,
        restarts: 0,
        reference_amplitude: u_ref,
        output_points,
        states: Vec::new(),
    };
    if !report.converged() {
        response.termination = format!(
            "the start at omega_ratio {} did not converge: {} after {} iterations (|F| = {:e})",
            sweep.omega_ratio_from,
            newton_termination(&report),
            report.iterations,
            report.residual_norm()
        );
        response.solve_seconds = started.elapsed().as_secs_f64();
        return Ok(response);
    }

    let y0: Vec<f64> = x.iter().zip(&scale).map(|(x, s)| x / s).collect();
    let max_step = options.max_step;
    let trust = Rc::new(RefCell::new(Trust::default()));
    let mut scaled = Scaled {
        inner: problem,
        scale: &scale,
        omega_unit,
        x: vec![0.0; n],
        trust: trust.clone(),
    };
    let mut scaled_solver = ScaledSolver {
        inner: solver,
        scale: &scale,
    };
    let q0 = omega_from / omega_unit;
    let base_points = options.max_points;
    // Segments: the main continuation, and after a failure a short one with the state-heavy
    // metric (THETA_RESTART) from the last accepted point, then the main one again.
    let mut start_y = y0;
    let mut start_q = q0;
    let mut direction = options.direction;
    let mut restart = false;
    let mut restarts = 0;
    let mut raw_events: Vec<(usize, f64)> = Vec::new();
    let mut c = ContinuationCounters::default();
    let mut start_failure = None;
    let mut last_tangent_parameter = 0.0;
    let mut corner_starts: Vec<(Vec<f64>, f64)> = Vec::new();
    let termination = loop {
        let offset = response.omega.len();
        let remaining = base_points.saturating_sub(offset);
        let segment_options = ContinuationOptions {
            theta: if restart { THETA_RESTART } else { THETA },
            max_points: if restart {
                RESTART_POINTS + 1
            } else {
                remaining + usize::from(offset > 0)
            }
            .min(remaining + usize::from(offset > 0))
            .max(1),
            direction,
            ..options.clone()
        };
        let mut cont = Continuation::new(
            &mut scaled,
            &mut scaled_solver,
            &start_y,
            start_q,
            segment_options,
        )
        .map_err(continuation_error)?;
        let mut first = true;
        while let Some(item) = cont.next() {
            let point = match item {
                Ok(point) => point,
                Err(ContinuationError::StartNotConverged { failure, .. }) => {
                    start_failure = Some(failure);
                    break;
                }
                Err(e) => return Err(continuation_error(e)),
            };
            {
                // Next attempts: at most 2 * this step (the step control's growth bound).
                let mut t = trust.borrow_mut();
                t.center.clone_from(&point.state);
                t.center_q = point.parameter;
                let next = if point.step > 0.0 {
                    (2.0 * point.step).min(max_step)
                } else {
                    max_step
                };
                t.radius = TRUST_FACTOR * next;
            }
            // The start of a restarted segment repeats the last point.
            if std::mem::take(&mut first) && offset > 0 {
                continue;
            }
            last_tangent_parameter = point.tangent_parameter;
            let state: Vec<f64> = point.state.iter().zip(&scale).map(|(y, s)| y * s).collect();
            let omega = point.parameter * omega_unit;
            let (max, min) = measure(&*cont.problem().inner, &state)?;
            response.omega.push(omega);
            response.tip_max.push(max);
            response.tip_min.push(min);
            response.amplitude.push(max.abs().max(min.abs()));
            response.iterations.push(point.iterations);
            response.states.push(state);
            start_y = point.state;
            start_q = point.parameter;
            if let Some(report) = progress {
                report(response.omega.len() - 1, omega / omega_1);
            }
        }
        let shift = offset.saturating_sub(1);
        for event in cont.events() {
            if let ContinuationEvent::Fold { index, parameter } = event {
                raw_events.push((index + shift, parameter * omega_unit));
            }
        }
        add_counters(&mut c, &cont.counters());
        let termination = cont.termination().cloned();
        drop(cont);
        if start_failure.is_some() {
            break termination;
        }
        let failed = matches!(
            termination,
            Some(
                ContinuationTermination::StepTooSmall { .. }
                    | ContinuationTermination::TooManyFailures { .. }
            )
        );
        let short_done =
            restart && matches!(termination, Some(ContinuationTermination::MaxPoints { .. }));
        if response.omega.len() >= base_points {
            break termination;
        }
        let stuck = failed && restart && response.omega.len() == offset;
        // A corner just ahead where the branch turns by more than 90 degrees (no arclength
        // hyperplane cuts the outgoing piece): restart on the outgoing piece when the
        // problem can tell (the LCP) and the start is within one largest step.
        let k = response.omega.len();
        if let (true, true, Some(step), 2..) = (
            failed,
            corner_starts.len() < MAX_CORNER_STEPS,
            corner.as_mut(),
            k,
        ) {
            let found = step(
                &mut *scaled.inner,
                &response.states[k - 1],
                response.omega[k - 1],
                &response.states[k - 2],
                response.omega[k - 2],
            );
            if let Some((x, w, increasing)) = found {
                let y: Vec<f64> = x.iter().zip(&scale).map(|(x, s)| x / s).collect();
                let q = w / omega_unit;
                let dy: f64 = y.iter().zip(&start_y).map(|(a, b)| (a - b) * (a - b)).sum();
                let d2 = THETA / n as f64 * dy + (1.0 - THETA) * (q - start_q).powi(2);
                // A corner start within one smallest step of an earlier one: the pieces
                // form a cycle, stop stepping.
                let min_step = options.min_step;
                let repeated = corner_starts.iter().any(|(y0, q0): &(Vec<f64>, f64)| {
                    let dy: f64 = y.iter().zip(y0).map(|(a, b)| (a - b) * (a - b)).sum();
                    THETA / n as f64 * dy + (1.0 - THETA) * (q - q0).powi(2) <= min_step * min_step
                });
                let inside = q >= options.parameter_min && q <= options.parameter_max;
                if d2.is_finite() && d2 <= max_step * max_step && !repeated && inside {
                    corner_starts.push((y.clone(), q));
                    restarts += 1;
                    restart = true;
                    start_y = y;
                    start_q = q;
                    direction = if increasing {
                        Direction::Increasing
                    } else {
                        Direction::Decreasing
                    };
                    continue;
                }
            }
        }
        if failed && restarts - corner_starts.len() < MAX_RESTARTS && last_tangent_parameter != 0.0
        {
            restarts += 1;
            restart = true;
        } else if short_done {
            restart = false;
        } else {
            break termination;
        }
        // Keep going the way the branch went (the last increment of ω; the tangent's sign
        // can be flipped where the branch turns sharply). A restart that could not make a
        // single step tries the other orientation (a fold at a corner of the branch).
        let k = response.omega.len();
        let heading = if k >= 2 {
            response.omega[k - 1] - response.omega[k - 2]
        } else {
            last_tangent_parameter
        };
        let forward = if heading >= 0.0 {
            Direction::Increasing
        } else {
            Direction::Decreasing
        };
        direction = match (stuck, direction) {
            (true, Direction::Increasing) => Direction::Decreasing,
            (true, Direction::Decreasing) => Direction::Increasing,
            _ => forward,
        };
    };
    let (folds, indices) = folds_from_branch(&response.omega, &raw_events);
    response.folds = folds;
    response.fold_indices = indices;
    response.restarts = restarts;
    counters.residual_evaluations += c.work.residual_evaluations;
    counters.jacobian_evaluations += c.work.jacobian_evaluations;
    counters.factorizations += c.work.factorizations + c.dense_bordered_factorizations;
    counters.linear_solves += c.work.linear_solves;
    counters.ffts += c.work.ffts;
    response.counters = counters;
    response.continuation = c;
    let to_q = sweep.omega_ratio_to / q_unit;
    let ratio = |q: f64| q * q_unit;
    let (converged, words) = match (&termination, start_failure) {
        (_, Some(failure)) => (
            false,
            format!("the start point could not be corrected: {failure}"),
        ),
        (Some(ContinuationTermination::ReachedBound { parameter, bound }), None) => {
            let reached_end = *bound == to_q;
            let at_bound = *parameter == *bound;
            (
                reached_end,
                format!(
                    "reached omega_ratio {}{}",
                    ratio(*bound),
                    if reached_end {
                        if at_bound {
                            " (the end of the sweep)".to_string()
                        } else {
                            format!(
                                " (the end of the sweep; last point at {} not re-solved on it)",
                                ratio(*parameter)
                            )
                        }
                    } else {
                        " (the start of the sweep: the branch turned back)".to_string()
                    }
                ),
            )
        }
        (Some(ContinuationTermination::MaxPoints { points }), None) => (
            false,
            format!(
                "point limit ({points} points) at omega_ratio {}",
                response.omega.last().map_or(f64::NAN, |w| w / omega_1)
            ),
        ),
        (
            Some(ContinuationTermination::StepTooSmall {
                parameter,
                step,
                failure,
                ..
            }),
            None,
        ) => (
            false,
            format!(
                "step too small at omega_ratio {}: the attempt with step {step:e} failed: {failure}",
                ratio(*parameter)
            ),
        ),
        (
            Some(ContinuationTermination::TooManyFailures {
                parameter,
                failures,
                failure,
                ..
            }),
            None,
        ) => (
            false,
            format!(
                "{failures} failed steps in a row at omega_ratio {}: {failure}",
                ratio(*parameter)
            ),
        ),
        (None, None) => (false, "stopped without a reason".to_string()),
    };
    response.converged = converged;
    response.termination = words;
    response.solve_seconds = started.elapsed().as_secs_f64();
    Ok(response)
}

fn add_run_counters(total: &mut RunCounters, c: &RunCounters) {
    total.residual_evaluations += c.residual_evaluations;
    total.jacobian_evaluations += c.jacobian_evaluations;
    total.factorizations += c.factorizations;
    total.linear_solves += c.linear_solves;
    total.line_search_backtracks += c.line_search_backtracks;
    total.ffts += c.ffts;
}

fn add_counters(total: &mut ContinuationCounters, c: &ContinuationCounters) {
    total.work += c.work;
    total.parameter_derivative_evaluations += c.parameter_derivative_evaluations;
    total.dense_bordered_factorizations += c.dense_bordered_factorizations;
    total.corrector_iterations += c.corrector_iterations;
    total.rejected_iterations += c.rejected_iterations;
    total.rejected_steps += c.rejected_steps;
}

/// Folds as the local extrema of `ω` along the branch (sign changes of its increments).
/// Each is reported at the interpolated fold of a continuation event within one point of
/// it when that lies beyond the extreme point (cubic Hermite refinement), else at the
/// extreme point. Events without a reversal of `ω` (a tangent orientation flipped on a
/// sharply turning branch) are dropped.
fn folds_from_branch(omega: &[f64], events: &[(usize, f64)]) -> (Vec<f64>, Vec<usize>) {
    let mut folds = Vec::new();
    let mut indices = Vec::new();
    let mut last_sign = 0.0;
    let mut last_index = 0;
    for i in 1..omega.len() {
        let inc = omega[i] - omega[i - 1];
        if inc == 0.0 {
            continue;
        }
        let sign = inc.signum();
        if last_sign != 0.0 && sign != last_sign {
            // The extreme is the point before this increment.
            let k = i - 1;
            let w = omega[k];
            let reach = (omega[k] - omega[last_index]).abs().max(inc.abs());
            let refined = events
                .iter()
                .filter(|(index, _)| index.abs_diff(k) <= 2)
                .map(|(_, p)| *p)
                .filter(|p| (p - w) * last_sign >= 0.0 && (p - w).abs() <= reach)
                .fold(w, |best, p| {
                    if (p - best) * last_sign > 0.0 {
                        p
                    } else {
                        best
                    }
                });
            folds.push(refined);
            indices.push(k);
        }
        last_sign = sign;
        last_index = i - 1;
    }
    (folds, indices)
}

/// Reconstructs one dof over a period from HB coefficients (index `j N + dof`).
struct HbTip {
    aft: Aft,
    coeffs: Vec<f64>,
    samples: Vec<f64>,
    dofs: usize,
    dof: usize,
}

impl HbTip {
    fn new(harmonics: usize, points: usize, dofs: usize, dof: usize) -> Result<Self, RunError> {
        let basis = FourierBasis::new(harmonics, points).map_err(HbError::from)?;
        Ok(Self {
            aft: Aft::new(basis),
            coeffs: vec![0.0; 2 * harmonics + 1],
            samples: vec![0.0; points],
            dofs,
            dof,
        })
    }

    fn extremes(&mut self, x: &[f64]) -> Result<(f64, f64), RunError> {
        for (j, c) in self.coeffs.iter_mut().enumerate() {
            *c = x[j * self.dofs + self.dof];
        }
        self.aft
            .to_time(&self.coeffs, &mut self.samples)
            .map_err(HbError::from)?;
        Ok(extremes(&self.samples))
    }
}

fn extremes(samples: &[f64]) -> (f64, f64) {
    samples
        .iter()
        .fold((f64::NEG_INFINITY, f64::INFINITY), |(hi, lo), v| {
            (hi.max(*v), lo.min(*v))
        })
}

/// Frequency-response curve of the rod with the scene's method (module documentation):
/// globalized Newton at `omega_ratio_from`, then pseudo-arclength continuation in `ω` up to
/// `omega_ratio_to`. `progress(index, omega_ratio)` is called after each accepted point.
///
/// `Err` when the sweep could not start (bad settings, unsupported method, a model the
/// method cannot build); a branch that stopped early is an `Ok` curve with
/// `converged = false` and the reason in `termination`.
pub fn frequency_response(
    rod: &RodModel,
    settings: &SolverSettings,
    sweep: &SweepSettings,
    progress: Option<&dyn Fn(usize, f64)>,
) -> Result<FrequencyResponse, RunError> {
    check_sweep(sweep)?;
    let started = Instant::now();
    let model = &rod.model;
    let tip = rod.tip_dof();
    let dofs = model.dofs();
    let omega_1 = rod.omega_1;
    let u_ref = reference_amplitude(rod);
    let output_points = HB_OUTPUT_POINTS.max(settings.time_samples);
    let setup = |units: Vec<f64>, output_points: usize| Setup {
        settings,
        sweep,
        omega_1,
        u_ref,
        dofs,
        units,
        output_points,
        started,
        start: None,
    };
    match settings.method {
        Method::SsnHb => {
            let options = HbOptions {
                harmonics: settings.harmonics,
                time_samples: Some(settings.time_samples),
                c: settings.c,
            };
            let mut problem = SsnHb::new(model, &options)?;
            let split = problem.displacement_len();
            let c = problem.c();
            let units = (0..problem.dim())
                .map(|i| if i < split { 1.0 } else { c })
                .collect();
            let mut tip_rec = HbTip::new(settings.harmonics, output_points, dofs, tip)?;
            let mut measure = |_: &SsnHb, x: &[f64]| tip_rec.extremes(x);
            let setup = setup(units, output_points);
            match settings.linear_solver {
                LinearSolverChoice::Structured => follow(
                    &mut problem,
                    &mut StructuredHbSolver::new(),
                    setup,
                    &mut measure,
                    None,
                    progress,
                ),
                LinearSolverChoice::Dense => follow(
                    &mut problem,
                    &mut FaerDenseLu::new(),
                    setup,
                    &mut measure,
                    None,
                    progress,
                ),
            }
        }
        Method::PenaltyHb => {
            let options = PenaltyHbOptions {
                harmonics: settings.harmonics,
                time_samples: Some(settings.time_samples),
                penalty_stiffness: settings
                    .penalty_stiffness
                    .unwrap_or(DEFAULT_RELATIVE_PENALTY * model.contact_stiffness_scale()),
            };
            let mut problem = PenaltyHb::new(model, &options)?;
            let units = vec![1.0; problem.dim()];
            let mut tip_rec = HbTip::new(settings.harmonics, output_points, dofs, tip)?;
            let mut measure = |_: &PenaltyHb, x: &[f64]| tip_rec.extremes(x);
            let setup = setup(units, output_points);
            match settings.linear_solver {
                LinearSolverChoice::Structured => follow(
                    &mut problem,
                    &mut StructuredHbSolver::new(),
                    setup,
                    &mut measure,
                    None,
                    progress,
                ),
                LinearSolverChoice::Dense => follow(
                    &mut problem,
                    &mut FaerDenseLu::new(),
                    setup,
                    &mut measure,
                    None,
                    progress,
                ),
            }
        }
        Method::LcpSsn => {
            if model.contacts.is_empty() {
                return Err(RunError::Unsupported {
                    method: "lcp-ssn",
                    what: "a [contact] section (the periodic LCP is posed on the contact \
                           forces; sweep a linear scene with ssn-hb or penalty-hb)",
                });
            }
            let kappa = settings.c.unwrap_or(model.contact_stiffness_scale());
            let lcp_options = PeriodicLcpOptions {
                time_samples: settings.time_samples,
                observed_dofs: Vec::new(),
            };
            // Start: the runner's sequenced min-map solve at omega_from, y0 = (q + A z, z).
            let mut start_model = model.clone();
            start_model.forcing.omega = sweep.omega_ratio_from * omega_1;
            let sequenced = solve_min_map_sequenced(
                &start_model,
                lcp_options.clone(),
                &newton_options(settings),
            )?;
            let mut start_counters = RunCounters::default();
            for level in &sequenced.levels {
                add_run_counters(&mut start_counters, &level.report.counters.into());
            }
            let mut problem = FrequencyLcp::new(&start_model, lcp_options, kappa)?;
            let y0 = problem.state_from_forces(&sequenced.z)?;
            let half = problem.half();
            let units = (0..problem.dim())
                .map(|i| if i < half { 1.0 } else { kappa })
                .collect();
            // u_tip = g - w on the nodes when the tip is a contact dof; otherwise the tip's
            // history from an LCP at the point's frequency with the tip observed.
            let contacts = model.contact_count();
            let tip_contact = model.contacts.iter().position(|c| c.dof == tip);
            let gap = tip_contact.map_or(0.0, |c| model.contacts[c].gap);
            let time_samples = settings.time_samples;
            let mut measure = |p: &FrequencyLcp, y: &[f64]| -> Result<(f64, f64), RunError> {
                let half = p.half();
                match tip_contact {
                    Some(c) => {
                        let tip: Vec<f64> = (0..time_samples)
                            .map(|n| gap - y[n * contacts + c])
                            .collect();
                        Ok(extremes(&tip))
                    }
                    None => {
                        let mut m = model.clone();
                        m.forcing.omega = p.parameter();
                        let options = PeriodicLcpOptions {
                            time_samples,
                            observed_dofs: vec![tip],
                        };
                        let lcp = PeriodicLcp::new(&m, options)?;
                        let u = lcp.displacements(&y[half..])?;
                        Ok(extremes(&u[0]))
                    }
                }
            };
            let mut corner_step =
                |p: &mut FrequencyLcp, y: &[f64], omega: f64, y_prev: &[f64], omega_prev: f64| {
                    p.corner_step(y, omega, y_prev, omega_prev)
                };
            let setup = Setup {
                start: Some((y0, start_counters)),
                ..setup(units, settings.time_samples)
            };
            follow(
                &mut problem,
                &mut FrequencyLcpSolver::new(),
                setup,
                &mut measure,
                Some(&mut corner_step),
                progress,
            )
        }
        Method::LcpLemke => Err(RunError::Unsupported {
            method: "lcp-lemke",
            what: "a method continuable in omega (Lemke's pivoting is not a smooth equation): \
                   sweep with ssn-hb or penalty-hb, or solve frequency by frequency \
                   with `ssn solve`",
        }),
        Method::March => Err(RunError::Unsupported {
            method: "march",
            what: "a method continuable in omega (time marching has no equation to continue): \
                   sweep with ssn-hb or penalty-hb, or march frequency by frequency \
                   with `ssn solve`",
        }),
    }
}
