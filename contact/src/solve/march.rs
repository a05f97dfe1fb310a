//! Time marching as a one-call solve: from rest (or a warm start) to the steady period,
//! reduced to the [`Solution`] of the other methods (the tip, every contact and friction
//! point over the last period).

use std::time::Instant;

use super::{
    solution, Outcome, Period, RunCounters, RunError, Solution, SolveRequest, Termination,
};
use crate::contacts::{march_friction_report, MARCH_STICK_VELOCITY};
use crate::hb::FrictionalContactReport;
use crate::march::{
    march_from_state, MarchError, MarchOptions, MarchScheme, MarchState, SteadyPeriod,
};
use crate::model::{NormalForce, NormalLaw, StructuralModel};
use crate::settings::SolverSettings;

/// The time-marching scheme of `settings`: Moreau–Jean with the restitution when it is
/// positive, else the model's choice ([`MarchScheme::Auto`]).
pub(crate) fn march_scheme(settings: &SolverSettings) -> MarchScheme {
    if settings.restitution > 0.0 {
        MarchScheme::MoreauJean {
            theta: 0.5,
            restitution: settings.restitution,
        }
    } else {
        MarchScheme::Auto
    }
}

/// The march state `(u, v, lambda)` of [`Solution::state`] (`None` when `state` is not of
/// the model's size).
fn march_state(model: &StructuralModel, state: &[f64]) -> Option<MarchState> {
    let (n, m) = (model.dofs(), model.contact_count());
    (state.len() == 2 * n + m).then(|| MarchState {
        displacement: state[..n].to_vec(),
        velocity: state[n..2 * n].to_vec(),
        contact_force: state[2 * n..].to_vec(),
    })
}

/// The slip limit `mu N` of each friction point at the steps of a marched period, from the
/// contacts' forces there.
fn march_slip_limits(model: &StructuralModel, forces: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let steps = forces.first().map_or(0, Vec::len);
    model
        .friction
        .iter()
        .map(|point| match point.normal {
            NormalForce::Contact(p) => forces[p].iter().map(|l| point.slip_limit(*l)).collect(),
            NormalForce::Prescribed(_) => vec![point.slip_limit(0.0); steps.max(1)],
        })
        .collect()
}

/// The largest static deflection under the load, `max |K^{-1} f|` (0 when `K` cannot be
/// factored): a displacement scale that does not vanish when nothing moves.
fn static_deflection(model: &StructuralModel) -> f64 {
    use semismooth::{Factorize, LinearSolve};
    let mut lu = semismooth::linalg::FaerSparseLu::new();
    let mut u = model.load.forcing_cosine();
    match lu
        .factor(&model.stiffness)
        .and_then(|_| lu.solve_in_place(&mut u))
    {
        Ok(()) if u.iter().all(|v| v.is_finite()) => max_abs(&u),
        _ => 0.0,
    }
}

/// Largest magnitude of a series (0 for an empty one).
fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0f64, |a, x| a.max(x.abs()))
}

/// Time marching from rest (or from `warm_start`, the [`Solution::state`] of a march of
/// the same model) to the steady state.
pub(super) fn solve_march(request: SolveRequest<'_>) -> Result<Solution, RunError> {
    let (rod, omega, settings, warm_start) = request.parts();
    let model = &rod.model;
    let tip = rod.observed_dof;
    let options = MarchOptions {
        steps_per_period: settings.steps_per_period,
        max_periods: settings.max_periods,
        tolerance: settings.march_tolerance,
        scheme: march_scheme(settings),
    };
    let observed = observed_dofs(model, tip);
    let initial = warm_start
        .and_then(|w| march_state(model, w))
        .unwrap_or_else(|| MarchState::rest(model));
    let start = Instant::now();
    // A march that does not settle is a run that did not converge: its last period is
    // reported with the last period-to-period change.
    let (period, steady) = match march_from_state(model, omega, &options, &observed, &initial) {
        Ok(period) => (period, true),
        Err(MarchError::NotSteady { last_period, .. }) => (*last_period, false),
        Err(e) => return Err(e.into()),
    };
    let seconds = start.elapsed().as_secs_f64();
    // Drop the closing sample (t = T repeats t = 0).
    let keep = period.times.len().saturating_sub(1).max(1);
    let cut = |v: &Vec<f64>| v[..keep.min(v.len())].to_vec();
    let tip_series = cut(&period.displacements[0]);
    let contact_u = contact_closures(model, &observed, &period.displacements, cut);
    let forces: Vec<Vec<f64>> = period.contact_forces.iter().map(cut).collect();
    let start_time = period.times[0];
    let times = period.times[..keep]
        .iter()
        .map(|t| t - start_time)
        .collect();
    let outcome = march_outcome(&period, steady, settings, seconds);
    let slip_limits = march_slip_limits(model, &forces);
    let velocity_scale = omega * max_abs(&tip_series).max(static_deflection(model));
    let friction = period
        .friction_forces
        .iter()
        .zip(&period.slip_velocities)
        .zip(slip_limits)
        .enumerate()
        .map(|(f, ((force, velocity), limit))| {
            march_friction_report(f, cut(force), cut(velocity), &limit, velocity_scale)
        })
        .collect();
    let frictional_contacts = frictional_reports(model, &period, velocity_scale, cut);
    let final_state = period.final_state;
    let period = Period {
        times,
        observed: tip_series,
        contact_forces: forces,
        contact_force_series: Vec::new(),
        contact_displacements: contact_u,
        friction,
    };
    let state = [
        final_state.displacement,
        final_state.velocity,
        final_state.contact_force,
    ]
    .concat();
    let mut solution = solution(request, settings.steps_per_period, outcome, period, state);
    solution.frictional_contacts = frictional_contacts;
    Ok(solution)
}

/// The reports of the 3-D frictional contacts over a marched period (each series shortened
/// by `cut`); a closed step sticks below [`MARCH_STICK_VELOCITY`] times the velocity scale
/// (the larger of `velocity_scale` and the largest slip speed).
fn frictional_reports(
    model: &StructuralModel,
    period: &SteadyPeriod,
    velocity_scale: f64,
    cut: impl Fn(&Vec<f64>) -> Vec<f64>,
) -> Vec<FrictionalContactReport> {
    let mut rows = period.frictional_forces.iter();
    let mut slips = period.frictional_slip_velocities.iter();
    let mut reports = Vec::new();
    for (p, point) in model.frictional_contacts.iter().enumerate() {
        let normal = match point.normal {
            NormalLaw::Unilateral { .. } => cut(rows.next().expect("a normal row")),
            NormalLaw::Prescribed(load) => vec![-load; cut(&period.times).len()],
        };
        let force = [(); 2].map(|_| cut(rows.next().expect("a tangent row")));
        let slip = [(); 2].map(|_| cut(slips.next().expect("a slip velocity")));
        let speed =
            (0..slip[0].len()).fold(velocity_scale, |a, n| a.max(slip[0][n].hypot(slip[1][n])));
        reports.push(FrictionalContactReport::from_march(
            p,
            normal,
            (force, slip),
            period.omega,
            MARCH_STICK_VELOCITY * speed,
        ));
    }
    reports
}

/// The observed dofs of a march: the tip, then every dof of the contacts' rows (their gap
/// closures `g . u` are combined from these series).
fn observed_dofs(model: &StructuralModel, tip: usize) -> Vec<usize> {
    let mut observed = vec![tip];
    for dof in model.contacts.iter().flat_map(|c| c.row.dofs()) {
        if !observed[1..].contains(dof) {
            observed.push(*dof);
        }
    }
    observed
}

/// Each contact's gap closure `g . u` over the period, combined from the series of the
/// `observed` dofs (`displacements`, each shortened by `cut`).
fn contact_closures(
    model: &StructuralModel,
    observed: &[usize],
    displacements: &[Vec<f64>],
    cut: impl Fn(&Vec<f64>) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let series = |dof: usize| {
        let k = 1 + observed[1..].iter().position(|d| *d == dof).unwrap_or(0);
        cut(&displacements[k])
    };
    model
        .contacts
        .iter()
        .map(|c| {
            let mut entries = c.row.entries();
            let (d, a) = entries.next().expect("a row has at least one dof");
            let mut u: Vec<f64> = series(d).iter().map(|v| a * v).collect();
            for (d, a) in entries {
                for (ui, v) in u.iter_mut().zip(series(d)) {
                    *ui += a * v;
                }
            }
            u
        })
        .collect()
}

/// How the march of `period` ended (`steady`: it settled), its work and wall time.
fn march_outcome(
    period: &SteadyPeriod,
    steady: bool,
    settings: &SolverSettings,
    seconds: f64,
) -> Outcome<'static> {
    Outcome {
        termination: Termination::March {
            steady,
            period_change: period.period_change,
            tolerance: settings.march_tolerance,
            periods: period.periods,
        },
        iterations: period.periods,
        residual_norm: period.period_change,
        effective_tolerance: Some(settings.march_tolerance),
        counters: RunCounters {
            time_steps: period.counters.steps,
            factorizations: period.counters.factorizations,
            ..RunCounters::default()
        },
        solve_seconds: seconds,
        newton: None,
    }
}
