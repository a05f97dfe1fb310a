//! Corners of piecewise-affine branches, crossed exactly.
//!
//! A [`PiecewiseAffine`] problem has, at fixed `p`, a residual that is affine in `x` on each
//! piece `h` (the sign pattern of its switching functions `s(x, p)`). Its branch is a chain
//! of smooth pieces `x_h(p)` (one linear solve at each `p`, a graph over `p`) joined at
//! corners where one switching function changes sign; a piece cannot turn back in `p`, so
//! every fold of such a branch is a corner. Where a corner turns by more than a right
//! angle in the arclength metric, no pseudo-arclength hyperplane cuts the far piece and
//! the continuation stalls; with many pieces (a stiff penalty: the contact moves from
//! sample to sample) the branch zigzags through hundreds of them.
//!
//! The walk from a branch point: on the current piece, locate the first switching function
//! to change sign ahead (Newton in `p` on the earliest predicted crossing from the
//! farthest consistent point, or back from the nearest inconsistent one, bisection when
//! both leave the bracket; each iterate one linear solve of the affine piece), flip it,
//! take the direction of `p` in which the new piece is consistent (its switching function
//! has the new sign), and go on to the next corner while it is within one largest
//! continuation step. The walk ends on a consistent point a short way along the first long
//! piece, from which the continuation restarts.

use super::corrector::Metric;
use super::Direction;
use crate::newton::WorkCounters;
use crate::{EvaluationError, Factorize, GeneralizedJacobian, ParameterDependent};

/// A residual that is piecewise affine in `x` at fixed `p`: the pieces are the sign
/// patterns of `m` switching functions `s(x, p)`, each affine in `x`; on the piece `h`
/// (`h_i` true exactly where `s_i > 0`) the residual is an affine map `F_h(x, p)` defined
/// for every `x` (the affine extension of the piece). A penalty contact law
/// `lambda = -k max(0, g(x))` sampled in time is of this kind (`s` = the sampled gaps).
///
/// With [`Continuation::with_affine_pieces`](super::Continuation::with_affine_pieces) the
/// continuation crosses the corners of such a branch exactly (module documentation of
/// [`crate::continuation`], *Piecewise-affine branches*).
///
/// ```
/// use semismooth::continuation::{Continuation, ContinuationOptions};
/// use semismooth::faer::Mat;
/// use semismooth::linalg::FaerDenseLu;
/// use semismooth::continuation::PiecewiseAffine;
/// use semismooth::{EvaluationError, GeneralizedJacobian, ParameterDependent, Residual};
///
/// /// A spring against a stiffer one beyond x = 1: x + 3 max(0, x - 1) = p, one switching
/// /// function s = x - 1; the branch x(p) has a corner at p = 1.
/// struct Springs { p: f64, held: Option<bool> }
/// impl Springs {
///     fn closed(&self, x: f64) -> bool { self.held.unwrap_or(x > 1.0) }
/// }
/// impl Residual for Springs {
///     fn dim(&self) -> usize { 1 }
///     fn residual(&mut self, x: &[f64], f: &mut [f64]) -> Result<(), EvaluationError> {
///         let stiff = if self.closed(x[0]) { 3.0 * (x[0] - 1.0) } else { 0.0 };
///         f[0] = x[0] + stiff - self.p;
///         Ok(())
///     }
/// }
/// impl GeneralizedJacobian for Springs {
///     type Jacobian = Mat<f64>;
///     fn new_jacobian(&self) -> Mat<f64> { Mat::zeros(1, 1) }
///     fn jacobian(&mut self, x: &[f64], j: &mut Mat<f64>) -> Result<(), EvaluationError> {
///         j[(0, 0)] = if self.closed(x[0]) { 4.0 } else { 1.0 };
///         Ok(())
///     }
/// }
/// impl ParameterDependent for Springs {
///     fn parameter(&self) -> f64 { self.p }
///     fn set_parameter(&mut self, p: f64) { self.p = p; }
///     fn residual_parameter_derivative(
///         &mut self, _: &[f64], d: &mut [f64], _: &mut [f64],
///     ) -> Result<(), EvaluationError> {
///         d[0] = -1.0;
///         Ok(())
///     }
/// }
/// impl PiecewiseAffine for Springs {
///     fn switching_count(&self) -> usize { 1 }
///     fn switching(&mut self, x: &[f64], s: &mut [f64]) -> Result<(), EvaluationError> {
///         s[0] = x[0] - 1.0;
///         Ok(())
///     }
///     fn hold_piece(&mut self, piece: Option<&[bool]>) { self.held = piece.map(|h| h[0]); }
/// }
///
/// let mut springs = Springs { p: 0.0, held: None };
/// let options = ContinuationOptions { parameter_max: 3.0, ..Default::default() };
/// let branch = Continuation::new(&mut springs, &mut FaerDenseLu::new(), &[0.0], 0.0, options)
///     .unwrap()
///     .with_affine_pieces()
///     .run();
/// let corners = branch.corner_parameters();
/// assert_eq!(corners.len(), 1);
/// assert!((corners[0] - 1.0).abs() < 1e-9, "{corners:?}");
/// ```
pub trait PiecewiseAffine: GeneralizedJacobian + ParameterDependent {
    /// Number `m` of switching functions.
    fn switching_count(&self) -> usize;

    /// Writes `s(x, p)` (at the current parameter) into `out` (length `m`).
    fn switching(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError>;

    /// While `Some(h)`, the residual, Jacobian and parameter derivative are those of the
    /// piece `h`, `F_h`, whatever the signs of `s(x, p)`; `None` restores `F`.
    fn hold_piece(&mut self, piece: Option<&[bool]>);
}

/// Iterations of each search (a crossing, the entry point of the last piece).
const CORNER_ITERATIONS: usize = 30;

/// A crossing is located when its predicted distance is within this fraction of `|p|`.
const CORNER_PARAMETER_TOLERANCE: f64 = 1e-10;

/// Rounding of a switching function, in units of `ε max_i |s_i|`.
const SWITCHING_ROUNDING: f64 = 64.0;

/// `PiecewiseAffine::switching` as a function pointer.
type Switching<P> = fn(&mut P, &[f64], &mut [f64]) -> Result<(), EvaluationError>;

/// The [`PiecewiseAffine`] methods, kept as function pointers so that the continuation can
/// hold them without requiring the trait of every problem.
pub(super) struct AffineOps<P: ?Sized> {
    pub count: fn(&P) -> usize,
    pub switching: Switching<P>,
    pub hold: fn(&mut P, Option<&[bool]>),
}

impl<P: ?Sized> Clone for AffineOps<P> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<P: ?Sized> Copy for AffineOps<P> {}

impl<P: PiecewiseAffine + ?Sized> AffineOps<P> {
    pub fn of() -> Self {
        Self {
            count: P::switching_count,
            switching: P::switching,
            hold: P::hold_piece,
        }
    }
}

/// Corners stepped over, in branch order, and where the branch goes on.
pub(super) struct Walk {
    /// Each corner's state (one switching function is zero there) and parameter.
    pub corners: Vec<(Vec<f64>, f64)>,
    /// A point on the piece after the last corner, a short way along it, and its parameter.
    pub start: Vec<f64>,
    pub start_parameter: f64,
    /// Which way `p` goes along that piece.
    pub direction: Direction,
}

/// A point of a piece with its tangent `dx/dp`.
struct OnPiece {
    x: Vec<f64>,
    v: Vec<f64>,
    p: f64,
}

/// Everything a walk needs, borrowed from the continuation.
pub(super) struct Walker<'a, P: GeneralizedJacobian + ?Sized, S: ?Sized> {
    pub problem: &'a mut P,
    pub solver: &'a mut S,
    pub jac: &'a mut P::Jacobian,
    pub ops: AffineOps<P>,
    /// The continuation's main metric (arclength of a walk).
    pub metric: &'a Metric,
    pub work: &'a mut WorkCounters,
    /// Farthest a first crossing is searched from the starting point (in `p`).
    pub reach: f64,
    /// Largest shift from the last corner to the entry point (in `p`).
    pub shift: f64,
    /// Corners are walked while the next one is within this arclength.
    pub walk: f64,
    /// The parameter interval of the continuation.
    pub bounds: (f64, f64),
}

impl<P, S> Walker<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    /// The piece holding `x` at the current parameter (`None` if `s` cannot be evaluated).
    pub fn piece(&mut self, x: &[f64]) -> Option<Vec<bool>> {
        let s = self.switching(x)?;
        Some(s.iter().map(|v| *v > 0.0).collect())
    }

    fn switching(&mut self, x: &[f64]) -> Option<Vec<f64>> {
        let mut s = vec![0.0; (self.ops.count)(self.problem)];
        (self.ops.switching)(self.problem, x, &mut s).ok()?;
        Some(s)
    }

    /// Steps over the next corners of the branch from its point `(x, p)`, travelling with
    /// `p` increasing (`heading > 0`) or decreasing, at most `max_corners` of them; `None`
    /// where it cannot. The problem is back on its own residual afterwards.
    pub fn cross(&mut self, x: &[f64], p: f64, heading: f64, max_corners: usize) -> Option<Walk> {
        let walk = self.walk_corners(x, p, heading, max_corners.max(1));
        (self.ops.hold)(self.problem, None);
        walk
    }

    fn walk_corners(
        &mut self,
        x: &[f64],
        p: f64,
        heading: f64,
        max_corners: usize,
    ) -> Option<Walk> {
        let mut sign = if heading >= 0.0 { 1.0 } else { -1.0 };
        self.problem.set_parameter(p);
        let mut activity = self.piece(x)?;
        let mut at = self.solve_piece(&activity, p, x)?;
        let mut exclude = None;
        let mut corners = Vec::new();
        loop {
            // The next corner along this piece; after a corner whose successor cannot be
            // found (or a long piece ahead), the walk enters this piece.
            let found = self.crossing(&activity, &at, sign, exclude);
            let Some((corner, n)) = found else {
                if corners.is_empty() {
                    return None;
                }
                return self.enter(&activity, &at, sign, f64::INFINITY, corners);
            };
            corners.push((corner.x.clone(), corner.p));
            // The next piece, and which way p goes along it.
            activity[n] = !activity[n];
            let next = self.solve_piece(&activity, corner.p, &corner.x)?;
            let (s, ds) = self.switching_and_rates(&next)?;
            if ds[n] == 0.0 {
                return None;
            }
            sign = if activity[n] {
                ds[n].signum()
            } else {
                -ds[n].signum()
            };
            // Two functions switching at once: not handled.
            if s.iter()
                .zip(&activity)
                .enumerate()
                .any(|(m, (sm, &on))| m != n && (*sm > 0.0) != on)
            {
                return None;
            }
            let ahead = s
                .iter()
                .zip(&ds)
                .enumerate()
                .filter(|&(m, (_, &dm))| m != n && dm != 0.0)
                .map(|(_, (&sm, &dm))| -sm / dm)
                .filter(|d| d * sign > 0.0)
                .fold(f64::INFINITY, |a, d| a.min(d.abs()));
            let rate = self.metric.norm(&next.v, 1.0);
            if ahead * rate > self.walk || corners.len() >= max_corners {
                return self.enter(&activity, &next, sign, ahead, corners);
            }
            at = next;
            exclude = Some(n);
        }
    }

    /// Ends a walk on a consistent point of the piece `h` through `from` (a corner), half
    /// way to its next predicted crossing `ahead` and at most `shift` away in `p`.
    fn enter(
        &mut self,
        activity: &[bool],
        from: &OnPiece,
        sign: f64,
        ahead: f64,
        corners: Vec<(Vec<f64>, f64)>,
    ) -> Option<Walk> {
        let mut delta = (0.5 * ahead).min(self.shift);
        for _ in 0..CORNER_ITERATIONS {
            let target = from.p + sign * delta;
            if self.inside(target) {
                let start = self.solve_piece(activity, target, &from.x)?;
                if self.piece(&start.x).as_deref() == Some(activity) {
                    return Some(Walk {
                        corners,
                        start: start.x,
                        start_parameter: target,
                        direction: if sign > 0.0 {
                            Direction::Increasing
                        } else {
                            Direction::Decreasing
                        },
                    });
                }
            }
            delta *= 0.5;
        }
        None
    }

    fn inside(&self, p: f64) -> bool {
        p >= self.bounds.0 && p <= self.bounds.1
    }

    /// The piece with activity `h` at `p`, reached from `x` (two Newton steps on the affine
    /// piece, the second removing round-off), and its tangent `dx/dp = -J_h^{-1} F_p`.
    fn solve_piece(&mut self, activity: &[bool], p: f64, x: &[f64]) -> Option<OnPiece> {
        (self.ops.hold)(self.problem, Some(activity));
        self.problem.set_parameter(p);
        self.work.jacobian_evaluations += 1;
        self.problem.jacobian(x, self.jac).ok()?;
        self.work.factorizations += 1;
        self.solver.factor(self.jac).ok()?;
        let mut u = x.to_vec();
        let mut r = vec![0.0; u.len()];
        for _ in 0..2 {
            self.work.residual_evaluations += 1;
            self.problem.residual(&u, &mut r).ok()?;
            self.work.linear_solves += 1;
            self.solver.solve_in_place(&mut r).ok()?;
            for (a, d) in u.iter_mut().zip(&r) {
                *a -= d;
            }
        }
        let mut scratch = vec![0.0; u.len()];
        self.problem
            .residual_parameter_derivative(&u, &mut r, &mut scratch)
            .ok()?;
        self.problem.set_parameter(p);
        self.work.linear_solves += 1;
        self.solver.solve_in_place(&mut r).ok()?;
        let v: Vec<f64> = r.iter().map(|d| -d).collect();
        u.iter()
            .chain(&v)
            .all(|a| a.is_finite())
            .then_some(OnPiece { x: u, v, p })
    }

    /// Switching functions at a point of a piece and their rates `ds/dp` (the functions are
    /// affine in `x`, and `p` enters through `x_h(p)`).
    fn switching_and_rates(&mut self, at: &OnPiece) -> Option<(Vec<f64>, Vec<f64>)> {
        self.problem.set_parameter(at.p);
        let s = self.switching(&at.x)?;
        let moved: Vec<f64> = at.x.iter().zip(&at.v).map(|(a, b)| a + b).collect();
        let rates = self
            .switching(&moved)?
            .iter()
            .zip(&s)
            .map(|(a, b)| a - b)
            .collect();
        Some((s, rates))
    }

    /// The first crossing along the piece `h` from the consistent point `at`, `p` moving
    /// with `sign`, located on its consistent side: Newton on the earliest predicted
    /// crossing from the farthest consistent point, or back from the nearest inconsistent
    /// one (stopping a little short), bisection when both leave the bracket. `exclude`: a
    /// function that has just switched (it is zero at `at`), ignored there. `None` beyond
    /// `reach` or the bounds, on a singular piece, or when no crossing lies ahead.
    fn crossing(
        &mut self,
        activity: &[bool],
        at: &OnPiece,
        sign: f64,
        exclude: Option<usize>,
    ) -> Option<(OnPiece, usize)> {
        let from = at.p;
        let tolerance = CORNER_PARAMETER_TOLERANCE * from.abs();
        let mut good = OnPiece {
            x: at.x.clone(),
            v: at.v.clone(),
            p: at.p,
        };
        let mut skip = exclude;
        let mut bad: Option<OnPiece> = None;
        for _ in 0..CORNER_ITERATIONS {
            // The earliest crossing ahead of the farthest consistent point.
            let (s, ds) = self.switching_and_rates(&good)?;
            let (n, d) = s
                .iter()
                .zip(&ds)
                .enumerate()
                .filter(|&(m, (_, &dm))| Some(m) != skip && dm != 0.0)
                .map(|(m, (&sm, &dm))| (m, -sm / dm))
                .filter(|(_, d)| d * sign >= 0.0)
                .fold(None, |best: Option<(usize, f64)>, (m, d)| match best {
                    Some((_, b)) if b.abs() <= d.abs() => best,
                    _ => Some((m, d)),
                })?;
            // Located to `tolerance`, or to what the rounding of the switching functions
            // allows (an active penalty sample's gap is only force / k_p).
            let scale = s.iter().fold(0.0, |a: f64, v| a.max(v.abs()));
            let resolution = tolerance + SWITCHING_ROUNDING * f64::EPSILON * scale / ds[n].abs();
            if d.abs() <= resolution
                || bad
                    .as_ref()
                    .is_some_and(|b| (b.p - good.p).abs() <= resolution)
            {
                return Some((good, n));
            }
            let mut p = good.p + d;
            if let Some(b) = &bad {
                let inside = |p: f64| (p - good.p) * sign > 0.0 && (b.p - p) * sign > 0.0;
                if !inside(p) {
                    // Back from the inconsistent point to the earliest crossing behind it.
                    let (s, ds) = self.switching_and_rates(b)?;
                    let back = s
                        .iter()
                        .zip(&ds)
                        .zip(activity)
                        .filter(|((sm, &dm), &on)| (**sm > 0.0) != on && dm != 0.0)
                        .map(|((&sm, &dm), _)| -sm / dm)
                        .filter(|d| d * sign < 0.0)
                        .fold(0.0, |a: f64, d| if d.abs() > a.abs() { d } else { a });
                    let pb = b.p + back - 0.5 * sign * tolerance;
                    p = if back != 0.0 && inside(pb) {
                        pb
                    } else {
                        0.5 * (good.p + b.p)
                    };
                }
            } else if (p - from).abs() > self.reach || !self.inside(p) {
                return None;
            }
            let trial = self.solve_piece(activity, p, &good.x)?;
            let consistent = self
                .switching(&trial.x)?
                .iter()
                .zip(activity)
                .all(|(sm, &on)| (*sm > 0.0) == on);
            if consistent {
                good = trial;
                skip = None;
            } else {
                bad = Some(trial);
            }
        }
        None
    }
}
