//! The piecewise-affine capability of the driver: the piece of each accepted point and the
//! walks over corners ([`super::super::pieces`]).

use super::super::pieces::{AffineOps, PiecewiseAffine, Walk, Walker};
use super::{Continuation, Pieces, Resume, Tracked};
use crate::continuation::{BranchPoint, FoldDetector};
use crate::{Factorize, GeneralizedJacobian, ParameterDependent};

impl<P, S> Continuation<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    /// The piece of `point` against the last one; on a change, the corners between them
    /// are walked and emitted, and the branch may resume elsewhere.
    pub(super) fn track_pieces(&mut self, point: &BranchPoint) -> Tracked {
        let k = self.points;
        let remaining = self.options.max_points.saturating_sub(k);
        let previous = self.last.clone();
        let label = self.walker().and_then(|mut w| {
            w.problem.set_parameter(point.parameter);
            w.piece(&point.state)
        });
        let (Some(mut label), Some(pieces)) = (label, self.pieces.as_ref()) else {
            // No piece to compare with: the point stands as it is.
            return Tracked::Resume(None);
        };
        let (current, mut travel) = (pieces.current.clone(), pieces.travel);
        let mut resume = None;
        let mut corners = Vec::new();
        match (&current, &previous) {
            (Some(current), Some(prev)) if *current != label && k > 0 => {
                let walk = self
                    .walker()
                    .and_then(|mut w| w.cross(&prev.state, prev.parameter, travel, remaining));
                if let Some(Walk {
                    corners: found,
                    start,
                    start_parameter,
                    direction,
                }) = walk
                {
                    let along = direction.sign();
                    let start_label = self.walker().and_then(|mut w| {
                        w.problem.set_parameter(start_parameter);
                        w.piece(&start)
                    });
                    if found.len() > 1 || start_label.as_ref() != Some(&label) {
                        if let Some(start_label) = start_label {
                            label = start_label;
                        }
                        resume = Some(Resume::Fresh(start, start_parameter, direction));
                    } else if (point.parameter - prev.parameter) * along < 0.0 {
                        resume = Some(Resume::Repeat(direction));
                    }
                    corners = found;
                    travel = along;
                } else {
                    travel = (point.parameter - prev.parameter).signum();
                }
                self.problem.set_parameter(point.parameter);
            }
            (Some(_), Some(prev)) if k > 0 && point.parameter != prev.parameter => {
                travel = (point.parameter - prev.parameter).signum();
            }
            _ => {}
        }
        if let Some(pieces) = self.pieces.as_mut() {
            pieces.current = Some(label);
            pieces.travel = travel;
        }
        if !self.emit_corners(corners) {
            return Tracked::Ended;
        }
        Tracked::Resume(resume)
    }

    /// Emits corners found by a walk; `false` if the run ended on one.
    pub(super) fn emit_corners(&mut self, corners: Vec<(Vec<f64>, f64)>) -> bool {
        for (state, parameter) in corners {
            let point = BranchPoint {
                state,
                parameter,
                iterations: 0,
                residual_norm: 0.0,
                step: 0.0,
                tangent_parameter: 0.0,
                corner: true,
            };
            if !self.emit(point, 0.0) || self.finished() {
                return false;
            }
        }
        true
    }

    /// The corner walker on this run's problem, solver and counters.
    pub(super) fn walker(&mut self) -> Option<Walker<'_, P, S>> {
        let ops = self.pieces.as_ref()?.ops;
        let parameter_unit = 1.0 / self.main_metric.parameter_dot(1.0, 1.0).sqrt();
        Some(Walker {
            problem: &mut *self.problem,
            solver: &mut *self.solver,
            jac: &mut self.bordered.jac,
            ops,
            metric: &self.main_metric,
            work: &mut self.work,
            reach: self.options.max_step * parameter_unit,
            shift: 0.25 * self.options.initial_step * parameter_unit,
            walk: self.options.max_step,
            bounds: (self.options.parameter_min, self.options.parameter_max),
        })
    }
}

impl<'a, P, S> Continuation<'a, P, S>
where
    P: PiecewiseAffine + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    /// Crosses the corners of a piecewise-affine branch exactly (module documentation,
    /// *Piecewise-affine branches*): when an accepted point lies on another piece than the
    /// last one, or when the steps fail for good, the corners ahead are walked on the
    /// pieces themselves and emitted as branch points ([`BranchPoint::corner`], a
    /// [`ContinuationEvent::Corner`](crate::continuation::ContinuationEvent::Corner) each); folds are then reported at corners, never
    /// interpolated.
    pub fn with_affine_pieces(mut self) -> Self {
        self.pieces = Some(Pieces {
            ops: AffineOps::of(),
            current: None,
            travel: self.options.direction.sign(),
        });
        self.folds =
            FoldDetector::new(false).with_min_excursion(self.options.fold_parameter_excursion());
        self
    }
}
