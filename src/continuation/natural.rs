//! Natural-parameter continuation: a solve at each of a list of parameters, each from the
//! previous solution. It fails or jumps at folds; it exists to be compared with
//! pseudo-arclength.

use super::ContinuationError;
use crate::newton::{NewtonError, NewtonReport, Termination, WorkCounters};
use crate::{GeneralizedJacobian, ParameterDependent};

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
    /// Work done (summed over the solves).
    pub counters: WorkCounters,
}

/// Natural-parameter continuation: for each `p` in `parameters`, `solve(problem, x)` at
/// fixed `p` from the previous solution (`x0` for the first): a Newton run
/// ([`NewtonSolver::solve`](crate::newton::NewtonSolver::solve)) or the polyalgorithm
/// ([`Polyalgorithm::solve`](crate::polyalgorithm::Polyalgorithm::solve)), with the linear
/// solver the closure holds. At a fold it fails or jumps to another branch; it exists to be
/// compared with the pseudo-arclength [`Continuation`](super::Continuation). Stops at the
/// first point that does not converge ([`NaturalSweep::failure`]); the problem's parameter
/// is then left at the last solved point. `Err` when it could not run: a start of the wrong
/// length, a parameter that is not finite, or a solve that could not run
/// ([`ContinuationError::Newton`]).
///
/// ```
/// use faer::Mat;
/// use semismooth::continuation::natural_sweep;
/// use semismooth::linalg::FaerDenseLu;
/// use semismooth::newton::{NewtonOptions, NewtonSolver};
/// use semismooth::{EvaluationError, GeneralizedJacobian, ParameterDependent, Residual};
///
/// /// x^2 - p = 0 from x = 1: the root sqrt(p).
/// struct Root { p: f64 }
/// impl Residual for Root {
///     fn dim(&self) -> usize { 1 }
///     fn residual(&mut self, x: &[f64], f: &mut [f64]) -> Result<(), EvaluationError> {
///         f[0] = x[0] * x[0] - self.p;
///         Ok(())
///     }
/// }
/// impl GeneralizedJacobian for Root {
///     type Jacobian = Mat<f64>;
///     fn new_jacobian(&self) -> Mat<f64> { Mat::zeros(1, 1) }
///     fn jacobian(&mut self, x: &[f64], j: &mut Mat<f64>) -> Result<(), EvaluationError> {
///         j[(0, 0)] = 2.0 * x[0];
///         Ok(())
///     }
/// }
/// impl ParameterDependent for Root {
///     fn parameter(&self) -> f64 { self.p }
///     fn set_parameter(&mut self, p: f64) { self.p = p; }
/// }
///
/// let mut newton = NewtonSolver::new(NewtonOptions::default()).unwrap();
/// let mut lu = FaerDenseLu::new();
/// let sweep = natural_sweep(&mut Root { p: 1.0 }, &[1.0], &[1.0, 4.0, 9.0], |p, x| {
///     newton.solve(p, &mut lu, x)
/// })
/// .unwrap();
/// assert!(sweep.failure.is_none());
/// assert!((sweep.points[2].state[0] - 3.0).abs() < 1e-12);
/// ```
pub fn natural_sweep<P>(
    problem: &mut P,
    x0: &[f64],
    parameters: &[f64],
    mut solve: impl FnMut(&mut P, &mut [f64]) -> Result<NewtonReport, NewtonError>,
) -> Result<NaturalSweep, ContinuationError>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
{
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
        let report = solve(problem, &mut x)?;
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
