//! Every periodic response at one forcing frequency, with its stability.
//!
//! Inside an overhang of a frequency response a forced structure with contact has several
//! periodic responses at the same frequency `w*`; which one a machine settles on depends on
//! its history. The branch of the scene's harmonic-balance problem holds all of them that
//! are connected to the linear response: [`find_solutions`] follows it in frequency with
//! the core's continuation over a window around `w*` (the scene's `[sweep]` range, or
//! `[0.5, 2] w*` without one), takes every pair of neighbouring branch points on either
//! side of `w*`, corrects the interpolated state by Newton at exactly `w*` (the one-call
//! [`crate::solve()`] with that warm start), merges corrections that land on the same solution
//! (relative distance of the unknowns below [`SAME_SOLUTION`]) and computes the stability
//! of each ([`crate::stability::hb_stability`]).
//!
//! Isolated branches (not connected to the linear response) are not found; nor are
//! solutions outside the window.

use std::time::Instant;

use crate::contacts::ContactSummary;
use crate::model::Structure;
use crate::settings::{SolverSettings, SweepSettings};
use crate::solve::StateShape;
use crate::solve::{solve, RunCounters, RunError, Solution, Termination};
use crate::stability::{HbStability, Stability, StabilityError, Undecided};
use crate::sweep::Reconstruction;
use crate::sweep::{follow_branch, FrequencyResponse, SweepTermination};

/// Relative distance of the unknowns below which two corrected solutions are the same.
pub const SAME_SOLUTION: f64 = 1e-6;

/// One periodic solution at the frequency.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct PeriodicSolution {
    /// The corrected solve at exactly the frequency (tip series, statistics, unknowns).
    pub solution: Solution,
    /// Per contact.
    pub contacts: Vec<ContactSummary>,
    /// Floquet multipliers and the verdict.
    pub stability: Stability,
    /// Index of the branch point after the crossing it was corrected from.
    pub branch_index: usize,
}

/// A crossing of the frequency whose correction did not converge.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FailedCorrection {
    /// Index of the branch point after the crossing.
    pub branch_index: usize,
    /// How the correction ended.
    pub termination: Termination,
    /// Its final residual norm.
    pub residual_norm: f64,
}

/// The answer of [`find_solutions`].
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct SolutionSet {
    /// The forcing frequency `w*`.
    pub omega: f64,
    /// First natural frequency.
    pub omega_1: f64,
    /// The shape of every solution's unknowns (method, harmonics, dofs, contacts).
    pub shape: StateShape,
    /// The distinct solutions, in branch order.
    pub solutions: Vec<PeriodicSolution>,
    /// The window searched, in units of `omega_1`.
    pub window: (f64, f64),
    /// Branch points followed.
    pub branch_points: usize,
    /// Whether the branch crossed the whole window.
    pub branch_converged: bool,
    /// Why the branch stopped.
    pub branch_termination: SweepTermination,
    /// Crossings of `w*` found on the branch.
    pub crossings: usize,
    /// Crossings whose correction did not converge.
    pub failed_corrections: Vec<FailedCorrection>,
    /// Work of the branch and of the corrections at `w*`.
    pub counters: RunCounters,
    /// Wall time.
    pub seconds: f64,
}

/// All periodic solutions of `structure` at the forcing frequency `omega` (module
/// documentation). `sweep`: the window and continuation settings (`None`:
/// `[0.5, 2] w* / omega_1` with the scene defaults).
pub fn find_solutions(
    structure: &Structure,
    omega: f64,
    settings: &SolverSettings,
    sweep: Option<&SweepSettings>,
) -> Result<SolutionSet, RunError> {
    let started = Instant::now();
    let window = search_window(structure, omega, settings, sweep)?;
    let branch = follow_branch(structure, settings, &window, None)?;
    let reconstruction = Reconstruction::new(&structure.model, omega, settings)?;
    // The method is a harmonic-balance one (checked by `search_window`): only the model
    // can fail here.
    let mut analysis = HbStability::new(&structure.model, settings).map_err(|e| match e {
        StabilityError::Hb(e) => RunError::HarmonicBalance(e),
        _ => RunError::Unsupported {
            method: settings.method.name(),
            what: "a harmonic-balance method (ssn-hb or penalty-hb)",
        },
    })?;
    let mut set = SolutionSet {
        omega,
        omega_1: structure.omega_1,
        shape: StateShape {
            method: settings.method,
            harmonics: settings.harmonics,
            dofs: structure.model.dofs(),
            contacts: structure.model.contacts.len(),
        },
        solutions: Vec::new(),
        window: (window.omega_ratio_from, window.omega_ratio_to),
        branch_points: branch.points.len(),
        branch_converged: branch.converged(),
        branch_termination: branch.termination.clone(),
        crossings: 0,
        failed_corrections: Vec::new(),
        counters: branch.counters,
        seconds: 0.0,
    };
    for i in 1..branch.points.len() {
        let Some((start, from)) = crossing_start(&branch, i, omega) else {
            continue;
        };
        set.crossings += 1;
        let solution = correct_crossing(structure, omega, settings, &branch, (&start, from))?;
        set.counters = set.counters + solution.counters;
        if !solution.converged() {
            set.failed_corrections.push(FailedCorrection {
                branch_index: i,
                termination: solution.termination,
                residual_norm: solution.residual_norm,
            });
            continue;
        }
        let x = &solution.state;
        if is_known(&set.solutions, x) {
            continue;
        }
        // With an accuracy target each solution has its own harmonics: its own analysis.
        let (stability, contacts) = if solution.harmonics == Some(settings.harmonics) {
            let contacts = reconstruction.contacts(&structure.model, x)?;
            (analysis.of(omega, x), contacts)
        } else {
            let solved = &solution.settings;
            let contacts = Reconstruction::new(&structure.model, omega, solved)?
                .contacts(&structure.model, x)?;
            let stability =
                HbStability::new(&structure.model, solved).and_then(|mut own| own.of(omega, x));
            (stability, contacts)
        };
        let stability = stability.unwrap_or_else(|e| Stability::not_decided(Undecided::Failed(e)));
        set.solutions.push(PeriodicSolution {
            solution,
            contacts,
            stability,
            branch_index: i,
        });
    }
    set.seconds = started.elapsed().as_secs_f64();
    Ok(set)
}

/// The window searched for the solutions at `omega` (`sweep`, else `[0.5, 2] omega /
/// omega_1`): `Err` unless the method is a harmonic-balance one, `omega` a finite
/// frequency > 0 and inside the window.
fn search_window(
    rod: &Structure,
    omega: f64,
    settings: &SolverSettings,
    sweep: Option<&SweepSettings>,
) -> Result<SweepSettings, RunError> {
    if !settings.method.is_harmonic_balance() {
        return Err(RunError::Unsupported {
            method: settings.method.name(),
            what: "a harmonic-balance method (ssn-hb or penalty-hb) to follow the branch \
                   through the frequency and correct each crossing",
        });
    }
    if !(omega.is_finite() && omega > 0.0) {
        return Err(RunError::InvalidSetting {
            name: "omega",
            value: omega,
            allowed: "a finite angular frequency > 0",
        });
    }
    let ratio = omega / rod.omega_1;
    let window = match sweep {
        Some(s) => s.clone(),
        None => SweepSettings::new(0.5 * ratio, 2.0 * ratio),
    };
    let (lo, hi) = (
        window.omega_ratio_from.min(window.omega_ratio_to),
        window.omega_ratio_from.max(window.omega_ratio_to),
    );
    if !(lo <= ratio && ratio <= hi) {
        return Err(RunError::InvalidSetting {
            name: "omega / omega_1",
            value: ratio,
            allowed: "a frequency inside the [sweep] range searched for solutions",
        });
    }
    Ok(window)
}

/// The start of the correction at `omega` when the branch crosses it between its points
/// `i - 1` and `i` (interpolated linearly in the frequency), with the point whose
/// discretisation it is on; `None` when it does not cross. Points of different harmonics
/// (a branch followed to an accuracy) give the nearer point's state.
fn crossing_start(branch: &FrequencyResponse, i: usize, omega: f64) -> Option<(Vec<f64>, usize)> {
    let (w0, w1) = (branch.points[i - 1].omega, branch.points[i].omega);
    // Each crossing once: the left point strictly on one side (or exactly at w*).
    let crosses = (w0 - omega) * (w1 - omega) < 0.0 || w1 == omega;
    if !crosses {
        return None;
    }
    let t = if w1 != w0 {
        (omega - w0) / (w1 - w0)
    } else {
        1.0
    };
    let (a, b) = (&branch.points[i - 1].state, &branch.points[i].state);
    if a.len() != b.len() {
        let nearer = if t < 0.5 { i - 1 } else { i };
        return Some((branch.points[nearer].state.clone(), nearer));
    }
    Some((a.iter().zip(b).map(|(a, b)| a + t * (b - a)).collect(), i))
}

/// The solve at `omega` from `start` on the discretisation of branch point `from`: with an
/// accuracy target, the search whose first rung is that point's harmonics (a start on
/// another rung would be dropped for zero, and zero finds one solution of several).
fn correct_crossing(
    structure: &Structure,
    omega: f64,
    settings: &SolverSettings,
    branch: &FrequencyResponse,
    (start, from): (&[f64], usize),
) -> Result<Solution, RunError> {
    match settings.accuracy {
        None => solve(structure, omega, settings, Some(start)),
        Some(target) => crate::solve::accuracy::search::solve_to_accuracy_from(
            structure,
            omega,
            settings,
            target,
            Some(start),
            branch.points[from].harmonics,
        ),
    }
}

/// Whether the state `x` is one of `solutions` (within [`SAME_SOLUTION`] of its norm).
fn is_known(solutions: &[PeriodicSolution], x: &[f64]) -> bool {
    let scale = x
        .iter()
        .map(|v| v * v)
        .sum::<f64>()
        .sqrt()
        .max(f64::MIN_POSITIVE);
    solutions.iter().any(|s| {
        let d = s
            .solution
            .state
            .iter()
            .zip(x)
            .map(|(a, b)| (a - b).powi(2))
            .sum::<f64>()
            .sqrt();
        d <= SAME_SOLUTION * scale
    })
}
