//! The JSON documents of the program: `ssn solve --json`, `ssn sweep --json`,
//! `ssn solutions --json` (every field is listed in README.md). Non-finite numbers are
//! written as `null`.

use std::path::Path;

use serde_json::{json, Value};

use semismooth_contact::accuracy::{Discretisation, DiscretisationSearch};
use semismooth_contact::contacts::{ContactReport, FrictionReport, FrictionSummary};
use semismooth_contact::hb::{FrictionalContactReport, FrictionalContactSummary};
use semismooth_contact::model::Structure;
use semismooth_contact::solutions::SolutionSet;
use semismooth_contact::solve::{RunCounters, Solution};
use semismooth_contact::sweep::doubling::PeriodTwoOutcome;
use semismooth_contact::sweep::fold_accuracy::FoldAccuracy;
use semismooth_contact::sweep::{BifurcationEvent, FrequencyResponse, ResponsePoint};

use crate::state::HbState;

/// The JSON object of one contact (non-finite numbers as null).
pub fn contact_json(c: &ContactReport) -> Value {
    let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
    json!({
        "node": c.node,
        "dof": c.dof,
        "gap": num(c.gap),
        "force_mean": num(c.force_mean),
        "max_penetration": num(c.max_penetration),
        "contact_fraction": num(c.contact_fraction),
        "displacement_min": num(c.displacement_min),
        "displacement_max": num(c.displacement_max),
    })
}

/// The JSON object of one friction point's numbers over a period: `point`,
/// `stick_fraction`, `force_amplitude`, `slip_velocity_amplitude`, `slip_limit_max`.
pub fn friction_summary_json(point: usize, f: &FrictionSummary) -> Value {
    let mut v = json!({ "point": point });
    for (name, value) in f.named() {
        v[name] = finite_or_null(value);
    }
    v
}

/// The JSON object of one friction point of a solution: its numbers
/// ([`friction_summary_json`]) and its `force` and `slip_velocity` over the period (at the
/// times of the solution's CSV).
pub fn friction_json(f: &FrictionReport) -> Value {
    let mut v = friction_summary_json(f.point, &f.summary);
    let series = |s: &[f64]| s.iter().map(|x| finite_or_null(*x)).collect::<Vec<_>>();
    v["force"] = json!(series(&f.force));
    v["slip_velocity"] = json!(series(&f.slip_velocity));
    v
}

/// The JSON object of one 3-D frictional contact's numbers (a sweep point's): `point`,
/// `max_normal_force`, `max_tangential_force`, `dissipated_energy` per cycle,
/// `stick_fraction`, `slip_fraction`, `separated_fraction`.
pub fn frictional_summary_json(s: &FrictionalContactSummary) -> Value {
    json!({
        "point": s.point,
        "max_normal_force": finite_or_null(s.max_normal_force),
        "max_tangential_force": finite_or_null(s.max_tangential_force),
        "dissipated_energy": finite_or_null(s.dissipated_energy),
        "stick_fraction": finite_or_null(s.stick_fraction),
        "slip_fraction": finite_or_null(s.slip_fraction),
        "separated_fraction": finite_or_null(s.separated_fraction),
    })
}

/// The JSON object of one 3-D frictional contact of a solution: its numbers
/// ([`frictional_summary_json`]) and `normal_force`, `tangential_force` (two series),
/// `slip_velocity` (two series) over the period (at the times of the solution's CSV).
pub fn frictional_contact_json(p: &FrictionalContactReport) -> Value {
    let series = |s: &[f64]| s.iter().map(|x| finite_or_null(*x)).collect::<Vec<_>>();
    let mut v = frictional_summary_json(&p.summary());
    v["normal_force"] = json!(series(&p.normal_force));
    v["tangential_force"] = json!([
        series(&p.tangential_force[0]),
        series(&p.tangential_force[1])
    ]);
    v["slip_velocity"] = json!([series(&p.slip_velocity[0]), series(&p.slip_velocity[1])]);
    v
}

/// The JSON fields of the Newton-style counters: `residual_evaluations`,
/// `jacobian_evaluations`, `factorizations`, `linear_solves`, `line_search_backtracks`,
/// `ffts`, `krylov_iterations`.
pub fn newton_counters(c: &RunCounters) -> serde_json::Map<String, Value> {
    let mut map = serde_json::Map::new();
    for (name, value) in [
        ("residual_evaluations", c.residual_evaluations),
        ("jacobian_evaluations", c.jacobian_evaluations),
        ("factorizations", c.factorizations),
        ("linear_solves", c.linear_solves),
        ("line_search_backtracks", c.line_search_backtracks),
        ("ffts", c.ffts),
        ("krylov_iterations", c.krylov_iterations),
    ] {
        map.insert(name.to_string(), value.into());
    }
    map
}

/// The JSON object of the work counters.
pub fn counters_json(c: &RunCounters) -> Value {
    let mut map = newton_counters(c);
    map.insert("lemke_pivots".into(), c.lemke_pivots.into());
    map.insert("time_steps".into(), c.time_steps.into());
    Value::Object(map)
}

/// The JSON document of `ssn solve --json` (documented in README.md). `harmonics` is absent
/// for the LCP and time marching; `time_samples` is then the number of steps per period.
pub fn solution_json(scene: &Path, s: &Solution) -> Value {
    let mut v = json!({
        "scene": scene.display().to_string(),
        "method": s.method.name(),
        "time_samples": s.time_samples,
        "omega": s.omega,
        "omega_ratio": s.omega / s.omega_1,
        "omega_1": s.omega_1,
        "converged": s.converged(),
        "termination": crate::words::termination(&s.termination),
        "iterations": s.iterations,
        "residual_norm": finite_or_null(s.residual_norm),
        "effective_tolerance": s.effective_tolerance,
        "solve_seconds": s.solve_seconds,
        "tip_max": finite_or_null(s.stats.max),
        "tip_min": finite_or_null(s.stats.min),
        "max_penetration": finite_or_null(s.stats.max_penetration),
        "contact_force_mean": finite_or_null(s.stats.mean_contact_force),
        "contacts": s.contacts.iter().map(contact_json).collect::<Vec<_>>(),
        "friction": s.friction.iter().map(friction_json).collect::<Vec<_>>(),
        "counters": counters_json(&s.counters),
    });
    if let Some(h) = s.harmonics {
        v["harmonics"] = json!(h);
    }
    if !s.frictional_contacts.is_empty() {
        let points: Vec<Value> = s
            .frictional_contacts
            .iter()
            .map(frictional_contact_json)
            .collect();
        v["frictional_contacts"] = json!(points);
    }
    if let Some(scheme) = s.lcp_scheme {
        v["lcp_scheme"] = json!(scheme.name());
    }
    if let Some(diagnosis) = s.diagnosis {
        v["diagnosis"] = json!(crate::words::diagnosis(diagnosis));
    }
    if let Some(strategy) = s.strategy {
        v["strategy"] = json!(strategy.name());
        v["attempts"] = s
            .attempts
            .iter()
            .map(|a| {
                json!({
                    "strategy": a.strategy.name(),
                    "iterations": a.iterations,
                    "converged": a.converged,
                    "outcome": a.outcome,
                })
            })
            .collect();
    }
    if let Some(c) = s.c {
        v["c"] = json!(c);
    }
    (v["error_estimate"], v["error_estimate_note"]) = estimate_json(s);
    if let Some(search) = &s.search {
        v["accuracy"] = search_json(s, search);
    }
    v
}

pub fn finite_or_null(v: f64) -> Value {
    if v.is_finite() {
        json!(v)
    } else {
        Value::Null
    }
}

/// The JSON object of `ssn sweep --json`: `points`, `omega`, `omega_ratio`, `tip_max`,
/// `tip_min`, `amplitude`, per point `stable` (true / false / null), `floquet_max_abs`,
/// `contact_force_mean` (the sum over the contacts), `max_penetration`, `contacts` (per
/// point, the list of [`ContactReport`]s), then `stability_note` (why points are
/// undecided), `stability_seconds`, `events` ({`kind`, `omega`, `omega_ratio`,
/// `index`}), `folds`, `corner_folds` (rad per unit time) and `fold_ratios`,
/// `corner_fold_ratios` (units of `omega_1`), `omega_1`, `converged`, `solve_seconds`, `termination`, `counters`;
/// harmonic balance: per point `harmonics` and `time_samples`; with an accuracy target
/// (SSN-HB, harmonics chosen per point): per point `error_estimate` and the summary
/// `accuracy` {`target`, `basis`, `order`, `points_met`, `worst_estimate`, `raises`,
/// `lowers`, `failed_raises`, `max_harmonics`, `estimate_seconds`, `estimate_counters`};
/// at period doublings (SSN-HB with stability) `period_two`, one document per doubling
/// (`period_two_json`). Non-finite numbers become `null`.
pub fn response_json(r: &FrequencyResponse) -> Value {
    let ratios = |omegas: &[f64]| omegas.iter().map(|w| w / r.omega_1).collect::<Vec<_>>();
    let mut counters = newton_counters(&r.counters);
    for (name, value) in [
        ("corrector_iterations", r.continuation.corrector_iterations),
        ("rejected_steps", r.continuation.rejected_steps),
        ("corner_passes", r.continuation.corner_passes),
        ("restarts", r.restarts as u64),
        ("corners", r.corners as u64),
    ] {
        counters.insert(name.to_string(), value.into());
    }
    let events: Vec<serde_json::Value> =
        r.events.iter().map(|e| event_json(e, r.omega_1)).collect();
    let points = &r.points;
    let column = |value: fn(&ResponsePoint) -> Value| points.iter().map(value).collect::<Vec<_>>();
    // Without friction points the list is empty, not a list of empty lists.
    let friction = if points.iter().all(|p| p.friction.is_empty()) {
        Vec::new()
    } else {
        column(|p| {
            p.friction
                .iter()
                .enumerate()
                .map(|(f, s)| friction_summary_json(f, s))
                .collect()
        })
    };
    let frictional = if points.iter().all(|p| p.frictional_contacts.is_empty()) {
        Vec::new()
    } else {
        column(|p| {
            (p.frictional_contacts.iter())
                .map(frictional_summary_json)
                .collect()
        })
    };
    let mut doc = json!({
        "points": points.len(),
        "omega": column(|p| json!(p.omega)),
        "omega_ratio": r.omega_ratio(),
        "tip_max": column(|p| json!(p.observed_max)),
        "tip_min": column(|p| json!(p.observed_min)),
        "amplitude": column(|p| json!(p.amplitude)),
        "stable": column(|p| json!(p.stability.stable)),
        "floquet_max_abs": column(|p| json!(p.stability.floquet_max_abs)),
        "placed_by_fold": column(|p| json!(p.stability.placed_by_fold)),
        "contact_force_mean": r.contact_force_mean(),
        "max_penetration": column(|p| json!(p.stability.max_penetration)),
        "contacts": column(|p| p.contacts.iter().map(contact_json).collect()),
        "friction": friction,
        "frictional_contacts": frictional,
        "stability_note": r.undecided.as_ref().map(crate::words::undecided),
        "stability_seconds": r.stability_seconds,
        "events": events,
        "folds": r.folds,
        "corner_folds": r.corner_folds,
        "fold_ratios": ratios(&r.folds),
        "corner_fold_ratios": ratios(&r.corner_folds),
        "omega_1": r.omega_1,
        "peak": r.located_peak.as_ref().map(|p| peak_json(p, r.omega_1)),
        "converged": r.converged(),
        "solve_seconds": r.solve_seconds,
        "termination": crate::words::sweep_termination(r),
        "counters": counters,
    });
    if r.is_harmonic_balance() {
        doc["harmonics"] = json!(r.harmonics());
        doc["time_samples"] = json!(r.time_samples());
    }
    if !r.period_two.is_empty() {
        doc["period_two"] = r
            .period_two
            .iter()
            .map(|o| period_two_json(o, r.omega_1))
            .collect();
    }
    if let Some(a) = &r.accuracy {
        doc["error_estimate"] = json!(column(|p| json!(p.error_estimate)));
        doc["accuracy"] = json!({
            "target": a.target,
            "basis": "the change of the observed extremes against H/2 solved from the truncated \
                      point, times 1/(2^p - 1) with p = HB_ORDER",
            "order": semismooth_contact::solve::accuracy::HB_ORDER,
            "points_met": a.met(points),
            "worst_estimate": r.worst_estimate(),
            "raises": a.raises,
            "lowers": a.lowers,
            "failed_raises": a.failed_raises,
            "max_harmonics": a.max_harmonics,
            "estimate_seconds": a.estimate_seconds,
            "estimate_counters": newton_counters(&a.estimate_counters),
        });
    }
    doc
}

/// A stability change of a branch: `kind`, `omega`, `omega_ratio`, `index`,
/// `uncertainty_ratio`.
fn event_json(e: &BifurcationEvent, omega_1: f64) -> Value {
    json!({
        "kind": e.kind.name(),
        "omega": e.omega,
        "omega_ratio": e.omega / omega_1,
        "index": e.index,
        "uncertainty_ratio": e.uncertainty.map(|u| u / omega_1),
    })
}

/// The period-2 branch born at a period doubling: `period_multiple` (2), `from_event`,
/// then either the branch as [`response_json`] (its `omega` the forcing frequency, its
/// `harmonics` those of `omega / 2`, its points' stability that of the `2T`-periodic orbit)
/// with `start_omega_ratio` and `next_event` (the next period doubling of a cascade, where
/// the branch was cut, or null), or `not_started` (why).
fn period_two_json(outcome: &PeriodTwoOutcome, omega_1: f64) -> Value {
    match outcome {
        PeriodTwoOutcome::Followed(b) => {
            let mut doc = response_json(&b.response);
            doc["period_multiple"] = json!(b.period_multiple);
            doc["from_event"] = event_json(&b.from, omega_1);
            doc["start_omega_ratio"] = json!(b.start_omega / omega_1);
            doc["next_event"] = b
                .next_event
                .as_ref()
                .map_or(Value::Null, |e| event_json(e, omega_1));
            doc
        }
        PeriodTwoOutcome::NotStarted { from, reason } => json!({
            "period_multiple": 2,
            "from_event": event_json(from, omega_1),
            "not_started": reason,
        }),
        _ => json!({ "period_multiple": 2 }),
    }
}

/// The JSON of `ssn solutions --json`: `omega`, `omega_ratio`, `window`,
/// `branch_points`, `branch_converged`, `crossings`, `failed_corrections`, `seconds` and
/// `solutions`, each {`tip_min`, `tip_max`, `contact_force_mean`, `max_penetration`,
/// `contacts` [{`dof`, `gap`, `contact_force_mean`, `max_penetration`}], `stable`
/// (true / false / null), `floquet_max_abs`, `stability_note`, `iterations`,
/// `residual_norm`, `state` (the harmonic coefficients, [`crate::state`]: start
/// `ssn solve` from it with `--start FILE --entry K`)}.
pub fn solutions_json(set: &SolutionSet) -> Value {
    let solutions: Vec<serde_json::Value> = set
        .solutions
        .iter()
        .map(|s| {
            let contacts: Vec<serde_json::Value> = s
                .contacts
                .iter()
                .map(|c| {
                    json!({
                        "dof": c.dof,
                        "gap": c.gap,
                        "contact_force_mean": c.contact_force_mean,
                        "max_penetration": c.max_penetration,
                    })
                })
                .collect();
            json!({
                "tip_min": s.solution.stats.min,
                "tip_max": s.solution.stats.max,
                "contact_force_mean": s.solution.stats.mean_contact_force,
                "max_penetration": s.solution.stats.max_penetration,
                "contacts": contacts,
                "friction": s
                    .solution
                    .friction
                    .iter()
                    .map(|f| friction_summary_json(f.point, &f.summary))
                    .collect::<Vec<_>>(),
                "stable": s.stability.stable,
                "floquet_max_abs": s.stability.floquet_max_abs,
                "stability_note": s.stability.undecided.as_ref().map(crate::words::undecided),
                "iterations": s.solution.iterations,
                "residual_norm": s.solution.residual_norm,
                "state": HbState::from_unknowns(
                    semismooth_contact::solve::StateShape {
                        harmonics: s.solution.harmonics.unwrap_or(set.shape.harmonics),
                        ..set.shape
                    },
                    set.omega,
                    set.omega_1,
                    &s.solution.state
                )
                .to_json(),
            })
        })
        .collect();
    json!({
        "omega": set.omega,
        "omega_ratio": set.omega / set.omega_1,
        "window": [set.window.0, set.window.1],
        "branch_points": set.branch_points,
        "branch_converged": set.branch_converged,
        "crossings": set.crossings,
        "failed_corrections": set.failed_corrections.iter().map(crate::words::failed_correction).collect::<Vec<_>>(),
        "seconds": set.seconds,
        "solutions": solutions,
    })
}

/// The `error_estimate` object of a solution (`null` without one) and the
/// `error_estimate_note` saying why there is none (`null` with one).
pub fn estimate_json(s: &Solution) -> (Value, Value) {
    match &s.error_estimate {
        Ok(e) => (
            json!({
                "relative": finite_or_null(e.relative),
                "displacement_max": finite_or_null(e.parts.displacement_max),
                "displacement_min": finite_or_null(e.parts.displacement_min),
                "contact_force": e.parts.contact_force.map(finite_or_null),
                "based_on": crate::words::estimate_basis(s.method, &e.basis),
                "against": discretisation_json(&e.basis.against),
                "order": e.basis.order,
                "seconds": e.seconds,
            }),
            Value::Null,
        ),
        Err(n) => (Value::Null, json!(crate::words::no_estimate(n))),
    }
}

/// `{harmonics, time_samples}` (`harmonics` null for the LCP and time marching).
fn discretisation_json(d: &Discretisation) -> Value {
    json!({"harmonics": d.harmonics, "time_samples": d.time_samples})
}

/// The `accuracy` object of a solve with an accuracy target: `target`, `met`, `stop`,
/// `chosen` ({`harmonics`, `time_samples`}), `steps` (each {`harmonics`, `time_samples`,
/// `converged`, `iterations`, `seconds`, `estimate`}), `seconds` and `counters` of the whole
/// search.
pub fn search_json(s: &Solution, search: &DiscretisationSearch) -> Value {
    let steps: Vec<Value> = search
        .steps
        .iter()
        .map(|step| {
            let mut v = discretisation_json(&step.discretisation);
            v["converged"] = json!(step.converged);
            v["iterations"] = json!(step.iterations);
            v["seconds"] = json!(step.seconds);
            v["estimate"] = step.estimate.map_or(Value::Null, finite_or_null);
            v
        })
        .collect();
    json!({
        "target": search.target,
        "met": search.met(),
        "stop": crate::words::search_stop(s.method, &search.stop),
        "chosen": discretisation_json(&search.steps[search.chosen].discretisation),
        "steps": steps,
        "seconds": search.seconds,
        "counters": counters_json(&search.counters),
    })
}

/// The folds of a sweep located to an accuracy target: frequency, uncertainty (absolute,
/// in units of `omega_1`), harmonics, whether the target is met, and each rung.
pub fn fold_accuracy_json(folds: &[FoldAccuracy], omega_1: f64) -> Value {
    folds
        .iter()
        .map(|f| {
            json!({
                "omega_ratio": f.omega / omega_1,
                "uncertainty_ratio": f.uncertainty.map(|u| u / omega_1),
                "harmonics": f.harmonics(),
                "met": f.met(),
                "sweep_omega_ratio": f.sweep_omega / omega_1,
                "rungs": f.rungs.iter().map(|r| json!({
                    "harmonics": r.harmonics,
                    "time_samples": r.time_samples,
                    "omega_ratio": r.omega / omega_1,
                    "points": r.points,
                    "seconds": r.seconds,
                })).collect::<Vec<_>>(),
            })
        })
        .collect()
}

/// The observed dof's amplitude in every sector of the full disk, recovered from a reduced
/// cyclic sector's harmonic-balance solution (`None` for any other structure or method).
pub fn blade_amplitudes(structure: &Structure, s: &Solution) -> Option<Value> {
    let coupling = structure.model.cyclic.as_ref()?;
    let (n, harmonics) = (structure.model.dofs(), s.harmonics?);
    let dof = structure.observed_dof;
    let coefficients: Vec<f64> = (0..2 * harmonics + 1)
        .map(|j| s.state.get(j * n + dof).copied())
        .collect::<Option<_>>()?;
    let amplitudes = coupling.sector_amplitudes(&coefficients, s.time_samples);
    Some(Value::from(
        amplitudes
            .into_iter()
            .map(finite_or_null)
            .collect::<Vec<_>>(),
    ))
}

/// The located peak: where, how large, how it was found (`location` as
/// [`crate::words::peak_location`] names it).
fn peak_json(peak: &semismooth_contact::sweep::peak::LocatedPeak, omega_1: f64) -> Value {
    json!({
        "omega": peak.omega,
        "omega_ratio": peak.omega / omega_1,
        "amplitude": peak.amplitude,
        "solves": peak.solves,
        "location": crate::words::peak_location(&peak.location),
    })
}
