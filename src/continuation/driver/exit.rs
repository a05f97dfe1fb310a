//! The exit-tangent pass at a corner: where the steps from a point fail for good, the
//! generalized Jacobian just past the point (where the switched pieces are active) gives the
//! tangent of the piece that leaves the corner, and the branch goes on along it.

use super::super::corrector::Corrector;
use super::{Accepted, Continuation, Segment};
use crate::continuation::BranchPoint;
use crate::iteration::kernel::{KernelRules, StepRule};
use crate::newton::Tolerances;
use crate::{Factorize, GeneralizedJacobian, ParameterDependent};

/// Distances of the probes past the last point along the failed direction, in units of
/// `min_step`: the steps failed down to `min_step`, so the corner lies about that close.
const EXIT_PROBES: [f64; 3] = [2.0, 16.0, 128.0];

/// Steps along an exit tangent, in units of the probe's distance.
const EXIT_STEPS: [f64; 2] = [4.0, 32.0];

/// A direction lies along the incoming piece when the sine of its angle with the incoming
/// piece's tangent is below this (a probe's tangent, a chord from the last point).
const RETRACE_SINE: f64 = 0.05;

impl<P, S> Continuation<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    /// After a restarted segment went back along the branch (its end would be
    /// [`Retraced`](crate::continuation::ContinuationTermination::Retraced)): the main segment again at
    /// `corner`, where its steps along `failed` failed for good, and the exit-tangent pass
    /// there; the run goes on from the point it finds, else ends as it would have. The
    /// restart's retrace test stays on: where the exit piece comes back to the points
    /// before the corner, the run ends there, `Retraced` too.
    pub(super) fn exit_after_retrace(&mut self, corner: BranchPoint, failed: Vec<f64>) {
        let retraced = self.termination.take();
        self.metric = self.main_metric.clone();
        self.segment = Segment::Main;
        self.direction = failed;
        self.problem.set_parameter(corner.parameter);
        self.last = Some(corner.clone());
        match self.pass_corner_by_exit(&corner) {
            Some(Some((point, chord))) => self.after_accept(point, chord),
            Some(None) => {}
            None => {
                if let Some(termination) = retraced {
                    self.finish(termination);
                }
            }
        }
    }

    /// The exit-tangent pass (module documentation, *Corners*): for each probe `y_q =
    /// y_k + δ d` past the last point `y_k` along the failed direction `d`, the unit
    /// tangent `e` of `[J(y_q), F_p(y_q)]` (the pieces active at `y_q`), then the corrector
    /// from `y_k + ds e` on the hyperplane normal to `e` at `ds`, for both orientations of
    /// `e` (first the one whose state part goes along `d`'s) and a few `ds`. Probes whose
    /// tangent is the incoming piece's (at the last point) are skipped; a converged point
    /// whose chord lies along the incoming piece is rejected; another is accepted with its
    /// tangent oriented along `e`. `Some(result of accept)` when one was.
    pub(super) fn pass_corner_by_exit(&mut self, last: &BranchPoint) -> Option<Accepted> {
        let n = self.metric.n;
        let d = self.direction.clone();
        // The incoming piece's tangent, at the last point itself.
        let incoming = self.exit_tangent(last, &d, 0.0)?;
        for probe in EXIT_PROBES {
            let delta = probe * self.options.min_step;
            let Some(exit) = self.exit_tangent(last, &d, delta) else {
                if self.finished() {
                    return None;
                }
                continue;
            };
            let cos = self
                .metric
                .dot(&exit[..n], exit[n], &incoming[..n], incoming[n]);
            if cos.abs() > 1.0 - RETRACE_SINE * RETRACE_SINE / 2.0 {
                continue;
            }
            let forward = self.metric.state_dot(&exit[..n], &d[..n]) >= 0.0;
            let first = if forward { 1.0 } else { -1.0 };
            for sign in [first, -first] {
                let e: Vec<f64> = exit.iter().map(|v| sign * v).collect();
                for factor in EXIT_STEPS {
                    let ds = (factor * delta).min(self.options.max_step);
                    if let Some(accepted) = self.step_along_exit(last, &e, &incoming, ds) {
                        return Some(accepted);
                    }
                    if self.finished() || self.iterations_left() == Some(0) {
                        return None;
                    }
                }
            }
        }
        None
    }

    /// The unit tangent (θ-norm) of `[J, F_p]` at `last + delta d`; `None` when it cannot
    /// be computed there (the problem's parameter is restored to the last point's).
    fn exit_tangent(&mut self, last: &BranchPoint, d: &[f64], delta: f64) -> Option<Vec<f64>> {
        let n = self.metric.n;
        let mut y: Vec<f64> = last
            .state
            .iter()
            .zip(d)
            .map(|(x, di)| x + delta * di)
            .collect();
        y.push(last.parameter + delta * d[n]);
        let corrector = Corrector {
            problem: &mut *self.problem,
            solver: &mut *self.solver,
            ws: &mut self.bordered,
            fallback: self.fallback,
            metric: &self.metric,
            trust: None,
            rules: KernelRules::new(Tolerances::default(), 1, StepRule::Full),
        };
        let computed = corrector.tangent_at(&y, &mut self.work, &mut self.corrector_counts);
        self.problem.set_parameter(last.parameter);
        computed.ok()?;
        let raw = &self.bordered.tangent;
        let norm = self.metric.norm(&raw[..n], raw[n]);
        (norm.is_finite() && norm > 0.0).then(|| raw.iter().map(|v| v / norm).collect())
    }

    /// One attempt along the exit direction `e` with step `ds` from `last`; `None` when
    /// the corrector failed or its point goes back along the incoming direction `d`.
    fn step_along_exit(
        &mut self,
        last: &BranchPoint,
        e: &[f64],
        d: &[f64],
        ds: f64,
    ) -> Option<Accepted> {
        let n = self.metric.n;
        self.metric.state_normal(&e[..n], &mut self.bordered.w);
        let constraint = self.arclength_constraint(last, e[n], ds);
        let mut x: Vec<f64> = last
            .state
            .iter()
            .zip(e)
            .map(|(x, ei)| x + ds * ei)
            .collect();
        let mut p = last.parameter + ds * e[n];
        let before = self.corrector_counts.iterations;
        // The trust ball of a step of this length (the failed steps shrank it).
        self.set_trust(&last.state, last.parameter, ds);
        let corrected = self.correct_at(&mut x, &mut p, constraint).0;
        let chord: Vec<f64> = x.iter().zip(&last.state).map(|(a, b)| a - b).collect();
        let back = self.along_incoming(&chord, p - last.parameter, d);
        match corrected {
            Ok(c) if !back => {
                self.counters.corner_passes += 1;
                self.counters.exit_passes += 1;
                self.direction.copy_from_slice(e);
                Some(self.accept(last, x, p, ds, c, Some(e)))
            }
            _ => {
                self.reject(before, last.parameter);
                self.set_trust(&last.state, last.parameter, last.step);
                None
            }
        }
    }

    /// Whether the chord `(dx, dp)` lies along the unit tangent `t` of the incoming piece
    /// (either way, within the angle of [`RETRACE_SINE`]), or is empty.
    fn along_incoming(&self, dx: &[f64], dp: f64, t: &[f64]) -> bool {
        let n = self.metric.n;
        let length2 = self.metric.dot(dx, dp, dx, dp);
        let along = self.metric.dot(dx, dp, &t[..n], t[n]);
        let across2 = (length2 - along * along).max(0.0);
        length2 == 0.0 || across2 < RETRACE_SINE * RETRACE_SINE * length2
    }
}
