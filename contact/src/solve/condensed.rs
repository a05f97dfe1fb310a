//! SSN-HB solved on the contact unknowns with one per-harmonic factorization held at a time:
//! the exact unreduced path of models too large for the structured solver's `H + 1`
//! factorizations.
//!
//! Newton runs on the `m (2H + 1)` contact-force coefficients of
//! [`CondensedSsnHb::one_factorization_at_a_time`] (dense algebra; per harmonic only
//! `Z_k^{-1} G^T` and `Z_k^{-1} F` are kept); the displacements `U = A^{-1} (F + G^T
//! Lambda)` are expanded from those at the end, and the outputs are [`solve`]'s of the full
//! problem. The same equations as [`solve`]'s SSN-HB, with its second start at
//! [`super::RAISED_C_FACTOR`] times `c` when the first does not converge (the receptances
//! do not depend on `c`: nothing is refactored).

use std::time::Instant;

use semismooth::linalg::FaerDenseLu;
use semismooth::polyalgorithm::SmoothingOf;
use semismooth::Residual;

use super::raised_c::{after_raise, may_raise_c, RAISED_C_FACTOR};
#[cfg(doc)]
use super::solve;
use super::{
    hb_options, load_scaled_tolerance, newton_options, ssn_hb_solution, Outcome, RunError,
    Solution, SolveRequest, HB_OUTPUT_POINTS,
};
use crate::hb::{check_len, CondensedSsnHb};
use crate::model::Structure;
use crate::settings::{Method, SolverSettings};

/// Solves `structure` forced at `omega` by SSN-HB condensed onto its contact unknowns, one
/// harmonic's sparse factorization in memory at a time (module documentation), from the
/// contact-force coefficients `start` (`m (2H + 1)`, index `j m + row`, e.g. the last
/// entries of a reduced model's [`Solution::state`] with the same contact rows; zero when
/// `None`: the condensed unknowns start at the linear response, which the globalization
/// may not leave where the full problem's start `U = 0` does). Only [`Method::SsnHb`] is supported (another method is
/// [`RunError::Unsupported`]); the settings' linear solver is not used (dense LU on the
/// contact unknowns, sparse LU per harmonic).
pub fn solve_condensed(
    structure: &Structure,
    omega: f64,
    settings: &SolverSettings,
    start: Option<&[f64]>,
) -> Result<Solution, RunError> {
    if settings.method != Method::SsnHb {
        return Err(RunError::Unsupported {
            method: "the condensed exact solve",
            what: "the SSN-HB formulation",
        });
    }
    let model = &structure.model;
    let mut problem =
        CondensedSsnHb::one_factorization_at_a_time(model, omega, &hb_options(settings))?;
    let start_lambda = match start {
        Some(forces) => {
            check_len("contact-force coefficients", problem.dim(), forces.len())?;
            forces.to_vec()
        }
        None => vec![0.0; problem.dim()],
    };
    let mut lambda = start_lambda.clone();
    let options = newton_options(&SolverSettings {
        tolerance: load_scaled_tolerance(settings.tolerance, model),
        ..settings.clone()
    });
    let start = Instant::now();
    let newton = |problem: &mut CondensedSsnHb, lambda: &mut [f64]| {
        options.solve(
            problem,
            &mut FaerDenseLu::new(),
            lambda,
            Some(SmoothingOf::new()),
        )
    };
    let mut report = newton(&mut problem, &mut lambda)?;
    if !report.converged() && may_raise_c(settings, structure.model.contacts.len()) {
        let first_c = problem.c();
        problem.set_c(RAISED_C_FACTOR * first_c)?;
        let mut raised_lambda = start_lambda;
        let raised = newton(&mut problem, &mut raised_lambda)?;
        if raised.converged() {
            report = after_raise(report, raised);
            lambda = raised_lambda;
        } else {
            problem.set_c(first_c)?;
        }
    }
    let seconds = start.elapsed().as_secs_f64();
    let x = problem.expand(&lambda)?;
    let request = SolveRequest {
        rod: structure,
        omega,
        settings,
        warm_start: None,
    };
    let points = HB_OUTPUT_POINTS.max(settings.time_samples);
    let outcome = Outcome::of_newton(&report, seconds);
    let mut solution = ssn_hb_solution(problem.full_problem(), request, outcome, x, points)?;
    solution.settings = solution.solved_settings(settings);
    Ok(solution)
}
