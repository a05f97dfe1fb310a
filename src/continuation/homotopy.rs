//! A natural-parameter homotopy towards a target with step halving: a parameter the problem
//! offers (a penalty stiffness, a load factor) is moved from an easy value towards a hard
//! one, each stage solved by Newton from the previous stage's solution.

use crate::newton::{NewtonReport, WorkCounters};

/// Steps of a [`homotopy`] in a parameter `p` (for a stiffness `k`, `p = ln k` makes each
/// step a factor).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HomotopySchedule {
    /// First step `Δp > 0`. Default `ln 10` (a stiffness times ten).
    pub initial_step: f64,
    /// The homotopy stops when a failure halves the step to this or below. Default
    /// `ln 1.05`.
    pub min_step: f64,
}

impl Default for HomotopySchedule {
    fn default() -> Self {
        Self {
            initial_step: 10f64.ln(),
            min_step: 1.05f64.ln(),
        }
    }
}

/// What a [`homotopy`] did.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct HomotopyReport {
    /// The parameters of the converged stages, in order.
    pub solved: Vec<f64>,
    /// Stages attempted, converged or not.
    pub stages: usize,
    /// Newton iterations over all stages.
    pub iterations: usize,
    /// Work over all stages.
    pub counters: WorkCounters,
}

/// Natural-parameter homotopy: stages at `p = from, from + Δ, ...` while `p < to`, each
/// solved by `stage(p, x)` from the last converged solution (`x` holds it on return; the
/// caller then solves at `to` itself). A stage that does not converge is dropped: the next
/// one is half a step beyond the last converged parameter (half a step below `from` when
/// none converged yet), and the homotopy ends when the step has been halved to
/// [`HomotopySchedule::min_step`]. `stage` returns the Newton report of its solve,
/// converged or not; its errors (a solve that could not run) end the homotopy.
///
/// ```
/// use semismooth::continuation::{homotopy, HomotopySchedule};
/// use semismooth::newton::{NewtonReport, Strategy, Termination, WorkCounters};
/// // A fake solver that converges for p <= 2.5 only: from 0 with steps 1, 0.5, 0.25, ...
/// let solve = |p: f64, x: &mut [f64]| -> Result<NewtonReport, ()> {
///     x[0] = p;
///     let ok = p <= 2.5;
///     Ok(NewtonReport {
///         termination: if ok { Termination::Converged } else { Termination::MaxIterations },
///         strategy: Strategy::FullSteps,
///         attempts: Vec::new(),
///         iterations: 1,
///         effective_tolerance: 0.0,
///         residual_norms: vec![1.0, 0.0],
///         step_lengths: vec![1.0],
///         step_norms: vec![1.0],
///         observed_order: None,
///         counters: WorkCounters::default(),
///     })
/// };
/// let schedule = HomotopySchedule { initial_step: 1.0, min_step: 0.2 };
/// let mut x = [0.0];
/// let report = homotopy(0.0, 10.0, &schedule, &mut x, solve).unwrap();
/// assert_eq!(report.solved, vec![0.0, 1.0, 2.0, 2.5]);
/// assert_eq!(x, [2.5]);
/// ```
pub fn homotopy<E>(
    from: f64,
    to: f64,
    schedule: &HomotopySchedule,
    x: &mut [f64],
    mut stage: impl FnMut(f64, &mut [f64]) -> Result<NewtonReport, E>,
) -> Result<HomotopyReport, E> {
    let mut report = HomotopyReport::default();
    let mut trial = x.to_vec();
    let mut p = from;
    let mut step = schedule.initial_step;
    let mut last_converged: Option<f64> = None;
    while p < to && step > schedule.min_step {
        trial.copy_from_slice(x);
        let stage_report = stage(p, &mut trial)?;
        report.stages += 1;
        report.iterations += stage_report.iterations;
        report.counters += stage_report.counters;
        if stage_report.converged() {
            x.copy_from_slice(&trial);
            report.solved.push(p);
            last_converged = Some(p);
            p += step;
        } else {
            step *= 0.5;
            p = last_converged.map_or(p - step, |pc| pc + step);
        }
    }
    Ok(report)
}
