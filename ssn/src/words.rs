//! The library's typed results in words: how a run, a sweep or a stability analysis ended,
//! as the text summaries, the JSON `termination` / `diagnosis` / `stability_note` fields and
//! the tables print them.

use semismooth::continuation::ContinuationTermination;
use semismooth::lemke::{LemkeOptions, LemkeTermination};
use semismooth_contact::settings::{LcpScheme, Method};
use semismooth_contact::solutions::FailedCorrection;
use semismooth_contact::solve::{Diagnosis, Termination};
use semismooth_contact::stability::Undecided;
use semismooth_contact::sweep::{FrequencyResponse, SweepTermination};

/// How a run ended: `converged`, the core's name of a Newton termination, or a sentence
/// with the numbers for Lemke's ray and pivot limit and a march that did not settle.
pub fn termination(t: &Termination) -> String {
    match t {
        Termination::Lemke {
            outcome: LemkeTermination::Ray,
            pivots,
            smallest_symmetric_eigenvalue,
            ..
        } => format!(
            "ray after {pivots} pivots (smallest eigenvalue of the symmetric part of A: {:e})",
            smallest_symmetric_eigenvalue.unwrap_or(f64::NAN)
        ),
        Termination::Lemke {
            outcome: LemkeTermination::PivotLimit,
            pivots,
            pivot_limit,
            order,
            ..
        } => {
            // The run used Lemke's default options: name their rule when it gave the limit.
            let default = LemkeOptions::default();
            let rule = if default.pivot_limit(*order) == *pivot_limit {
                format!(" = {}", default.pivot_limit_rule())
            } else {
                String::new()
            };
            format!(
                "pivot-limit ({pivots} pivots done, the limit {pivot_limit}{rule} for n = \
                 {order}): the tip values are those of the unfinished path's last basis, not of \
                 a solution"
            )
        }
        Termination::March {
            steady: false,
            period_change,
            tolerance,
            periods,
        } => format!(
            "not-steady: period-to-period change {period_change:.3e} above the tolerance \
             {tolerance:e} after {periods} periods (solver.max_periods)"
        ),
        other => other.to_string(),
    }
}

/// What makes a run that did not converge hard, and what to change.
pub fn diagnosis(d: Diagnosis) -> String {
    match d {
        Diagnosis::AlternatingNullVector => format!(
            "every contact dof has mass or damping, so the trapezoidal LCP's Nyquist receptance \
             is 0 and a contact force alternating node to node moves nothing (a null vector of \
             A): solutions chatter and are nearly degenerate; lcp_scheme = \"{}\" has no such \
             vector",
            LcpScheme::Bdf2.name()
        ),
        other => format!("{other:?}"),
    }
}

/// Why a sweep stopped, with the frequencies in units of `omega_1`.
pub fn sweep_termination(r: &FrequencyResponse) -> String {
    let ratio = |omega: f64| omega / r.omega_1;
    match &r.termination {
        SweepTermination::StartNotConverged {
            termination,
            iterations,
            residual_norm,
        } => format!(
            "the start at omega_ratio {} did not converge: {termination} after {iterations} \
             iterations (|F| = {residual_norm:e})",
            ratio(r.omega_from)
        ),
        SweepTermination::StartNotCorrected(failure) => {
            format!("the start point could not be corrected: {failure}")
        }
        SweepTermination::Branch(t) => branch_termination(r, t),
        SweepTermination::Unexplained => "stopped without a reason".to_string(),
        other => format!("{other:?}"),
    }
}

fn branch_termination(r: &FrequencyResponse, t: &ContinuationTermination) -> String {
    let ratio = |omega: f64| omega / r.omega_1;
    match t {
        ContinuationTermination::Retraced { parameter } => format!(
            "stalled at omega_ratio {}: no step ahead (a corner the continuation cannot turn), \
             and the only step found goes back along the branch",
            ratio(*parameter)
        ),
        ContinuationTermination::ReachedBound { parameter, bound } => {
            let end = if *bound != r.omega_to {
                " (the start of the sweep: the branch turned back)".to_string()
            } else if parameter == bound {
                " (the end of the sweep)".to_string()
            } else {
                format!(
                    " (the end of the sweep; last point at {} not re-solved on it)",
                    ratio(*parameter)
                )
            };
            format!("reached omega_ratio {}{end}", ratio(*bound))
        }
        ContinuationTermination::IterationBudgetSpent { parameter, budget } => format!(
            "the {budget} corrector iterations allowed were spent at omega_ratio {}",
            ratio(*parameter)
        ),
        ContinuationTermination::MaxPoints { points } => format!(
            "point limit ({points} points) at omega_ratio {}",
            r.omega.last().map_or(f64::NAN, |w| ratio(*w))
        ),
        ContinuationTermination::StepTooSmall {
            parameter,
            step,
            failure,
            ..
        } => format!(
            "step too small at omega_ratio {}: the attempt with step {step:e} failed: {failure}",
            ratio(*parameter)
        ),
        ContinuationTermination::TooManyFailures {
            parameter,
            failures,
            failure,
            ..
        } => format!(
            "{failures} failed steps in a row at omega_ratio {}: {failure}",
            ratio(*parameter)
        ),
        ContinuationTermination::StartFailed { failure, .. }
        | ContinuationTermination::SegmentStartFailed { failure, .. } => {
            format!("the start point could not be corrected: {failure}")
        }
        other => other.to_string(),
    }
}

/// Why a solution's stability is not decided.
pub fn undecided(u: &Undecided) -> String {
    match u {
        Undecided::MassCarryingContact => {
            "a contact dof has mass: the flow has impacts and the monodromy needs the impact \
             law's saltation matrices, which are not implemented (use a modified mass)"
                .to_string()
        }
        Undecided::Friction { points } => format!(
            "{points} friction points: the monodromy of the stepping map through stick and \
             slip is not implemented"
        ),
        Undecided::TooManyDofs { dofs, limit } => {
            format!("{dofs} dofs: the dense monodromy is formed only up to {limit} dofs (2N x 2N)")
        }
        Undecided::OrbitNotFound {
            termination,
            iterations,
            residual_norm,
        } => format!(
            "the periodic orbit of the time-stepping map was not found near the \
             harmonic-balance solution: Newton on the period map stopped ({termination:?}) \
             after {iterations} iterations with |F| = {residual_norm:e}"
        ),
        Undecided::ShootingNotRun(err) => {
            format!("Newton on the period map could not run: {err}")
        }
        Undecided::NotHarmonicBalance(method) => format!(
            "stability is computed for harmonic-balance branches ({}, {}), not {}",
            Method::SsnHb.name(),
            Method::PenaltyHb.name(),
            method.name()
        ),
        Undecided::Failed(err) => format!("stability not computed: {err}"),
        other => format!("{other:?}"),
    }
}

/// A crossing whose correction did not converge.
pub fn failed_correction(f: &FailedCorrection) -> String {
    format!(
        "crossing between points {} and {}: {} (|F| = {:e})",
        f.branch_index - 1,
        f.branch_index,
        termination(&f.termination),
        f.residual_norm
    )
}
