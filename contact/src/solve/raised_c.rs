//! SSN-HB from a start the default complementarity constant `c` cannot leave: the same
//! start solved again with `c` raised.
//!
//! The default `c` is scaled by the static stiffness the contacts see together. A contact on
//! a light part tied stiffly to the rest (a pad on a spring of 1,000 carried by a chain of
//! springs of 1 or 2: static stiffness 0.111) sees far more at the higher harmonics, where
//! the heavy part no longer follows: there the force term of the equation outweighs
//! `c (G u - g)` and Newton wanders (measured on that chain: from zero the default fails at
//! H = 30, 60 and 80 after 200 iterations where 10 times it converges in 41-69; started from
//! the raised answer, the default still fails at H = 60 in 2 of 3 trials). The equation of
//! the raised `c` has the same exact solution and Galerkin zeros within the truncation
//! error of the default's (they move with `c`), so its answer is returned, with the `c` it
//! solved in the solution.

use semismooth::newton::NewtonReport;
use semismooth::polyalgorithm::SmoothingOf;

use super::{newton_hb, RunError};
use crate::hb::SsnHb;
use crate::model::StructuralModel;
use crate::settings::{GlobalizationChoice, SolverSettings};

/// How much the default `c` is raised for the second start.
pub const RAISED_C_FACTOR: f64 = 10.0;

/// Newton on `problem` (built from `settings`) from `x`. When `settings` leave
/// `c` to its default and the globalization to the polyalgorithm (`auto`, of which this is
/// the last resort) and the run does not converge, the same start is solved with
/// [`RAISED_C_FACTOR`] times `c`; when that converges, `problem` keeps the raised `c`
/// and `x` its answer, the report counting both runs' iterations and listing their attempts
/// in order. When the raised run does not converge either, `x` and the report are the first
/// run's.
pub(super) fn ssn_hb_newton(
    problem: &mut SsnHb,
    x: &mut [f64],
    settings: &SolverSettings,
    model: &StructuralModel,
) -> Result<NewtonReport, RunError> {
    let may_raise = may_raise_c(settings, problem.contacts());
    // The start is kept only when a second run may need it (most solves converge).
    let start = may_raise.then(|| x.to_vec());
    let first = newton_hb(problem, x, settings, model, (0.0, Some(SmoothingOf::new())))?;
    let Some(start) = start.filter(|_| !first.converged()) else {
        return Ok(first);
    };
    // `c` enters only the contact rows: the same problem with `c` raised (no rebuild, and
    // no second problem held beside the first).
    let first_c = problem.c();
    problem.set_c(RAISED_C_FACTOR * first_c)?;
    let first_x = x.to_vec();
    x.copy_from_slice(&start);
    let raised = newton_hb(problem, x, settings, model, (0.0, Some(SmoothingOf::new())))?;
    if !raised.converged() {
        problem.set_c(first_c)?;
        x.copy_from_slice(&first_x);
        return Ok(first);
    }
    Ok(after_raise(first, raised))
}

/// Whether a run with `settings` on a problem with `contacts` contact rows may be repeated
/// with `c` raised ([`ssn_hb_newton`]).
pub(super) fn may_raise_c(settings: &SolverSettings, contacts: usize) -> bool {
    settings.c.is_none() && contacts > 0 && settings.globalization == GlobalizationChoice::Auto
}

/// The report of the converged raised run counting the first run's iterations and work,
/// the attempts of both in order.
pub(super) fn after_raise(first: NewtonReport, raised: NewtonReport) -> NewtonReport {
    let mut attempts = first.attempts;
    attempts.extend(raised.attempts.iter().cloned());
    let mut report = raised;
    report.attempts = attempts;
    report.iterations += first.iterations;
    report.counters += first.counters;
    report
}
