//! Corners of penalty-HB branches, crossed explicitly.
//!
//! With the set `h` of AFT samples that carry penalty force held fixed, the penalty residual
//! `A(ω) U - F + k_p G^T P diag(h) (G E U - g)` is affine in `U`: its solutions form a
//! piece `U_h(ω)`, a graph over `ω` (one linear solve at each `ω`), and the branch is a
//! chain of such pieces joined at corners where one sample's gap `s_n = G u(t_n) - g`
//! changes sign. A piece cannot turn back in `ω`: every fold of the branch is a corner.
//! With a stiff penalty the active samples sit at `s_n ≈ force / k_p`, the contact moves
//! from sample to sample as `ω` changes, and the branch zigzags in `ω` (the canonical rod,
//! `H = 5`, gap 0.5, `k_p = 1e5 x`: 44 folds, `ω` reversing by up to 2e-2 `ω_1`). Some of
//! these corners turn by more than a right angle in the arclength metric (measured 93.6°
//! at `ω = 1.01447 ω_1`, from the two-sample piece onto the one-sample piece): there the
//! arclength constraint has no solution on the next piece whatever the step, and the
//! continuation stalls.
//!
//! [`PenaltyCorners::cross`] therefore walks over corners exactly, on its own copy of the
//! problem: from a branch point it finds the first sample to switch along the current piece
//! (Newton on `s_n(U_h(ω)) = 0` in `ω`), flips that sample, takes the `ω` direction in which
//! the new piece is consistent (all `s_n > 0` exactly where `h_n = 1`), and goes on to the
//! next corner while it is within one largest continuation step (a chain of short pieces
//! costs about three factorizations per corner, far less than arclength steps). It ends on
//! a consistent point a short way along the first long piece, from which the continuation
//! restarts.

use semismooth::continuation::Direction;
use semismooth::newton::WorkCounters;
use semismooth::{Factorize, GeneralizedJacobian, ParameterDependent, Residual};

use crate::hb::{HbJacobian, PenaltyHb};

/// Iterations of each search (a crossing, the entry point of the last piece).
const CORNER_ITERATIONS: usize = 30;

/// A crossing is located when its predicted distance is within this fraction of `ω`.
const CORNER_OMEGA_TOLERANCE: f64 = 1e-10;

/// Rounding of a gap sample, in units of `ε max_n |s_n|` (a sum of `2H + 1` terms).
const GAP_ROUNDING: f64 = 64.0;

/// Corners stepped over by [`Corners::cross`], in branch order, and where the branch goes
/// on.
pub(super) struct Walk {
    /// Each corner's state (a sample's gap is zero there) and `ω`.
    pub corners: Vec<(Vec<f64>, f64)>,
    /// A point on the piece after the last corner, a short way along it, and its `ω`.
    pub start: Vec<f64>,
    pub start_omega: f64,
    /// Which way `ω` goes along that piece.
    pub direction: Direction,
}

/// Explicit crossing of the corners of a piecewise-smooth branch.
pub(super) trait Corners {
    /// Which smooth piece holds `x` (penalty: which AFT samples carry force).
    fn piece(&mut self, x: &[f64]) -> Vec<bool>;
    /// Steps over the next corners of the branch from its point `(x, ω)`, travelling with
    /// `ω` increasing (`heading > 0`) or decreasing, at most `max_corners` of them;
    /// `None` where it cannot.
    fn cross(
        &mut self,
        x: &[f64],
        omega: f64,
        heading: f64,
        max_corners: usize,
        work: &mut WorkCounters,
    ) -> Option<Walk>;
    /// FFTs performed so far.
    fn ffts(&self) -> u64;
}

/// [`Corners`] of penalty-HB branches (module documentation).
pub(super) struct PenaltyCorners {
    pub problem: PenaltyHb,
    pub solver: Box<dyn Factorize<HbJacobian>>,
    /// Farthest a first crossing is searched from the starting point (in `ω`).
    pub reach: f64,
    /// Largest shift from the last corner to the entry point (in `ω`).
    pub shift: f64,
    /// Corners are walked while the next one is within this arclength (the sweep's metric,
    /// `ds² = (Δω/ω_1)² + |ΔU|²/unit²`).
    pub walk: f64,
    pub omega_1: f64,
    pub unit: f64,
}

impl Corners for PenaltyCorners {
    fn piece(&mut self, x: &[f64]) -> Vec<bool> {
        self.problem
            .gap_samples_all(x)
            .iter()
            .map(|s| *s > 0.0)
            .collect()
    }

    fn cross(
        &mut self,
        x: &[f64],
        omega: f64,
        heading: f64,
        max_corners: usize,
        work: &mut WorkCounters,
    ) -> Option<Walk> {
        let walk = self.walk_corners(x, omega, heading, max_corners.max(1), work);
        self.problem.freeze_activity(None);
        walk
    }

    fn ffts(&self) -> u64 {
        self.problem.problem_counters().get("ffts")
    }
}

/// A point of a piece with its tangent `dU/dω`.
struct OnPiece {
    u: Vec<f64>,
    v: Vec<f64>,
    omega: f64,
}

impl PenaltyCorners {
    fn walk_corners(
        &mut self,
        x: &[f64],
        omega: f64,
        heading: f64,
        max_corners: usize,
        work: &mut WorkCounters,
    ) -> Option<Walk> {
        let mut sign = if heading >= 0.0 { 1.0 } else { -1.0 };
        let mut activity = self.piece(x);
        let mut at = self.solve_piece(&activity, omega, x, work)?;
        let mut exclude = None;
        let mut corners = Vec::new();
        loop {
            // The next corner along this piece; after a corner whose successor cannot be
            // found (or a long piece ahead), the walk enters this piece.
            let found = self.crossing(&activity, &at, sign, exclude, work);
            let Some((corner, n)) = found else {
                if corners.is_empty() {
                    return None;
                }
                return self.enter(&activity, &at, sign, f64::INFINITY, corners, work);
            };
            corners.push((corner.u.clone(), corner.omega));
            // The next piece, and which way ω goes along it.
            activity[n] = !activity[n];
            let next = self.solve_piece(&activity, corner.omega, &corner.u, work)?;
            let (s, ds) = self.gaps_and_rates(&next);
            if ds[n] == 0.0 {
                return None;
            }
            sign = if activity[n] {
                ds[n].signum()
            } else {
                -ds[n].signum()
            };
            // Two samples switching at once: not handled.
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
            if ahead * self.metric_rate(&next.v) > self.walk || corners.len() >= max_corners {
                return self.enter(&activity, &next, sign, ahead, corners, work);
            }
            at = next;
            exclude = Some(n);
        }
    }

    /// Ends a walk on a consistent point of the piece `h` through `from` (a corner),
    /// half way to its next predicted crossing `ahead` and at most `shift` away in `ω`.
    fn enter(
        &mut self,
        activity: &[bool],
        from: &OnPiece,
        sign: f64,
        ahead: f64,
        corners: Vec<(Vec<f64>, f64)>,
        work: &mut WorkCounters,
    ) -> Option<Walk> {
        let mut delta = (0.5 * ahead).min(self.shift);
        for _ in 0..CORNER_ITERATIONS {
            let target = from.omega + sign * delta;
            if target > 0.0 {
                let start = self.solve_piece(activity, target, &from.u, work)?;
                if self.piece(&start.u) == activity {
                    return Some(Walk {
                        corners,
                        start: start.u,
                        start_omega: target,
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

    /// Arclength per unit `ω` along a piece with tangent `v = dU/dω`.
    fn metric_rate(&self, v: &[f64]) -> f64 {
        let dv = v.iter().map(|a| a * a).sum::<f64>().sqrt() / self.unit;
        dv.hypot(1.0 / self.omega_1)
    }

    /// The piece with activity `h` at `ω`, reached from `x` (two Newton steps on the affine
    /// piece, the second removing round-off), and its tangent `dU/dω = -J_h^{-1} dR/dω`.
    fn solve_piece(
        &mut self,
        activity: &[bool],
        omega: f64,
        x: &[f64],
        work: &mut WorkCounters,
    ) -> Option<OnPiece> {
        let problem = &mut self.problem;
        problem.freeze_activity(Some(activity.to_vec()));
        problem.set_parameter(omega);
        let mut jac = problem.new_jacobian();
        problem.jacobian(x, &mut jac).ok()?;
        work.jacobian_evaluations += 1;
        work.factorizations += 1;
        self.solver.factor(&jac).ok()?;
        let mut u = x.to_vec();
        let mut r = vec![0.0; u.len()];
        for _ in 0..2 {
            problem.residual(&u, &mut r).ok()?;
            work.residual_evaluations += 1;
            work.linear_solves += 1;
            self.solver.solve_in_place(&mut r).ok()?;
            for (a, d) in u.iter_mut().zip(&r) {
                *a -= d;
            }
        }
        problem.residual_parameter_derivative(&u, &mut r).ok()?;
        work.linear_solves += 1;
        self.solver.solve_in_place(&mut r).ok()?;
        let v: Vec<f64> = r.iter().map(|d| -d).collect();
        u.iter()
            .chain(&v)
            .all(|a| a.is_finite())
            .then_some(OnPiece { u, v, omega })
    }

    /// Gap samples at a point of a piece and their rates `ds/dω` (the map is affine in `U`).
    fn gaps_and_rates(&mut self, at: &OnPiece) -> (Vec<f64>, Vec<f64>) {
        let s = self.problem.gap_samples_all(&at.u);
        let moved: Vec<f64> = at.u.iter().zip(&at.v).map(|(a, b)| a + b).collect();
        let rates = self
            .problem
            .gap_samples_all(&moved)
            .iter()
            .zip(&s)
            .map(|(a, b)| a - b)
            .collect();
        (s, rates)
    }

    /// The first crossing along the piece `h` from the consistent point `at`, `ω` moving
    /// with `sign`, located on its consistent side: Newton on the earliest predicted
    /// crossing from the farthest consistent point, or back from the nearest inconsistent
    /// one (stopping a little short), bisection when both leave the bracket. `exclude`: a
    /// sample that has just switched (its gap is zero at `at`), ignored there. `None`
    /// beyond `reach`, on a singular piece, or when no crossing lies ahead.
    fn crossing(
        &mut self,
        activity: &[bool],
        at: &OnPiece,
        sign: f64,
        exclude: Option<usize>,
        work: &mut WorkCounters,
    ) -> Option<(OnPiece, usize)> {
        let from = at.omega;
        let tolerance = CORNER_OMEGA_TOLERANCE * from;
        let mut good = OnPiece {
            u: at.u.clone(),
            v: at.v.clone(),
            omega: at.omega,
        };
        let mut skip = exclude;
        let mut bad: Option<OnPiece> = None;
        for _ in 0..CORNER_ITERATIONS {
            // The earliest crossing ahead of the farthest consistent point.
            let (s, ds) = self.gaps_and_rates(&good);
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
            // Located to `tolerance`, or to what the rounding of the gaps allows (an active
            // sample's gap is only force / k_p).
            let scale = s.iter().fold(0.0, |a: f64, v| a.max(v.abs()));
            let resolution = tolerance + GAP_ROUNDING * f64::EPSILON * scale / ds[n].abs();
            if d.abs() <= resolution
                || bad
                    .as_ref()
                    .is_some_and(|b| (b.omega - good.omega).abs() <= resolution)
            {
                return Some((good, n));
            }
            let mut w = good.omega + d;
            if let Some(b) = &bad {
                let inside = |w: f64| (w - good.omega) * sign > 0.0 && (b.omega - w) * sign > 0.0;
                if !inside(w) {
                    // Back from the inconsistent point to the earliest crossing behind it.
                    let (s, ds) = self.gaps_and_rates(b);
                    let back = s
                        .iter()
                        .zip(&ds)
                        .zip(activity)
                        .filter(|((sm, &dm), &on)| (**sm > 0.0) != on && dm != 0.0)
                        .map(|((&sm, &dm), _)| -sm / dm)
                        .filter(|d| d * sign < 0.0)
                        .fold(0.0, |a: f64, d| if d.abs() > a.abs() { d } else { a });
                    let wb = b.omega + back - 0.5 * sign * tolerance;
                    w = if back != 0.0 && inside(wb) {
                        wb
                    } else {
                        0.5 * (good.omega + b.omega)
                    };
                }
            } else if (w - from).abs() > self.reach || w <= 0.0 {
                return None;
            }
            let trial = self.solve_piece(activity, w, &good.u, work)?;
            let consistent = self
                .problem
                .gap_samples_all(&trial.u)
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
