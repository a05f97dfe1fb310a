//! The library's typed results in words: how a run, a sweep or a stability analysis ended,
//! as the text summaries, the JSON `termination` / `diagnosis` / `stability_note` fields and
//! the tables print them.

use semismooth::continuation::ContinuationTermination;
use semismooth::lemke::{LemkeOptions, LemkeTermination};
use semismooth_contact::accuracy::{Discretisation, EstimateBasis, NoEstimate, SearchStop};
use semismooth_contact::settings::{LcpScheme, Method};
use semismooth_contact::solutions::FailedCorrection;
use semismooth_contact::solve::{Diagnosis, DiscretisationKind, Solution, Termination};
use semismooth_contact::stability::Undecided;
use semismooth_contact::sweep::adaptive::BranchAccuracy;
use semismooth_contact::sweep::fold_accuracy::{FoldAccuracy, FoldStop};
use semismooth_contact::sweep::peak::{LocatedPeak, PeakLocation};
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
            r.points.last().map_or(f64::NAN, |p| ratio(p.omega))
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
            "a contact dof has mass: the time-stepping map of the discrete monodromy has no \
             impact law (the monodromy along the harmonic-balance contact phases decides it)"
                .to_string()
        }
        Undecided::Friction { points } => format!(
            "{points} friction points: the monodromy of the stepping map through stick and \
             slip is not implemented"
        ),
        Undecided::TooManyDofs { dofs, limit } => {
            format!("{dofs} dofs: the dense monodromy is formed only up to {limit} dofs (2N x 2N)")
        }
        Undecided::TooCostly { phases, work } => format!(
            "{phases} contact phases per period: the monodromy would take about {work:.1e} \
             floating-point operations (limit {:.0e})",
            semismooth_contact::stability::MAX_WORK
        ),
        Undecided::SectorContactHarmonics { harmonics } => format!(
            "a cyclic sector whose contacts close, at H = {harmonics}: Hill's method decides \
             it from H = {} (below, its truncation error turned verdicts against the full \
             disk's monodromy)",
            semismooth_contact::stability::SECTOR_CONTACT_HARMONICS
        ),
        Undecided::Marginal { max_abs } => format!(
            "the largest Floquet multiplier has modulus {max_abs} (on the unit circle to within \
             {:e}: an undamped model)",
            semismooth_contact::stability::MARGINAL
        ),
        Undecided::Phases(err) => format!("the contact phases' dynamics: {err}"),
        Undecided::NotRequested => {
            "stability not computed ([sweep] stability = false or --no-stability)".to_string()
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

/// A discretisation of `method` as the tables print it: `H=20 Nt=256` (harmonic balance),
/// `Nt=512` (the periodic LCP), `steps=2000` (time marching).
pub fn discretisation(method: Method, d: &Discretisation) -> String {
    match (d.harmonics, method.discretisation()) {
        (Some(h), _) => format!("H={h} Nt={}", d.time_samples),
        (None, DiscretisationKind::StepsPerPeriod) => format!("steps={}", d.time_samples),
        (None, _) => format!("Nt={}", d.time_samples),
    }
}

/// What an error estimate is based on.
pub fn estimate_basis(method: Method, b: &EstimateBasis) -> String {
    let mut s = format!(
        "the change against {} (Richardson, order {})",
        discretisation(method, &b.against),
        b.order
    );
    if let Some(k) = b.softer_penalty {
        s += &format!(", plus the change against penalty_stiffness {k:e} (order 1 in 1/k_p)");
    }
    if let Some(nt) = b.time_samples_check {
        s += &format!(", plus the change against Nt={nt} at the same H (order 2 in Nt)");
    }
    s
}

/// Why a solution has no error estimate.
pub fn no_estimate(n: &NoEstimate) -> String {
    match n {
        NoEstimate::Off => "not asked for".to_string(),
        NoEstimate::NotConverged => "the solve did not converge".to_string(),
        NoEstimate::Coarsest { minimum } => format!(
            "the discretisation has no coarser one to compare with (the coarsest is {minimum})"
        ),
        NoEstimate::ComparisonNotConverged(t) => format!(
            "the comparison solve on another discretisation did not converge: {}",
            termination(t)
        ),
        NoEstimate::ComparisonFailed => {
            "the comparison solve on another discretisation could not run".to_string()
        }
        other => format!("{other:?}"),
    }
}

/// Why an accuracy search stopped.
pub fn search_stop(method: Method, s: &SearchStop) -> String {
    match s {
        SearchStop::Met => "met".to_string(),
        SearchStop::Limit { limit } => format!(
            "not met: the finest discretisation the search allows ({} = {limit}) was reached \
             with a larger estimate",
            match method.discretisation() {
                DiscretisationKind::Harmonics => "harmonics",
                DiscretisationKind::StepsPerPeriod => "steps_per_period",
                DiscretisationKind::TimeSamples => "time_samples",
            }
        ),
        SearchStop::NotConverged { at } => format!(
            "not met: the solve at {} did not converge",
            discretisation(method, at)
        ),
        SearchStop::PenaltyTooSoft { penalty_stiffness } => format!(
            "not met: the penalty part of the estimate alone exceeds the target at \
             penalty_stiffness = {penalty_stiffness:e} (raise it)"
        ),
        SearchStop::NoEstimate(n) => format!("not met: no estimate ({})", no_estimate(n)),
        other => format!("{other:?}"),
    }
}

/// The lines of `ssn solve`'s text on the error estimate and, with an accuracy target, on
/// the search.
pub fn estimate_lines(s: &Solution) -> String {
    let mut t = match &s.error_estimate {
        Ok(e) => format!(
            "error estimate    {:.1e} relative (tip max {:.1e}, tip min {:.1e}{}): {}\n",
            e.relative,
            e.parts.displacement_max,
            e.parts.displacement_min,
            e.parts
                .contact_force
                .map(|f| format!(", mean force {f:.1e}"))
                .unwrap_or_default(),
            estimate_basis(s.method, &e.basis)
        ),
        Err(n) => format!("error estimate    none: {}\n", no_estimate(n)),
    };
    if let Some(search) = &s.search {
        t += &format!(
            "accuracy          {:e} asked: {}; chose {} of {} discretisations tried, search \
             {:.3} s\n",
            search.target,
            search_stop(s.method, &search.stop),
            discretisation(s.method, &search.steps[search.chosen].discretisation),
            search.steps.len(),
            search.seconds
        );
    }
    t
}

/// One line for a fold located to an accuracy target: where, how sure, with which
/// harmonics, and why the ladder stopped short when it did.
pub fn fold_accuracy(fold: &FoldAccuracy, omega_1: f64) -> String {
    let uncertainty = fold.uncertainty.map_or("no estimate".to_string(), |u| {
        format!(
            "+- {:.1e} (relative {:.1e})",
            u / omega_1,
            u / fold.omega.abs()
        )
    });
    let stop = match &fold.stop {
        FoldStop::Met => String::new(),
        FoldStop::Limit { harmonics } => {
            format!(", target not met: the next rung needs H = {harmonics}, beyond the limit")
        }
        FoldStop::StartFailed {
            harmonics,
            termination,
        } => format!(
            ", target not met: at H = {harmonics} the branch point before the fold could not \
             be corrected ({termination})"
        ),
        FoldStop::NotFound { harmonics, points } => format!(
            ", target not met: at H = {harmonics} the branch did not turn back near the fold \
             in {points} points"
        ),
        _ => ", target not met".to_string(),
    };
    format!(
        "fold              omega/omega_1 = {:.6} {uncertainty} at H = {} (the sweep's H = {} \
         gave {:.6}){stop}\n",
        fold.omega / omega_1,
        fold.harmonics(),
        fold.rungs.first().map_or(0, |r| r.harmonics),
        fold.sweep_omega / omega_1,
    )
}

/// The lines of `ssn sweep` on a branch whose harmonics were chosen point by point: the
/// range of harmonics, how many points meet the target and the largest estimate.
pub fn branch_accuracy(accuracy: &BranchAccuracy, response: &FrequencyResponse) -> String {
    let harmonics = response.harmonics();
    let lo = harmonics.iter().min().copied().unwrap_or(0);
    let hi = harmonics.iter().max().copied().unwrap_or(0);
    format!(
        "harmonics         {lo} to {hi} chosen per point for the accuracy {:e} \
         ({} raised, {} lowered; in --json as harmonics)\n\
         error estimate    {} of {} points meet it, the largest {} (against H/2; in --json \
         as error_estimate)\n",
        accuracy.target,
        accuracy.raises,
        accuracy.lowers,
        accuracy.met(&response.points),
        response.points.len(),
        response
            .worst_estimate()
            .map_or("not estimated".to_string(), |w| format!("{w:.2e}")),
    )
}

/// Largest number of folds listed one by one in the human-readable sweep summary.
const LISTED_FOLDS: usize = 8;

/// The folds of a sweep in words (units of omega_1): all of them when there are few; else
/// their count, range, first and last (LCP and stiff-penalty branches have tens to
/// hundreds of small folds where the contact moves from node to node; `--json` and
/// `--csv` keep every one).
pub(crate) fn folds_summary(folds: &[f64], omega_1: f64) -> String {
    let ratio: Vec<f64> = folds.iter().map(|w| w / omega_1).collect();
    match ratio.len() {
        0 => "none".into(),
        n if n <= LISTED_FOLDS => ratio
            .iter()
            .map(|r| format!("{r:.4}"))
            .collect::<Vec<_>>()
            .join(", "),
        n => {
            let lo = ratio.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = ratio.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            format!(
                "{n} between {lo:.4} and {hi:.4} (first {:.4}, last {:.4}; all in --json)",
                ratio[0],
                ratio[n - 1]
            )
        }
    }
}

/// The text summary of `ssn sweep`: the branch, its accuracy, folds, stability, the folds
/// located to an accuracy target (`folds`), the work, how it ended and the wall time of
/// the whole run (`seconds`) with its parts.
pub(crate) fn sweep_text(
    response: &FrequencyResponse,
    folds: Option<&[FoldAccuracy]>,
    omega_1: f64,
    seconds: f64,
) -> String {
    let ratio = response.omega_ratio();
    let mut t = format!(
        "sweep             {} points, omega/omega_1 from {:.4} to {:.4}\n",
        response.points.len(),
        ratio.first().copied().unwrap_or(f64::NAN),
        ratio.last().copied().unwrap_or(f64::NAN)
    );
    if let Some(peak) = &response.located_peak {
        t += &format!(
            "peak amplitude    {:.6} at omega/omega_1 = {:.6}: {}\n",
            peak.amplitude,
            peak.omega / omega_1,
            peak_words(peak)
        );
    } else if let Some((i, a)) = response.peak() {
        t += &format!(
            "peak amplitude    {a:.6} at omega/omega_1 = {:.4}\n",
            ratio[i]
        );
    }
    if let Some(a) = &response.accuracy {
        t += &branch_accuracy(a, response);
    }
    t += &format!(
        "folds             {}\n",
        folds_summary(&response.folds, omega_1)
    );
    if !response.corner_folds.is_empty() {
        t += &format!(
            "corner reversals  {} (the frequency goes back by less than {} omega_1; in \
             --json as corner_folds)\n",
            response.corner_folds.len(),
            semismooth_contact::sweep::TURNING_POINT_EXCURSION
        );
    }
    let stable = response.stable();
    let unstable = stable.iter().filter(|s| **s == Some(false)).count();
    let undecided_count = stable.iter().filter(|s| s.is_none()).count();
    t += &format!(
        "stability         {} stable, {unstable} unstable, {undecided_count} undecided{}\n",
        stable.len() - unstable - undecided_count,
        response
            .undecided
            .as_ref()
            .map(|u| format!(" ({})", undecided(u)))
            .unwrap_or_default()
    );
    for e in &response.events {
        t += &format!(
            "  {:<15} at omega/omega_1 = {:.4}\n",
            e.kind.name(),
            e.omega / omega_1
        );
    }
    for fold in folds.unwrap_or_default() {
        t += &fold_accuracy(fold, omega_1);
    }
    t += &format!(
        "work              {} corrector iterations, {} factorizations{}\n",
        response.continuation.corrector_iterations,
        response.counters.factorizations,
        gmres_words(&response.counters)
    );
    t += &format!(
        "converged         {} ({}), {}\n",
        response.converged(),
        sweep_termination(response),
        sweep_seconds(response, seconds)
    );
    t
}

/// A sweep's wall time `seconds` (the whole run) and its parts: the branch, its stability
/// analysis, and the rest (the peak's location, the contact reports, the folds located to
/// an accuracy target).
fn sweep_seconds(response: &FrequencyResponse, seconds: f64) -> String {
    let (branch, stability) = (response.solve_seconds, response.stability_seconds);
    let rest = (seconds - branch - stability).max(0.0);
    format!(
        "{seconds:.3} s (the branch {branch:.3} s, its stability {stability:.3} s, the rest \
         {rest:.3} s)"
    )
}

/// The method and its discretisation, as the first line of `ssn solve` names them.
pub(crate) fn describe_method(s: &Solution) -> String {
    match (s.harmonics, s.lcp_scheme) {
        (Some(h), _) => format!("{} H={h} Nt={}", s.method.name(), s.time_samples),
        (None, Some(scheme)) if scheme != semismooth_contact::lcp::LcpScheme::Trapezoidal => {
            format!(
                "{} Nt={} {}",
                s.method.name(),
                s.time_samples,
                scheme.name()
            )
        }
        (None, _) => format!("{} Nt={}", s.method.name(), s.time_samples),
    }
}

/// The text of `ssn solve`; `settings` gives the tolerance the scene asked for, which the
/// text compares with the effective one.
pub(crate) fn solution_text(s: &Solution, settings: &crate::scene::SolverSettings) -> String {
    use std::fmt::Write;
    let mut t = String::new();
    let c = &s.counters;
    // Writing into a String cannot fail.
    let _ = (|| -> std::fmt::Result {
        writeln!(t, "method            {}", describe_method(s))?;
        writeln!(
            t,
            "omega             {:.6} ({:.4} omega_1)",
            s.omega,
            s.omega / s.omega_1
        )?;
        writeln!(
            t,
            "converged         {} ({}), {} iterations, residual {:.3e}",
            s.converged(),
            termination(&s.termination),
            s.iterations,
            s.residual_norm
        )?;
        if let Some(d) = s.diagnosis {
            writeln!(t, "diagnosis         {}", diagnosis(d))?;
        }
        let asked = if s.method.marches() {
            settings.march_tolerance
        } else {
            settings.tolerance
        };
        if let Some(effective) = s.effective_tolerance.filter(|&e| e > asked) {
            writeln!(
                t,
                "tolerance         {effective:.3e} effective: the scene's {asked:e} is below the \
                 round-off floor of this formulation"
            )?;
        }
        writeln!(t, "solve time        {:.3} ms", 1e3 * s.solve_seconds)?;
        t += &result_lines(s);
        t += &estimate_lines(s);
        if s.contacts.len() > 1 {
            for c in &s.contacts {
                writeln!(
                    t,
                    "  contact node {:<4} mean force {:.6e}, in contact {:.1} % of the period, \
                     max penetration {:.3e}",
                    c.node,
                    c.force_mean,
                    100.0 * c.contact_fraction,
                    c.max_penetration
                )?;
            }
        }
        t += &frictional_contact_lines(s);
        writeln!(
            t,
            "work              {} residuals, {} Jacobians, {} factorizations, {} solves, {} FFTs{}",
            c.residual_evaluations,
            c.jacobian_evaluations,
            c.factorizations,
            c.linear_solves,
            c.ffts,
            gmres_words(c)
        )
    })();
    t
}

/// The tip's extremes, the largest penetration and the mean contact force (with unilateral
/// contacts) and the friction points of a converged run; a run that did not converge has no
/// result, and its best iterate's numbers are not printed as one.
fn result_lines(s: &Solution) -> String {
    if !s.converged() {
        return "tip max / min     none: the solve did not converge
"
        .to_string();
    }
    let mut t = format!(
        "tip max / min     {:.6} / {:.6}\n",
        s.stats.max, s.stats.min
    );
    // Penetration and mean force belong to unilateral contacts: a friction-only run has none.
    if !s.contacts.is_empty() {
        t += &format!(
            "max penetration   {:.3e}\nmean contact force {:.6e}\n",
            s.stats.max_penetration, s.stats.mean_contact_force
        );
    }
    t + &friction_lines(s)
}

/// One line per friction point: the fraction of the period it sticks, its largest force
/// against its largest slip limit, and its largest slip velocity (nothing without one).
fn friction_lines(s: &Solution) -> String {
    s.friction
        .iter()
        .map(|f| {
            let summary = &f.summary;
            format!(
                "  friction {:<3}    stick {:.1} % of the period, max force {:.6e} (slip limit \
                 {:.6e}), max slip velocity {:.6e}\n",
                f.point + 1,
                100.0 * summary.stick_fraction,
                summary.force_amplitude,
                summary.slip_limit_max,
                summary.slip_velocity_amplitude
            )
        })
        .collect()
}

/// One line per 3-D frictional contact: its energy per cycle, largest normal force and
/// stick / slip / separated fractions (nothing without one).
fn frictional_contact_lines(s: &Solution) -> String {
    s.frictional_contacts
        .iter()
        .map(|p| {
            let normal = p.normal_force.iter().fold(0.0f64, |a, f| a.max(-f));
            let mean = -p.normal_force.iter().sum::<f64>() / p.normal_force.len().max(1) as f64;
            format!(
                "  3-D contact {:<3} energy per cycle {:.6e}, normal force mean {:.6e} max \
                 {:.6e}, stick / slip / separated {:.1} / {:.1} / {:.1} % of the period\n",
                p.point + 1,
                p.dissipated_energy,
                mean,
                normal,
                100.0 * p.stick_fraction,
                100.0 * p.slip_fraction,
                100.0 * p.separated_fraction
            )
        })
        .collect()
}

/// `, N GMRES iterations` when the matrix-free condensed solve ran, else nothing.
pub(crate) fn gmres_words(c: &semismooth_contact::solve::RunCounters) -> String {
    match c.krylov_iterations {
        0 => String::new(),
        k => format!(", {k} GMRES iterations"),
    }
}

/// The JSON name of a peak's location: `located`, `at_edge`, `at_fold`, `not_located`.
pub fn peak_location(location: &PeakLocation) -> &'static str {
    match location {
        PeakLocation::Located => "located",
        PeakLocation::AtEdge => "at_edge",
        PeakLocation::AtFold => "at_fold",
        _ => "not_located",
    }
}

/// How a sweep's peak was found, in words.
fn peak_words(peak: &LocatedPeak) -> String {
    match &peak.location {
        PeakLocation::Located => {
            format!("located between the branch points ({} solves)", peak.solves)
        }
        PeakLocation::AtEdge => {
            "the largest amplitude is at the edge of the branch: the peak may lie outside it".into()
        }
        PeakLocation::AtFold => "at a fold of the branch".into(),
        PeakLocation::NotLocated(reason) => {
            format!("the largest branch point (not located: {reason})")
        }
        _ => "the largest branch point".into(),
    }
}
