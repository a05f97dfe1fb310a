//! Taking a branch up again on another problem: the same branch in another discretisation
//! (more or fewer unknowns), from where a run stood.

use super::{Continuation, Phase};
use crate::continuation::{ContinuationError, ContinuationOptions, FoldDetector};
use crate::{Factorize, GeneralizedJacobian, ParameterDependent};

/// Where a run stood after its last accepted point ([`Continuation::resumption`]): enough
/// to go on along the same branch with another problem ([`Continuation::resume`]), e.g.
/// the same equations with more unknowns. The caller carries `state` and the state part
/// of `direction` over to the other problem's unknowns.
#[derive(Clone, Debug)]
pub struct Resumption {
    /// The last accepted point's state.
    pub state: Vec<f64>,
    /// Its parameter.
    pub parameter: f64,
    /// The unit direction (θ-norm) of the next predictor: the state part, then the
    /// parameter component (length `n + 1`).
    pub direction: Vec<f64>,
    /// The next step length.
    pub step: f64,
    /// The fold detector over the points so far: the resumed run's events go on from it,
    /// so a fold across the change of problem is found.
    pub folds: FoldDetector,
    /// Points emitted so far, the last one included.
    pub points: usize,
}

impl<'a, P, S> Continuation<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    /// Where the run stands after the last item returned (`None` before the first point,
    /// while points are still pending, or when the last point is a corner of a
    /// piecewise-affine branch, which has no tangent).
    pub fn resumption(&self) -> Option<Resumption> {
        let last = self.last.as_ref()?;
        if last.corner || !self.pending.is_empty() {
            return None;
        }
        Some(Resumption {
            state: last.state.clone(),
            parameter: last.parameter,
            direction: self.direction.clone(),
            step: self.step,
            folds: self.folds.clone(),
            points: self.points,
        })
    }

    /// Takes a branch up from `resumption` with `problem` (its state and direction carried
    /// over to this problem's unknowns by the caller). The first item is the
    /// resumption's point corrected on this problem on the hyperplane through it normal to
    /// the carried direction (regular at a fold; at the fixed parameter when that fails),
    /// with the tangent oriented along the carried direction: it replaces the last point of the run
    /// taken up (same index; the fold detector takes its new tangent). Then the run goes on with the carried
    /// step, its events and point count continuing the earlier run's.
    ///
    /// `Err` as [`Continuation::new`], and when the direction does not have `n + 1`
    /// entries or the step is not finite and positive.
    pub fn resume(
        problem: &'a mut P,
        solver: &'a mut S,
        resumption: Resumption,
        options: ContinuationOptions,
    ) -> Result<Self, ContinuationError> {
        let n = problem.dim();
        if resumption.direction.len() != n + 1 {
            return Err(ContinuationError::DimensionMismatch {
                expected: n + 1,
                found: resumption.direction.len(),
            });
        }
        if !(resumption.step.is_finite() && resumption.step > 0.0) {
            return Err(ContinuationError::InvalidOption {
                name: "resumption.step",
                value: resumption.step,
                allowed: "finite and > 0",
            });
        }
        let Resumption {
            state,
            parameter,
            direction,
            step,
            folds,
            points,
        } = resumption;
        let mut run = Self::new(problem, solver, &state, parameter, options)?;
        run.step = step.clamp(run.options.min_step, run.options.max_step);
        run.folds = folds;
        run.points = points.saturating_sub(1);
        run.replacing = points > 0;
        run.phase = Phase::Resuming {
            x0: state,
            p0: parameter,
            carried: direction,
        };
        Ok(run)
    }
}
