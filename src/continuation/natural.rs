//! Natural-parameter continuation: Newton at a list of parameters, each from the previous
//! solution. It fails or jumps at folds; it exists to be compared with pseudo-arclength.

use super::ContinuationError;
use crate::newton::{NewtonOptions, NewtonSolver, Termination, WorkCounters};
use crate::{Factorize, GeneralizedJacobian, ParameterDependent};

/// One solved point of a natural-parameter sweep.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepPoint {
    /// The state.
    pub state: Vec<f64>,
    /// The parameter.
    pub parameter: f64,
    /// Newton iterations.
    pub iterations: usize,
    /// `|F|` at the point.
    pub residual_norm: f64,
}

/// Where and why a natural sweep stopped early.
#[derive(Clone, Debug, PartialEq)]
pub struct SweepFailure {
    /// Index in the requested parameters.
    pub index: usize,
    /// The parameter.
    pub parameter: f64,
    /// Why Newton stopped.
    pub termination: Termination,
    /// Newton iterations spent there.
    pub iterations: usize,
    /// `|F|` at Newton's best iterate there.
    pub residual_norm: f64,
}

/// Result of a natural-parameter sweep: the solved points in order, and the first failure
/// (the sweep stops there).
#[derive(Clone, Debug, PartialEq)]
pub struct NaturalSweep {
    /// Points solved before the first failure.
    pub points: Vec<SweepPoint>,
    /// The first failure, if any.
    pub failure: Option<SweepFailure>,
    /// Work done (summed over the Newton solves).
    pub counters: WorkCounters,
}

/// Natural-parameter continuation: for each `p` in `parameters`, semismooth Newton
/// ([`crate::newton`], with `options`) at fixed `p` from the previous solution (`x0` for
/// the first). At a fold it fails or jumps to another branch; it exists to be compared with
/// the pseudo-arclength [`Continuation`](super::Continuation). Stops at the first failure; the problem's
/// parameter is then left at the last solved point.
pub fn natural_sweep<P, S>(
    problem: &mut P,
    solver: &mut S,
    x0: &[f64],
    parameters: &[f64],
    options: &NewtonOptions,
) -> Result<NaturalSweep, ContinuationError>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    let mut newton = NewtonSolver::<P::Jacobian>::new(*options)?;
    let n = problem.dim();
    if x0.len() != n {
        return Err(ContinuationError::DimensionMismatch {
            expected: n,
            found: x0.len(),
        });
    }
    if let Some(&bad) = parameters.iter().find(|p| !p.is_finite()) {
        return Err(ContinuationError::InvalidStart {
            parameter: bad,
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
        });
    }
    let mut counters = WorkCounters::default();
    let mut points: Vec<SweepPoint> = Vec::with_capacity(parameters.len());
    let mut x = x0.to_vec();
    let mut failure = None;
    for (index, &parameter) in parameters.iter().enumerate() {
        problem.set_parameter(parameter);
        let report = newton.solve(problem, solver, &mut x)?;
        counters += report.counters;
        if report.converged() {
            points.push(SweepPoint {
                state: x.clone(),
                parameter,
                iterations: report.iterations,
                residual_norm: report.residual_norm(),
            });
        } else {
            if let Some(last) = points.last() {
                problem.set_parameter(last.parameter);
            }
            failure = Some(SweepFailure {
                index,
                parameter,
                residual_norm: report.residual_norm(),
                iterations: report.iterations,
                termination: report.termination,
            });
            break;
        }
    }
    Ok(NaturalSweep {
        points,
        failure,
        counters,
    })
}
