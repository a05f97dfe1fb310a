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
//! along them), with corners and folds at corners. Four measures on this side of the core:
//!
//! - a trust ball: the corrector may not leave the θ-ball of radius
//!   [`TRUST_FACTOR`]` x` (largest next step) around the last point (outside it the residual
//!   is NaN, so the attempt fails and the step is halved) — without it Newton sometimes
//!   converged on the far side of an overhang and skipped both folds;
//! - restarts: when the continuation stops on a failed step, it is restarted from the last
//!   point for [`RESTART_POINTS`] points with `θ = `[`THETA_RESTART`] (the arclength then
//!   measures mostly the state, so a branch that reverses in `ω` at a corner is still cut by
//!   the constraint), heading the way `ω` last moved, or the other way when that restart
//!   cannot make a single step; at most [`MAX_RESTARTS`] times. A restarted segment that
//!   goes back along the branch (one of its points within a quarter of `|x_j - x_last|` of
//!   one of the [`RETRACE_WINDOW`] points `x_j` before the restart point `x_last`) is cut
//!   there and the sweep stops, "stalled at omega_ratio ...": a branch returned twice, the
//!   second time backwards, would be garbage;
//! - penalty HB: corners crossed explicitly (below);
//! - folds are found by the core's [`FoldDetector`] over the whole stitched branch (a fold
//!   can fall between two segments): reversals of `ω` along the accepted points, located by
//!   Hermite interpolation where the tangent's `ω` component changes sign across them; a
//!   sign change of the tangent alone (a generalized Jacobian from the far side of a
//!   corner) is no fold. Corners recorded by the penalty path carry no tangent, so a fold
//!   there is the corner itself.
//!
//! The core's own corner passes ([`ContinuationOptions::pass_corners`]) are tried first,
//! before a segment gives up; the restarts above come after them.
//!
//! The corrector tolerance is [`CORRECTOR_TOLERANCE_FACTOR`] times the scene's Newton
//! tolerance for SSN-HB, so each point is a fixed point of a Newton solve at that
//! tolerance. For penalty HB it is the scene's tolerance or the rounding floor of `|F|`,
//! `ε k_p max(|g|, u_ref)` (the penalty force is `k_p` times gaps computed to `ε |u|`),
//! whichever is larger: at the default penalty on the canonical rod the floor is 3.3e-10
//! and a solution's `|F|` measures 1.5e-11 to 4.4e-11; from `k_p = 1e6 x` on, a fixed
//! tolerance of 1e-10 is below the floor and the corrector stalls (measured: `|F| = 2.1e-10`
//! at `k_p = 1e6 x`, `H = 5`).
//!
//! ## Penalty-HB branches: corners crossed explicitly
//!
//! With the active samples fixed, the penalty residual is affine in `U`: the branch is a
//! chain of pieces, each a graph over `ω`, joined at corners where a sample's gap changes
//! sign, and every fold of a penalty branch is a corner. With a stiff penalty the contact
//! moves from sample to sample as `ω` changes and the branch zigzags: on the canonical rod
//! (gap 0.5, default `k_p = 1e5 x` the contact stiffness scale) 48 corners and 44 folds at
//! `H = 5`, 670 and 646 at `H = 20` (1570 and 1510 with gap 0.25). They are features of
//! the penalty branch, not corrector artefacts: before corners were crossed explicitly,
//! `max_step = 2e-3` and `5e-4` (instead of `5e-2`) stalled after the same reversals at
//! the same frequencies (1.00448 -> 1.00350 and 1.00977 -> 1.00767 `ω_1`, then 1.01447);
//! now any `max_step` gives the same folds (44 to 6e-10 with `5e-2`, `2e-3` and `5e-4`;
//! 646 at `H = 20` to 1.3e-10 with `5e-2`, `1e-2` and `2e-3`). Some corners turn by more
//! than a right angle in the arclength metric (93.6° at `ω = 1.01447 ω_1`, `H = 5`, where
//! the two-sample piece meets the one-sample piece going back): the arclength constraint
//! then has no solution on the next piece at any step, and the sweep used to end there
//! with `converged = false` (after 20 restarts, or retracing the branch back to
//! `omega_from`). Scaling the force harmonics into the metric does not help (the turn
//! stays above 90°, 108° at weight 100).
//!
//! So a penalty sweep watches the active samples of each accepted point (`corners.rs`):
//! when they change, or when a segment stops on failed steps (after
//! [`PENALTY_MAX_FAILURES`] halvings), the corner ahead is located exactly on the current
//! piece (Newton in `ω` on the crossing sample's gap, each iterate one linear solve of the
//! affine piece), the sample is flipped, and the branch goes on along the new piece in the
//! `ω` direction where it is consistent — walking on from corner to corner while they are
//! closer than one largest step, then restarting the continuation a short way along the
//! first long piece (or from the continuation's own point when it already lies there,
//! heading away from the corner). Corners are branch points (`iterations = 0`), and the
//! folds of a penalty branch are its extreme corners (the core's interpolated fold, which
//! assumes a smooth turn, is not used). Measured with the sweep settings of
//! `tests/frequency_response.rs` (release, 2 shared cores): the four canonical cases above
//! reach `omega_ratio_to = 2` in 0.05-0.1, 0.1-0.2, 0.4-0.7 and 1.0 s (1356, 3260, 2777 and
//! 6185 factorizations), and the branch converges like `1/k_p` (jump-down frequency and
//! peak change by 4e-4 and 7e-4 from `k_p = 1e3` to `1e4 x`, by 4e-5 and 7e-5 from `1e4`
//! to `1e5 x`). Its limit is not the SSN-HB branch at the same `H` (contact imposed at the
//! `Nt` samples instead of on the `2H + 1`-term projection): jump-down 1.0518 against
//! 1.0414 `ω_1` at `H = 5`, 1.0293 against 1.0276 at `H = 20`, both approaching SSN-HB at
//! `H = 40` (1.0278).
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
//!   Known limits (`converged = false`, the reason in `termination`): a contact on a node
//!   with mass. With the consistent mass the branch has a corner right after the contact
//!   onset that neither the arclength, the core's corner passes nor the restarts turn;
//!   the sweep stops there ("stalled at omega_ratio 0.9825", `Nt = 128`; before the
//!   retrace check below it went back along the branch to `omega_from`). Likewise with
//!   the mid-span node 10 in contact (`two_contacts.toml` as an lcp-ssn scene, `Nt = 128`:
//!   stalled at 0.9788 `ω_1`, where SSN-HB `H = 20` passes): several nodes graze almost
//!   together at the onset (gaps 8e-5, 1.5e-4, 7e-4 at nodes 8, 9, 7) and the pieces lead
//!   back to the free response. Without an impact law the trapezoidal periodic LCP of a
//!   massive contact node is the ill-posed case (module `lcp`). At `Nt = 1024` (modified
//!   mass) the overhang has a sharp corner every few points and the sweep stalls at 1.0167
//!   `ω_1` (1573 points, 70 s on `[1, 1.04] ω_1`); an explicit step to the neighbouring
//!   piece of the LCP (extrapolating the current piece to its first switch, as
//!   `sweep/corners.rs` does for the penalty) carried it to 1.0270 `ω_1` in an experiment,
//!   where the pieces closed into a cycle (two nodes switching almost together).
//! - `lcp-lemke`, `march`: [`RunError::Unsupported`]. Lemke's pivoting and time
//!   marching are no equation in `ω` to continue; solve frequency by frequency with
//!   `ssn solve`.

use std::cell::RefCell;
use std::rc::Rc;
use std::time::Instant;

use semismooth::continuation::{
    Continuation, ContinuationCounters, ContinuationError, ContinuationEvent, ContinuationOptions,
    ContinuationTermination, Direction, FoldDetector, Predictor,
};
use semismooth::harmonic::{Aft, FourierBasis};
use semismooth::linalg::{FaerDenseLu, LinearSolveError};
use semismooth::newton::{self, WorkCounters};
use semismooth::{
    EvaluationError, Factorize, GeneralizedJacobian, LinearSolve, ParameterDependent,
    ProblemCounters, Residual,
};
use serde_json::json;

mod corners;

use corners::{Corners, PenaltyCorners};

use crate::hb::{
    HbError, HbJacobian, HbOptions, PenaltyHb, PenaltyHbOptions, SsnHb, StructuredHbSolver,
};
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

/// Points before a restart against which the restarted segment's points are checked for
/// going back along the branch.
pub const RETRACE_WINDOW: usize = 8;

/// Failed steps in a row (each halving the step) after which a penalty-HB continuation
/// segment stops and the corner ahead is crossed explicitly (module documentation).
pub const PENALTY_MAX_FAILURES: usize = 3;

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
    /// Corners of a penalty branch stepped over explicitly (module documentation).
    pub corners: usize,
    /// `u_ref` of the step scaling (module documentation).
    pub reference_amplitude: f64,
    /// Tip samples per period used for `tip_max`, `tip_min`, `amplitude`.
    pub output_points: usize,
    /// The method's unknowns at each point (HB coefficients `[U; Lambda]` or `U`, LCP
    /// `[w; z]`), unscaled, for warm starts and re-solves.
    pub states: Vec<Vec<f64>>,
}

impl FrequencyResponse {
    fn push(&mut self, omega: f64, max: f64, min: f64, iterations: usize, state: Vec<f64>) {
        self.omega.push(omega);
        self.tip_max.push(max);
        self.tip_min.push(min);
        self.amplitude.push(max.abs().max(min.abs()));
        self.iterations.push(iterations);
        self.states.push(state);
    }

    /// Keeps the first `len` points, and the folds confirmed by them (a fold at the last
    /// kept point needs a point after it).
    fn truncate(&mut self, len: usize) {
        self.omega.truncate(len);
        self.tip_max.truncate(len);
        self.tip_min.truncate(len);
        self.amplitude.truncate(len);
        self.iterations.truncate(len);
        self.states.truncate(len);
        let keep = self
            .fold_indices
            .iter()
            .take_while(|&&i| i + 1 < len)
            .count();
        self.folds.truncate(keep);
        self.fold_indices.truncate(keep);
    }

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
                "corner_passes": self.continuation.corner_passes,
                "restarts": self.restarts,
                "corners": self.corners,
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
    fn residual(&mut self, y: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        if !self.trusted(y) {
            return Err(EvaluationError::OutsideDomain {
                what: "distance from the last branch point beyond the trust radius",
                value: f64::INFINITY,
            });
        }
        self.unscale(y);
        self.inner.residual(&self.x, out)
    }
    fn problem_counters(&self) -> ProblemCounters {
        self.inner.problem_counters()
    }
}

impl<P: GeneralizedJacobian + ParameterDependent + ?Sized> GeneralizedJacobian for Scaled<'_, P> {
    type Jacobian = P::Jacobian;
    fn new_jacobian(&self) -> P::Jacobian {
        self.inner.new_jacobian()
    }
    /// The Jacobian in `y` is `J(x) diag(s)`; the column scaling is applied by
    /// [`ScaledSolver`], so `J(x)` itself is stored.
    fn jacobian(&mut self, y: &[f64], jac: &mut P::Jacobian) -> Result<(), EvaluationError> {
        self.unscale(y);
        self.inner.jacobian(&self.x, jac)
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
    fn residual_parameter_derivative(
        &mut self,
        y: &[f64],
        out: &mut [f64],
    ) -> Result<(), EvaluationError> {
        self.unscale(y);
        self.inner.residual_parameter_derivative(&self.x, out)?;
        for o in out.iter_mut() {
            *o *= self.omega_unit;
        }
        Ok(())
    }
}

/// Solves `J diag(s) dy = r` as `dy = (J^{-1} r) / s` with the inner solver's factorization.
struct ScaledSolver<'a, S: ?Sized> {
    inner: &'a mut S,
    scale: &'a [f64],
}

impl<J: ?Sized, S: Factorize<J> + ?Sized> Factorize<J> for ScaledSolver<'_, S> {
    fn factor(&mut self, jac: &J) -> Result<(), LinearSolveError> {
        self.inner.factor(jac)
    }
}

impl<S: LinearSolve + ?Sized> LinearSolve for ScaledSolver<'_, S> {
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

/// Maps the sweep settings onto continuation options in the scaled unknowns.
fn continuation_options(
    settings: &SolverSettings,
    sweep: &SweepSettings,
    q_unit: f64,
    residual_floor: f64,
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
            // |F| cannot be computed below its rounding floor (a stiff penalty puts it
            // near the scene's tolerance).
            Method::PenaltyHb => settings.tolerance.max(residual_floor),
            _ => CORRECTOR_TOLERANCE_FACTOR * settings.tolerance,
        },
        parameter_min: lo / q_unit,
        parameter_max: hi / q_unit,
        max_points: sweep.max_points,
        max_consecutive_failures: match settings.method {
            // A failed step on a penalty branch is a corner, crossed explicitly.
            Method::PenaltyHb => PENALTY_MAX_FAILURES,
            _ => halvings.clamp(3, 64),
        },
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

/// Reduces a state to `(tip_max, tip_min)` over one period.
type TipMeasure<'m, P> = dyn FnMut(&P, &[f64]) -> Result<(f64, f64), RunError> + 'm;

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
    /// Rounding floor of `|F|` (0 where negligible): the corrector tolerance is at least this.
    residual_floor: f64,
    /// Starting guess of the Newton solve at `omega_from` (zero when `None`) and the work
    /// spent computing it.
    start: Option<(Vec<f64>, WorkCounters)>,
}

fn follow<P, S>(
    problem: &mut P,
    solver: &mut S,
    setup: Setup<'_>,
    measure: &mut TipMeasure<'_, P>,
    mut corners: Option<&mut dyn Corners>,
    progress: Option<&dyn Fn(usize, f64)>,
) -> Result<FrequencyResponse, RunError>
where
    P: GeneralizedJacobian + ParameterDependent,
    S: Factorize<P::Jacobian>,
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
        residual_floor,
        start,
    } = setup;
    let n = problem.dim();
    // q = (ω/ω_1) / sqrt(1 - θ): (1 - θ) Δq² = Δ(ω/ω_1)².
    let q_unit = (1.0 - THETA).sqrt();
    let omega_unit = q_unit * omega_1;
    let options = continuation_options(settings, sweep, q_unit, residual_floor)?;
    // x = s ⊙ y with s² = θ N u_ref² / n: (θ/n)|Δy|² = |ΔX|² / (N u_ref²).
    let base = (THETA * dofs as f64 / n as f64).sqrt() * u_ref;
    let scale: Vec<f64> = units.iter().map(|u| u * base).collect();

    let omega_from = sweep.omega_ratio_from * omega_1;
    problem.set_parameter(omega_from);
    let (mut x, mut work) = start.unwrap_or_else(|| (vec![0.0; n], WorkCounters::default()));
    let report = newton::solve(problem, solver, &mut x, &newton_options(settings))
        .or_else(newton::NewtonError::into_report)?;
    work += report.counters;
    let mut counters = RunCounters::from(work);
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
        corners: 0,
        reference_amplitude: u_ref,
        output_points,
        states: Vec::new(),
    };
    if !report.converged() {
        response.termination = format!(
            "the start at omega_ratio {} did not converge: {} after {} iterations (|F| = {:e})",
            sweep.omega_ratio_from,
            report.termination,
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
    // Folds along the whole stitched branch (a fold can fall between two segments).
    // Penalty folds are corners, recorded exactly: no smooth-turn interpolation there.
    let mut fold_detector = FoldDetector::new(corners.is_none());
    let mut c = ContinuationCounters::default();
    let mut start_failure = None;
    let mut last_tangent_parameter = 0.0;
    // Where the sweep stopped because a restart went back along the branch.
    let mut retraced: Option<f64> = None;
    // After a corner the segment starts at a new point (otherwise at the last one).
    let mut new_start = false;
    let mut crossed = 0;
    let mut corner_work = newton::WorkCounters::default();
    // Penalty: the smooth piece of the last recorded point and the way ω goes along it.
    let mut piece: Option<Vec<bool>> = None;
    let mut travel = direction_sign(direction);
    let termination = loop {
        let offset = response.omega.len();
        let remaining = base_points.saturating_sub(offset);
        let repeat = usize::from(offset > 0 && !new_start);
        let segment_options = ContinuationOptions {
            theta: if restart { THETA_RESTART } else { THETA },
            max_points: if restart {
                RESTART_POINTS + 1
            } else {
                remaining + repeat
            }
            .min(remaining + repeat)
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
        // Whether the segment's first point (a repeat of the last one) is still to come, and
        // where the segment stopped to let the next one start after a corner.
        let mut skip_first = repeat > 0;
        let mut next: Option<(Vec<f64>, f64, Direction, bool)> = None;
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
            if std::mem::take(&mut skip_first) {
                continue;
            }
            let state: Vec<f64> = point.state.iter().zip(&scale).map(|(y, s)| y * s).collect();
            let omega = point.parameter * omega_unit;
            // Penalty: a point on another piece means a corner was passed. It is located
            // and recorded; the continuation goes on unless it would head back to it.
            let mut corner_points = Vec::new();
            if let Some(c) = corners.as_mut() {
                let mut label = c.piece(&state);
                let k = response.omega.len();
                match piece.as_ref() {
                    Some(last) if *last != label && k > 0 => {
                        let walk = c.cross(
                            &response.states[k - 1],
                            response.omega[k - 1],
                            travel,
                            remaining,
                            &mut corner_work,
                        );
                        if let Some(walk) = walk {
                            crossed += walk.corners.len();
                            let along = direction_sign(walk.direction);
                            let start_label = c.piece(&walk.start);
                            if walk.corners.len() > 1 || start_label != label {
                                // Several corners passed: go on after the last.
                                label = start_label;
                                next = Some((walk.start, walk.start_omega, walk.direction, true));
                            } else if (omega - response.omega[k - 1]) * along < 0.0 {
                                // The continuation would head back to the corner.
                                next = Some((state.clone(), omega, walk.direction, false));
                            }
                            corner_points = walk.corners;
                            travel = along;
                        } else {
                            travel = (omega - response.omega[k - 1]).signum();
                        }
                    }
                    Some(_) if k > 0 && omega != response.omega[k - 1] => {
                        travel = (omega - response.omega[k - 1]).signum();
                    }
                    _ => {}
                }
                piece = Some(label);
            }
            record_corners(
                &mut response,
                &mut fold_detector,
                measure,
                &*cont.problem().inner,
                corner_points,
                omega_unit,
                progress,
            )?;
            if matches!(next, Some((_, _, _, true))) {
                break;
            }
            last_tangent_parameter = point.tangent_parameter;
            let (max, min) = measure(&*cont.problem().inner, &state)?;
            response.push(omega, max, min, point.iterations, state);
            record_fold(
                &mut response,
                &mut fold_detector,
                omega,
                point.tangent_parameter,
                point.step,
                omega_unit,
            );
            start_y = point.state;
            start_q = point.parameter;
            if let Some(report) = progress {
                report(response.omega.len() - 1, omega / omega_1);
            }
            if next.is_some() {
                break;
            }
        }
        c += cont.counters();
        let termination = cont.termination().cloned();
        drop(cont);
        // A restarted segment must not go back along the branch. A point of it is taken as
        // going back when it is within a quarter of `|x_j - x_last|` of a point `x_j` among
        // the few before the restart point `x_last` (a genuine turn that close is sharper
        // than 165°).
        if restart && offset >= 2 {
            let distance = |i: usize, j: usize| {
                let dy: f64 = response.states[i]
                    .iter()
                    .zip(&response.states[j])
                    .zip(&scale)
                    .map(|((a, b), s)| ((a - b) / s).powi(2))
                    .sum();
                let dq = (response.omega[i] - response.omega[j]) / omega_unit;
                (THETA / n as f64 * dy + (1.0 - THETA) * dq * dq).sqrt()
            };
            let back = (offset..response.omega.len()).find(|&i| {
                (offset.saturating_sub(RETRACE_WINDOW)..offset - 1)
                    .any(|j| distance(i, j) < 0.25 * distance(j, offset - 1))
            });
            if let Some(i) = back {
                response.truncate(i);
                retraced = Some(response.omega[offset - 1]);
                break termination;
            }
        }
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
        // Penalty: a failed step at a corner (one the arclength cannot turn, e.g. a fold
        // where the next piece leaves at more than a right angle) is crossed explicitly.
        if let (true, None, Some(c)) = (failed, &next, corners.as_mut()) {
            let k = response.omega.len();
            if let Some(walk) = c.cross(
                &response.states[k - 1],
                response.omega[k - 1],
                travel,
                base_points.saturating_sub(k),
                &mut corner_work,
            ) {
                crossed += walk.corners.len();
                record_corners(
                    &mut response,
                    &mut fold_detector,
                    measure,
                    &*scaled.inner,
                    walk.corners,
                    omega_unit,
                    progress,
                )?;
                piece = Some(c.piece(&walk.start));
                travel = direction_sign(walk.direction);
                next = Some((walk.start, walk.start_omega, walk.direction, true));
            }
        }
        if let Some((x, w, d, fresh)) = next {
            start_y = x.iter().zip(&scale).map(|(x, s)| x / s).collect();
            start_q = w / omega_unit;
            direction = d;
            restart = false;
            new_start = fresh;
            let mut t = trust.borrow_mut();
            t.center.clone_from(&start_y);
            t.center_q = start_q;
            t.radius = TRUST_FACTOR * max_step;
            continue;
        }
        new_start = false;
        let stuck = failed && restart && response.omega.len() == offset;
        if failed && restarts < MAX_RESTARTS && last_tangent_parameter != 0.0 {
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

        travel = direction_sign(direction);
    };
    response.restarts = restarts;
    response.corners = crossed;
    if let Some(c) = corners.as_ref() {
        corner_work.problem.add("ffts", c.ffts());
    }
    c.work += corner_work;
    counters.residual_evaluations += c.work.residual_evaluations;
    counters.jacobian_evaluations += c.work.jacobian_evaluations;
    counters.factorizations += c.work.factorizations + c.dense_bordered_factorizations;
    counters.linear_solves += c.work.linear_solves;
    counters.ffts += c.work.problem.get("ffts");
    response.counters = counters;
    response.continuation = c;
    let to_q = sweep.omega_ratio_to / q_unit;
    let ratio = |q: f64| q * q_unit;
    let (converged, words) = match (&termination, start_failure) {
        (_, Some(failure)) => (
            false,
            format!("the start point could not be corrected: {failure}"),
        ),
        (_, None) if retraced.is_some() => (
            false,
            format!(
                "stalled at omega_ratio {}: no step ahead (a corner the continuation cannot \
                 turn), and the only step found goes back along the branch",
                retraced.unwrap_or(f64::NAN) / omega_1
            ),
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

fn direction_sign(direction: Direction) -> f64 {
    match direction {
        Direction::Increasing => 1.0,
        Direction::Decreasing => -1.0,
    }
}

/// Records corners stepped over explicitly (state and `ω` each) as branch points: their
/// tip extremes, their folds (a corner has no tangent: a fold there is the corner itself),
/// and the progress report.
fn record_corners<P: ?Sized>(
    response: &mut FrequencyResponse,
    detector: &mut FoldDetector,
    measure: &mut TipMeasure<'_, P>,
    problem: &P,
    corners: Vec<(Vec<f64>, f64)>,
    omega_unit: f64,
    progress: Option<&dyn Fn(usize, f64)>,
) -> Result<(), RunError> {
    for (x, w) in corners {
        let (max, min) = measure(problem, &x)?;
        response.push(w, max, min, 0, x);
        record_fold(response, detector, w, 0.0, 0.0, omega_unit);
        if let Some(report) = progress {
            report(response.omega.len() - 1, w / response.omega_1);
        }
    }
    Ok(())
}

/// Feeds the point just pushed (at `omega`, with the tangent's scaled-parameter component
/// and the chord from the previous point; both 0 for a corner, which has no tangent) to the
/// fold detector, recording a fold it confirms.
fn record_fold(
    response: &mut FrequencyResponse,
    detector: &mut FoldDetector,
    omega: f64,
    tangent_parameter: f64,
    chord: f64,
    omega_unit: f64,
) {
    if let Some(ContinuationEvent::Fold { index, parameter }) =
        detector.push(omega / omega_unit, tangent_parameter, chord)
    {
        response.folds.push(parameter * omega_unit);
        response.fold_indices.push(index);
    }
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
    let setup = |units: Vec<f64>, output_points: usize, residual_floor: f64| Setup {
        settings,
        sweep,
        omega_1,
        u_ref,
        dofs,
        units,
        output_points,
        started,
        residual_floor,
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
            let setup = setup(units, output_points, 0.0);
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
            // The penalty force is k_p times gaps computed to ε |u| (|u| ~ the gap in contact).
            let gap = model
                .contacts
                .iter()
                .map(|c| c.gap.abs())
                .fold(u_ref, f64::max);
            let floor = f64::EPSILON * options.penalty_stiffness * gap;
            let setup = setup(units, output_points, floor);
            // A corner is searched within one largest step of the last point, and the next
            // piece is entered at most a quarter of the first step from it (in ω).
            let solver: Box<dyn Factorize<HbJacobian>> = match settings.linear_solver {
                LinearSolverChoice::Structured => Box::new(StructuredHbSolver::new()),
                LinearSolverChoice::Dense => Box::new(FaerDenseLu::new()),
            };
            let mut corners = PenaltyCorners {
                problem: PenaltyHb::new(model, &options)?,
                solver,
                reach: sweep.max_step * omega_1,
                shift: 0.25 * sweep.step * omega_1,
                walk: sweep.max_step,
                omega_1,
                unit: (dofs as f64).sqrt() * u_ref,
            };
            match settings.linear_solver {
                LinearSolverChoice::Structured => follow(
                    &mut problem,
                    &mut StructuredHbSolver::new(),
                    setup,
                    &mut measure,
                    Some(&mut corners),
                    progress,
                ),
                LinearSolverChoice::Dense => follow(
                    &mut problem,
                    &mut FaerDenseLu::new(),
                    setup,
                    &mut measure,
                    Some(&mut corners),
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
                &PeriodicLcp::new(&start_model, lcp_options.clone())?,
                &newton_options(settings),
            )?;
            let mut start_counters = WorkCounters::default();
            for level in &sequenced.levels {
                start_counters += level.report.counters;
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
            let setup = Setup {
                start: Some((y0, start_counters)),
                ..setup(units, settings.time_samples, 0.0)
            };
            follow(
                &mut problem,
                &mut FrequencyLcpSolver::new(),
                setup,
                &mut measure,
                None,
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
