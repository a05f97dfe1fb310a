//! One step of the continuation: the corrector call, the tangent, the corner passes and the
//! acceptance of a corrected point (bound landing, orientation, next direction and step).

use super::super::corrector::{Constraint, Corrected, Corrector};
use super::{Accepted, Continuation};
use crate::continuation::{
    BranchPoint, ContinuationTermination, CorrectorFailure, Direction, Predictor,
};
use crate::iteration::kernel::{KernelRules, StepRule};
use crate::newton::{StateFloor, Tolerances};
use crate::{Factorize, GeneralizedJacobian, ParameterDependent};

/// The squared θ-norm of the state (parameter) part of a unit direction below which a
/// corner pass along that part is not tried.
const NEGLIGIBLE_PART: f64 = 1e-6;

impl<P, S> Continuation<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    /// Normalises the corrector's raw tangent in the θ-norm into `self.tangent`, oriented
    /// to have a non-negative inner product with `(ref_x, ref_p)`.
    pub(super) fn take_tangent(&mut self, reference: Option<&[f64]>, ref_p: f64) {
        let n = self.metric.n;
        let raw = &self.bordered.tangent;
        let norm = self.metric.norm(&raw[..n], raw[n]);
        for (t, r) in self.tangent.iter_mut().zip(raw) {
            *t = r / norm;
        }
        let t = &self.tangent;
        let orientation = match reference {
            Some(r) => self.metric.dot(&t[..n], t[n], &r[..n], r[n]),
            None => t[n] * ref_p,
        };
        if orientation < 0.0 {
            for v in &mut self.tangent {
                *v = -*v;
            }
        }
    }

    /// The corrector on this run's problem, solver, workspace and counters, from
    /// `(x, p)`; the converged point is written back. Also returns the smallest finite
    /// residual norm seen.
    pub(super) fn correct_at(
        &mut self,
        x: &mut [f64],
        p: &mut f64,
        constraint: Constraint,
    ) -> (Result<Corrected, CorrectorFailure>, f64) {
        let n = self.metric.n;
        let max_iterations = match self.iterations_left() {
            Some(0) => {
                let failure = CorrectorFailure::MaxIterations {
                    iterations: 0,
                    residual_norm: f64::INFINITY,
                };
                return (Err(failure), f64::INFINITY);
            }
            Some(left) => left.min(self.options.max_corrector_iterations),
            None => self.options.max_corrector_iterations,
        };
        let mut y = Vec::with_capacity(n + 1);
        y.extend_from_slice(x);
        y.push(*p);
        let tolerance = self.options.corrector_tolerance * self.problem.tolerance_scale(*p);
        let floor = self.options.corrector_state_floor;
        let corrector = Corrector {
            problem: &mut *self.problem,
            solver: &mut *self.solver,
            ws: &mut self.bordered,
            fallback: self.fallback,
            metric: &self.metric,
            trust: self
                .options
                .trust_factor
                .map(|_| (&self.trust, &self.main_metric)),
            rules: KernelRules {
                tolerances: Tolerances {
                    absolute_tolerance: tolerance,
                    relative_tolerance: 0.0,
                    residual_floor: 0.0,
                    // The floor measures the state, not the parameter appended to it.
                    state_floor: StateFloor {
                        entries: Some(floor.entries.map_or(n, |e| e.min(n))),
                        ..floor
                    },
                    step_tolerance: self.options.step_tolerance,
                },
                max_iterations,
                min_iterations: 1,
                step: match self.options.corrector_line_search {
                    Some(line_search) => StepRule::Backtracking {
                        memory: 1,
                        line_search,
                    },
                    None => StepRule::Full,
                },
                restore_best: false,
                stagnation: None,
            },
        };
        let outcome = corrector.correct(
            &mut y,
            constraint,
            &mut self.work,
            &mut self.corrector_counts,
        );
        if let Err(CorrectorFailure::Evaluation { error, .. }) = &outcome.0 {
            if error.ends_run() {
                let parameter = self.last.as_ref().map_or(*p, |l| l.parameter);
                self.finish(ContinuationTermination::ProblemFailed {
                    parameter,
                    error: error.clone(),
                });
            }
        }
        x.copy_from_slice(&y[..n]);
        *p = y[n];
        outcome
    }

    /// Corrects `(x, p)` and takes the tangent there. A resumed run's start (`carried`
    /// given) is corrected first on the hyperplane through `(x, p)` normal to `carried`
    /// (regular at a fold, where the new problem's branch may not reach `p`), then, if
    /// that fails, at fixed `p`; its tangent is oriented along `carried`. Any other start
    /// is corrected at fixed `p`, its tangent oriented so that `p` moves as `direction`
    /// says.
    pub(super) fn correct_start(
        &mut self,
        x: &mut [f64],
        p: &mut f64,
        (carried, direction): (Option<&[f64]>, Direction),
    ) -> Result<Corrected, CorrectorFailure> {
        if let Some(carried) = carried {
            let n = self.metric.n;
            let (x0, p0) = (x.to_vec(), *p);
            self.metric
                .state_normal(&carried[..n], &mut self.bordered.w);
            let w_p = self.metric.parameter_dot(carried[n], 1.0);
            let target = self
                .bordered
                .w
                .iter()
                .zip(&x0)
                .map(|(w, v)| w * v)
                .sum::<f64>()
                + w_p * p0;
            let normal = Constraint {
                arclength: true,
                w_p,
                target,
            };
            if let Ok(corrected) = self.correct_at(x, p, normal).0 {
                self.take_tangent(Some(carried), 0.0);
                self.direction.copy_from_slice(&self.tangent);
                return Ok(corrected);
            }
            if self.finished() {
                return Err(CorrectorFailure::MaxIterations {
                    iterations: 0,
                    residual_norm: f64::INFINITY,
                });
            }
            x.copy_from_slice(&x0);
            *p = p0;
            self.problem.set_parameter(p0);
        }
        let constraint = Constraint {
            arclength: false,
            w_p: 1.0,
            target: *p,
        };
        let corrected = self.correct_at(x, p, constraint).0?;
        self.take_tangent(carried, direction.sign());
        self.direction.copy_from_slice(&self.tangent);
        Ok(corrected)
    }

    /// The corner passes of the module documentation (*Corners*), with step `ds` from
    /// `last` along the current direction: first on the hyperplane normal to the direction's
    /// state part, then at the next parameter `p + ds / sqrt((1 - θ) / s_p²)` (sign of the
    /// direction's parameter component). `Some(result of accept)` when one converged.
    pub(super) fn pass_corner(&mut self, last: &BranchPoint, ds: f64) -> Option<Accepted> {
        let n = self.metric.n;
        let d = self.direction.clone();
        let state_part = self.metric.state_dot(&d[..n], &d[..n]);
        let parameter_part = self.metric.parameter_dot(d[n], d[n]);
        for on_state in [true, false] {
            if self.iterations_left() == Some(0) {
                return None;
            }
            let (scale, along, constraint) = if on_state {
                if state_part < NEGLIGIBLE_PART {
                    continue;
                }
                self.direction_weights();
                let mut along = d.clone();
                along[n] = 0.0;
                let target: f64 = self
                    .bordered
                    .w
                    .iter()
                    .zip(&last.state)
                    .zip(&d)
                    .map(|((w, x), di)| w * (x + ds * di))
                    .sum();
                let constraint = Constraint {
                    arclength: true,
                    w_p: 0.0,
                    target,
                };
                (ds, along, constraint)
            } else {
                if parameter_part < NEGLIGIBLE_PART {
                    continue;
                }
                let step_p = ds / self.metric.parameter_dot(1.0, 1.0).sqrt() * d[n].signum();
                let mut along = vec![0.0; n + 1];
                along[n] = d[n].signum();
                let constraint = Constraint {
                    arclength: false,
                    w_p: 1.0,
                    target: last.parameter + step_p,
                };
                (step_p / d[n], along, constraint)
            };
            let mut x: Vec<f64> = last
                .state
                .iter()
                .zip(&d)
                .map(|(x, di)| x + scale * di)
                .collect();
            let mut p = last.parameter + scale * d[n];
            let before = self.corrector_counts.iterations;
            match self.correct_at(&mut x, &mut p, constraint).0 {
                Ok(c) => {
                    self.counters.corner_passes += 1;
                    let dx: Vec<f64> = x.iter().zip(&last.state).map(|(a, b)| a - b).collect();
                    let step = self.metric.norm(&dx, p - last.parameter);
                    return Some(self.accept(last, x, p, step, c, Some(&along)));
                }
                Err(_) => {
                    self.reject(before, last.parameter);
                    if self.finished() {
                        return None;
                    }
                }
            }
        }
        None
    }

    /// Turns a converged correction into the next branch point: bound landing, tangent
    /// orientation, next direction and step. Returns the point and the θ-length of the
    /// chord from `last` (`None` when the run ends on a bound without a new point).
    pub(super) fn accept(
        &mut self,
        last: &BranchPoint,
        mut x: Vec<f64>,
        mut p: f64,
        ds: f64,
        corrected: Corrected,
        along: Option<&[f64]>,
    ) -> Accepted {
        let n = self.metric.n;
        self.consecutive_failures = 0;
        let direction = self.direction.clone();
        self.take_tangent(Some(&direction), 0.0);
        let mut iterations = corrected.iterations;
        let mut residual_norm = corrected.residual_norm;
        let mut step = ds;

        // Leaving the bounds: re-solve at the bound from the interpolated point.
        let bound = if p > self.options.parameter_max {
            Some(self.options.parameter_max)
        } else if p < self.options.parameter_min {
            Some(self.options.parameter_min)
        } else {
            None
        };
        if bound == Some(last.parameter) {
            // Already on the bound and heading out: nothing new to report.
            self.problem.set_parameter(last.parameter);
            self.finish(ContinuationTermination::ReachedBound {
                parameter: last.parameter,
                bound: last.parameter,
            });
            return None;
        }
        if let Some(pb) = bound {
            if let Some((xb, pbv, c, lambda)) = self.land_on_bound(last, (&x, p), pb, &direction) {
                x = xb;
                p = pbv;
                iterations += c.iterations;
                residual_norm = c.residual_norm;
                step = lambda * ds;
            }
        }

        // Secant direction for the next predictor.
        let dx: Vec<f64> = x.iter().zip(&last.state).map(|(a, b)| a - b).collect();
        let dpar = p - last.parameter;
        let chord = self.metric.norm(&dx, dpar);
        self.turn_along((&dx, dpar, chord), along);

        let factor = (self.options.target_iterations as f64 / iterations.max(1) as f64)
            .sqrt()
            .clamp(0.5, 2.0);
        self.step = (ds * factor).clamp(self.options.min_step, self.options.max_step);

        let point = BranchPoint {
            state: x,
            parameter: p,
            iterations,
            residual_norm,
            step,
            tangent_parameter: self.tangent[n],
            corner: false,
        };
        if let Some(pb) = bound {
            self.finish(ContinuationTermination::ReachedBound {
                parameter: point.parameter,
                bound: pb,
            });
        }
        Some((point, chord))
    }

    /// The point `(x, p)` past the bound `pb` taken back to it: the corrector at the bound
    /// from the point interpolated between `last` and `(x, p)`. The point, the correction
    /// and the fraction of the chord, with the tangent oriented along `direction`; `None`
    /// when it failed (the tangent kept, the problem at `p`).
    fn land_on_bound(
        &mut self,
        last: &BranchPoint,
        (x, p): (&[f64], f64),
        pb: f64,
        direction: &[f64],
    ) -> Option<(Vec<f64>, f64, Corrected, f64)> {
        let lambda = (pb - last.parameter) / (p - last.parameter);
        let mut xb: Vec<f64> = last
            .state
            .iter()
            .zip(x)
            .map(|(a, b)| a + lambda * (b - a))
            .collect();
        let mut pbv = pb;
        let constraint = Constraint {
            arclength: false,
            w_p: 1.0,
            target: pb,
        };
        let saved_tangent = self.tangent.clone();
        match self.correct_at(&mut xb, &mut pbv, constraint).0 {
            Ok(c) => {
                self.take_tangent(Some(direction), 0.0);
                Some((xb, pbv, c, lambda))
            }
            Err(_) => {
                self.tangent = saved_tangent;
                // Keep the point outside the bound; the problem follows it.
                self.problem.set_parameter(p);
                None
            }
        }
    }

    /// Orients the tangent along the step just taken (the chord `(dx, dpar)` of θ-length
    /// `chord`, or `along` after a corner pass) and sets the next predictor's direction.
    fn turn_along(&mut self, (dx, dpar, chord): (&[f64], f64, f64), along: Option<&[f64]>) {
        let n = self.metric.n;
        // Orient the tangent along the step just taken: where the branch turns sharply the
        // predictor's direction can make an obtuse angle with the new tangent, and orienting
        // by it would reverse the tangent (a spurious fold, and a tangent predictor heading
        // back along the branch). The secant always has a positive component along the
        // predictor (the arclength constraint), so it is the forward direction here.
        let forward = match along {
            Some(a) => self
                .metric
                .dot(&self.tangent[..n], self.tangent[n], &a[..n], a[n]),
            None if chord > 0.0 => self
                .metric
                .dot(&self.tangent[..n], self.tangent[n], dx, dpar),
            None => 0.0,
        };
        if forward < 0.0 {
            for v in &mut self.tangent {
                *v = -*v;
            }
        }

        match self.options.predictor {
            // After a corner the chord cuts across it: the new piece's tangent is the way on.
            Predictor::Secant if chord > 0.0 && along.is_none() => {
                for (d, v) in self.direction.iter_mut().zip(dx) {
                    *d = v / chord;
                }
                self.direction[n] = dpar / chord;
            }
            _ => self.direction.copy_from_slice(&self.tangent),
        }
    }
}
