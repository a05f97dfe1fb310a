//! Pseudo-arclength continuation of a branch of solutions of `F(x, p) = 0`, and a
//! natural-parameter sweep to compare it with.
//!
//! # The method
//!
//! Points `y = (x, p)` of the branch are measured with the weighted inner product
//! (BifurcationKit's `theta`, see Keller 1977 and Doedel's AUTO notes)
//!
//! ```text
//! <(a, α), (b, β)>_θ = (θ / n) a·b + (1 - θ) α β,        |y|_θ = sqrt(<y, y>_θ),
//! ```
//!
//! (with [`ContinuationOptions::state_scale`] `s`, `a·b` becomes `Σ a_i b_i / s_i^2`; with
//! [`ContinuationOptions::parameter_scale`] `s_p`, `α β` becomes `α β / s_p^2`), and step
//! lengths `ds` are lengths in that norm. From an accepted point `y0` with unit
//! direction `t` (tangent for the first step, secant afterwards by default) the predictor is
//! `y0 + ds t`; the corrector is Newton on the bordered system
//!
//! ```text
//! F(x, p) = 0,    N(x, p) = <t, y - y0>_θ - ds = 0,
//! [[J, F_p], [w_x^T, w_p]] [dx; dp] = -[F; N],    w_x = (θ/n) t_x / s^2,  w_p = (1-θ) t_p / s_p^2,
//! ```
//!
//! solved by block elimination ([`BorderedSolver`](crate::linalg::BorderedSolver) with one
//! border row and column) with ONE factorization of `J` per corrector iteration and two
//! solves, `J a = F_p` and `J b = F`: `dp = (w_x·b - N) / (w_p - w_x·a)`, `dx = -b - a dp`.
//! The bordered matrix is never assembled, so structured Jacobians (sparse, condensed)
//! keep their structure. The tangent at the converged point comes for free from the last
//! `a`: it is `±(-a, 1)` normalised (the kernel of `[J, F_p]`), with `J` and `F_p` from
//! the last corrector iteration, i.e. at the iterate before the converged one (an error
//! of the size of the last correction; the corrector always takes at least one step).
//!
//! # Folds and the dense fallback
//!
//! At a fold `J` is singular while the bordered matrix is not. Block elimination then loses
//! accuracy (the pivot `w_p - w_x·a` is a difference of large numbers) or the factorization
//! reports [`LinearSolveError::Singular`](crate::linalg::LinearSolveError::Singular). In practice the iterates rarely hit the singular
//! set exactly, and block elimination passes folds (the tests pass several). For Jacobians
//! that are singular on whole regions (piecewise-linear problems with a flat piece), the
//! continuation can fall back to a dense LU of the assembled `(n+1) x (n+1)` bordered
//! matrix. This is an optional capability chosen by a second entry point,
//! [`Continuation::with_dense_fallback`], which exists only when the Jacobian type
//! implements [`DenseAssemble`](crate::linalg::DenseAssemble); structured Jacobians that cannot be assembled use
//! [`Continuation::new`] and report a corrector failure instead (the step is then halved).
//!
//! # Step control
//!
//! After an accepted point corrected in `k` iterations the step is multiplied by
//! `sqrt(target_iterations / k)` clamped to `[1/2, 2]`, then clamped to
//! `[min_step, max_step]`. A failed corrector halves the step (not below `min_step`) and
//! restores the problem's parameter (`set_parameter`) to the last accepted point. The run
//! ends when an attempt at `min_step` fails ([`ContinuationTermination::StepTooSmall`]),
//! after `max_consecutive_failures` failures in a row
//! ([`ContinuationTermination::TooManyFailures`]), when the parameter leaves
//! `[parameter_min, parameter_max]` (the last point is then re-solved at the bound), or after
//! `max_points` points.
//!
//! Folds are extrema of the parameter along the branch that the branch leaves by more than
//! [`ContinuationOptions::fold_excursion`] (a θ-length, default the default `min_step`),
//! located by cubic Hermite interpolation of `p(s)` (values and slopes `dp/ds = t_p`, the
//! tangent oriented along the step just taken) where `t_p` changes sign next to the
//! extreme point, else at the extreme point (a fold at a corner of a piecewise-smooth
//! branch). A branch that turns back by less and forward again zigzags: on a sampled
//! nonsmooth problem the active set changes sample by sample and, where the branch is
//! nearly vertical, each change can tip the parameter back and forth by a sample-scale
//! amount. Those reversals are [`ContinuationEvent::Zigzag`]s, not folds ([`FoldDetector`],
//! a detector with hysteresis, also usable on branches stitched together from several
//! runs).
//!
//! # Corners
//!
//! Branches of semismooth problems are only piecewise smooth. Where the branch turns by
//! more than 90° in the θ-norm at a corner, the pseudo-arclength hyperplane (normal to the
//! incoming direction `d`) no longer cuts the far piece, whatever the step: halving ends
//! the run there. Before giving up ([`ContinuationOptions::pass_corners`]), the step that
//! failed last is tried twice more from the last point: on the hyperplane normal to `d`'s
//! state part only, `d_x · (x - x_k) = ds |d_x|²` (cuts a far piece along which the state
//! keeps moving forward, e.g. a fold at a corner), then at the next parameter
//! `p_k + sign(d_p) ds s_p / sqrt(1 - θ)` (cuts a far piece along which the parameter keeps
//! moving). A point found this way ([`ContinuationCounters::corner_passes`]) is accepted
//! with its tangent oriented along that constraint's normal, and the next predictor
//! follows that tangent (the chord across the corner is no direction for the far piece).
//!
//! Where both fail (a fold at a corner: the branch leaves the corner going back in `p`, often
//! along a piece nearly opposite to the incoming one), a restart may go back along the branch.
//! As the last resort of such a retrace, the exit-tangent pass
//! ([`ContinuationOptions::exit_tangents`], counted in
//! [`ContinuationCounters::exit_passes`]) goes back to the corner where the restart began
//! (the restart's retrace test stays on) and takes the generalized Jacobian just past the last
//! point, at `y_k + δ d` for `δ` = 2, 16 and 128 times `min_step`, where the switched pieces
//! are active: the kernel `e` of `[J, F_p]` there is the tangent of the piece that leaves the
//! corner. The corrector is tried from `y_k ± ds e` on the hyperplane normal to `e`
//! (`ds` = 4 and 32 times `δ`). A probe whose tangent is the incoming piece's (at `y_k`) is
//! skipped, and a point whose chord from `y_k` lies along the incoming piece is refused
//! (the piece the branch came by); the first other point is accepted with its tangent
//! oriented along `e`. The problem supplies nothing beyond its generalized Jacobian. (A
//! piecewise-affine branch crosses its corners exactly instead, below.)
//!
//! The corrector is the crate's Newton iteration ([`crate::newton`]: the same step rule and
//! termination tests) with the bordered direction above; it takes full steps unless
//! [`ContinuationOptions::corrector_line_search`] asks for Armijo backtracking on
//! `(|F|^2 + N^2) / 2`. A point where the problem cannot be evaluated
//! ([`EvaluationError`](crate::EvaluationError)) fails the attempt like a divergence.
//!
//! # Trust ball and restarts
//!
//! Two options for branches with sharp corners and overhangs. With
//! [`ContinuationOptions::trust_factor`] the corrector may not leave the θ-ball of
//! `trust_factor` times the largest next step around the last point (a corrector that
//! wanders farther has left for another part of the branch). With
//! [`ContinuationOptions::restarts`] ([`RestartPolicy`]), a run whose steps failed for good
//! is taken up again from its last point with a state-heavy metric (`θ` near 1) for a few
//! points, heading the way `p` last moved (the other way when a restart could not make a
//! single step), then with the options' metric again ([`ContinuationCounters::restarts`]).
//! A restarted segment that comes back near the points before the restart is going back
//! along the branch: the run then ends ([`ContinuationTermination::Retraced`]).
//!
//! # Another discretisation on the way
//!
//! A branch can be taken up on another problem (the same equations discretised with more or
//! fewer unknowns) from where a run stands: [`Continuation::resumption`] gives the last
//! point, the next predictor direction and step, and the fold detector; the caller carries
//! the state and direction over to the other unknowns and [`Continuation::resume`]s with the
//! other problem. The resumed run corrects that point at its fixed parameter, orients its
//! tangent along the carried direction and goes on with the carried step; its first item
//! replaces the last point of the earlier run, and fold events continue across the change.
//!
//! # Piecewise-affine branches
//!
//! When the residual is affine in `x` on each piece of a sign pattern
//! ([`PiecewiseAffine`]: a sampled penalty law), the branch is a chain of pieces that are
//! graphs over `p`, and every fold is a corner. [`Continuation::with_affine_pieces`] crosses
//! those corners exactly: when an accepted point lies on another piece than the last one,
//! or when the steps fail for good, the corners ahead are located on the pieces themselves
//! (Newton in `p` on the first switching function to change sign, one linear solve of the
//! affine piece per iterate), emitted as branch points ([`BranchPoint::corner`],
//! [`ContinuationEvent::Corner`]) while they follow each other within one largest step,
//! and the continuation resumes a short way along the first long piece. Folds are then
//! reported at corners, never interpolated.
//!
//! # Homotopy
//!
//! [`homotopy`] is the natural-parameter counterpart for a parameter the problem offers
//! (a penalty stiffness, a load factor): stages from an easy value towards a hard one, each
//! solved by Newton from the previous solution, the step halved after a failure.
//!
//! # Style
//!
//! [`Continuation`] is an [`Iterator`] over accepted points (BifurcationKit's style); the
//! first item is the starting point corrected at fixed `p0`. [`Continuation::run`] collects a
//! whole [`Branch`]. As for Newton, `Err` ([`ContinuationError`]) only when the run cannot
//! start (bad options, a start of the wrong length or out of bounds); a run that ran says
//! why it stopped in its [`ContinuationTermination`] (a start that cannot be corrected
//! included: [`ContinuationTermination::StartFailed`], and no point). [`natural_sweep`] solves at a list of parameters with
//! the solver it is given ([`crate::newton`] or [`crate::polyalgorithm`]) from the previous
//! solution, for comparison: it fails or jumps at folds.
//!
//! References: H. B. Keller, *Numerical solution of bifurcation and nonlinear eigenvalue
//! problems* (1977); E. Allgower & K. Georg, *Numerical Continuation Methods* (1990), for
//! the bordered system and its block elimination; BifurcationKit.jl (`Palc`) for the
//! θ-weighted arclength and the iterator; NLvib for the step bounds.
//!
//! ```
//! use faer::Mat;
//! use semismooth::continuation::{Continuation, ContinuationOptions, ContinuationTermination};
//! use semismooth::linalg::FaerDenseLu;
//! use semismooth::{EvaluationError, GeneralizedJacobian, ParameterDependent, Residual};
//!
//! /// The S-curve x^3 - x - p = 0 (folds at p = ±2/(3√3)).
//! struct SCurve { p: f64 }
//! impl Residual for SCurve {
//!     fn dim(&self) -> usize { 1 }
//!     fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
//!         out[0] = x[0].powi(3) - x[0] - self.p;
//!         Ok(())
//!     }
//! }
//! impl GeneralizedJacobian for SCurve {
//!     type Jacobian = Mat<f64>;
//!     fn new_jacobian(&self) -> Mat<f64> { Mat::zeros(1, 1) }
//!     fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
//!         jac[(0, 0)] = 3.0 * x[0] * x[0] - 1.0;
//!         Ok(())
//!     }
//! }
//! impl ParameterDependent for SCurve {
//!     fn parameter(&self) -> f64 { self.p }
//!     fn set_parameter(&mut self, p: f64) { self.p = p; }
//! }
//!
//! let mut problem = SCurve { p: -1.0 };
//! let mut solver = FaerDenseLu::new();
//! let options = ContinuationOptions { parameter_min: -1.0, parameter_max: 1.0, ..Default::default() };
//! let branch = Continuation::new(&mut problem, &mut solver, &[-1.3], -1.0, options)
//!     .unwrap() // Err only for bad options or a start of the wrong length
//!     .run();
//! assert_eq!(branch.fold_parameters().len(), 2);
//! assert!(matches!(branch.termination, ContinuationTermination::ReachedBound { .. }));
//! ```

mod branch;
mod corrector;
mod driver;
mod folds;
mod homotopy;
mod natural;
mod options;
mod pieces;

pub use branch::{
    Branch, BranchPoint, ContinuationCounters, ContinuationError, ContinuationEvent,
    ContinuationTermination, CorrectorFailure,
};
pub use driver::{Continuation, Resumption};
pub use folds::FoldDetector;
pub use homotopy::{homotopy, HomotopyReport, HomotopySchedule};
pub use natural::{natural_sweep, NaturalSweep, SweepFailure, SweepPoint};
pub use options::{ContinuationOptions, Direction, Predictor, RestartPolicy};
pub use pieces::PiecewiseAffine;

use crate::{Factorize, GeneralizedJacobian, ParameterDependent};

/// Runs a whole continuation: [`Continuation::new`] then [`Continuation::run`] (`Err`
/// only when it could not start: bad options, a start of the wrong length or out of
/// bounds).
pub fn run<P, S>(
    problem: &mut P,
    solver: &mut S,
    x0: &[f64],
    p0: f64,
    options: ContinuationOptions,
) -> Result<Branch, ContinuationError>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    Ok(Continuation::new(problem, solver, x0, p0, options)?.run())
}
