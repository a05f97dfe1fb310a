//! One-call solves: [`solve`] runs the chosen method on a [`Structure`] forced at a given
//! angular frequency, drives it with the core's solvers and reduces the answer to what
//! users compare (the observed dof over one period, every contact, work counters; the
//! frequency is the [`Solution`]'s `omega`).
//!
//! A run that could not start (bad settings, a singular model) is an [`RunError`]; a run that
//! started and stopped is an `Ok` [`Solution`] whose typed [`Termination`] says how
//! ([`Solution::converged`]), with the best answer it reached, so callers can still report
//! what happened.

pub mod accuracy;
mod condensed;
mod march;
mod raised_c;
pub use condensed::solve_condensed;
mod roundoff;
pub use raised_c::RAISED_C_FACTOR;
pub(crate) mod formulation;
use roundoff::DisplacementBlock;
pub(crate) use roundoff::{displacement_floor, load_scaled_tolerance, roundoff_floor};
mod reconstruction;

pub use formulation::{DiscretisationKind, FrictionSupport};
pub(crate) use formulation::{HarmonicProblem, SolveRequest};
pub(crate) use march::march_scheme;
pub(crate) use reconstruction::HbReconstruction;

use std::time::Instant;

use semismooth::continuation::{homotopy, HomotopySchedule};
use semismooth::lemke::{Lemke, LemkeOptions, LemkeTermination};
use semismooth::linalg::FaerDenseLu;
use semismooth::newton::{
    self, Globalization, NewtonOptions, NewtonReport, Strategy, Tolerances, WorkCounters,
};
use semismooth::polyalgorithm::{PolyalgorithmOptions, SmoothingOf, SolveOptions};
use semismooth::{GeneralizedJacobian, Residual};

use crate::contacts::{contact_reports, set_series_means, ContactReport, FrictionReport};
use crate::contacts::{period_statistics, PeriodStatistics};
use crate::hb::{
    CondensedSolve, FrictionalContactReport, HbError, HbJacobian, HbOptions, PenaltyHb,
    PenaltyHbOptions, SsnHb, StructuredHbSolver,
};
use crate::lcp::{
    ActiveSetSolver, LcpScheme, PeriodicLcp, PeriodicLcpOptions, DEFAULT_ACTIVE_SET_REGULARIZATION,
};
use crate::model::DEFAULT_C_FACTOR;
use crate::model::{StructuralModel, Structure};
use crate::settings::{GlobalizationChoice, Method, SolverSettings};
use accuracy::{DiscretisationSearch, ErrorEstimate, NoEstimate};

/// Number of reconstruction points per period for harmonic-balance outputs.
pub const HB_OUTPUT_POINTS: usize = 1024;

/// Why a run could not be carried out: the crate's one error type, [`crate::Error`].
pub type RunError = crate::Error;

/// Work done by a run (the JSON `counters` object).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct RunCounters {
    /// Residual evaluations.
    pub residual_evaluations: u64,
    /// Generalized Jacobian evaluations.
    pub jacobian_evaluations: u64,
    /// Factorizations requested from the linear solver.
    pub factorizations: u64,
    /// Linear solves.
    pub linear_solves: u64,
    /// Line-search backtracks.
    pub line_search_backtracks: u64,
    /// Fast Fourier transforms in the residual/Jacobian evaluations.
    pub ffts: u64,
    /// Lemke pivots (LCP by Lemke).
    pub lemke_pivots: u64,
    /// Time steps (time marching).
    pub time_steps: u64,
    /// GMRES iterations of the matrix-free condensed solve (0 on the direct paths).
    pub krylov_iterations: u64,
}

impl std::ops::Add for RunCounters {
    type Output = Self;

    /// The work of two runs together.
    fn add(self, other: Self) -> Self {
        Self {
            residual_evaluations: self.residual_evaluations + other.residual_evaluations,
            jacobian_evaluations: self.jacobian_evaluations + other.jacobian_evaluations,
            factorizations: self.factorizations + other.factorizations,
            linear_solves: self.linear_solves + other.linear_solves,
            line_search_backtracks: self.line_search_backtracks + other.line_search_backtracks,
            ffts: self.ffts + other.ffts,
            lemke_pivots: self.lemke_pivots + other.lemke_pivots,
            time_steps: self.time_steps + other.time_steps,
            krylov_iterations: self.krylov_iterations + other.krylov_iterations,
        }
    }
}

impl From<WorkCounters> for RunCounters {
    fn from(c: WorkCounters) -> Self {
        RunCounters {
            residual_evaluations: c.residual_evaluations,
            jacobian_evaluations: c.jacobian_evaluations,
            factorizations: c.factorizations,
            linear_solves: c.linear_solves,
            line_search_backtracks: c.line_search_backtracks,
            ffts: c.problem.get("ffts"),
            krylov_iterations: c.krylov_iterations,
            ..RunCounters::default()
        }
    }
}

/// How a run ended: the reason its driver stopped, with the numbers that explain it.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Termination {
    /// A Newton method (SSN-HB, penalty HB, the LCP by semismooth Newton): the core's
    /// termination of the run that produced the answer.
    Newton(newton::Termination),
    /// Lemke's algorithm on the periodic LCP.
    Lemke {
        /// Solved, ray or pivot limit.
        outcome: LemkeTermination,
        /// Pivots done.
        pivots: usize,
        /// The pivot limit of the LCP's order ([`LemkeOptions::pivot_limit`]).
        pivot_limit: usize,
        /// The LCP's order `m Nt`.
        order: usize,
        /// On a ray: the smallest eigenvalue of the symmetric part of the LCP matrix (a
        /// negative one means the matrix is not copositive-plus and a ray may end the path).
        smallest_symmetric_eigenvalue: Option<f64>,
    },
    /// Time marching to a steady state.
    March {
        /// Whether the period-to-period change fell below the tolerance.
        steady: bool,
        /// The last period-to-period change.
        period_change: f64,
        /// The tolerance it was compared with.
        tolerance: f64,
        /// Periods marched.
        periods: usize,
    },
}

impl Termination {
    /// Whether the run converged (a Newton run to its tolerance, Lemke to a solution, time
    /// marching to a steady period).
    pub fn converged(&self) -> bool {
        match self {
            Termination::Newton(t) => t.converged(),
            Termination::Lemke { outcome, .. } => *outcome == LemkeTermination::Solved,
            Termination::March { steady, .. } => *steady,
        }
    }
}

/// The short name of a termination: `converged`, the core's name of a Newton termination
/// (`max-iterations`, `line-search-failed`, ...), `ray`, `pivot-limit`, `not-steady`.
impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Termination::Newton(t) => write!(f, "{t}"),
            Termination::Lemke { outcome, .. } => f.write_str(match outcome {
                LemkeTermination::Solved => "converged",
                LemkeTermination::Ray => "ray",
                LemkeTermination::PivotLimit => "pivot-limit",
                _ => "lemke-stopped",
            }),
            Termination::March { steady, .. } => {
                f.write_str(if *steady { "converged" } else { "not-steady" })
            }
        }
    }
}

/// What is known to make a run that did not converge hard, and what to change.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Diagnosis {
    /// Every contact dof has mass or damping, so the trapezoidal LCP's Nyquist receptance
    /// is 0 and a contact force alternating node to node moves nothing (a null vector of
    /// the LCP matrix): its solutions chatter and are nearly degenerate;
    /// [`LcpScheme::Bdf2`] has no such vector.
    AlternatingNullVector,
}

/// The answer of one run, reduced to one period of the observed dof.
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct Solution {
    /// Method used.
    pub method: Method,
    /// Harmonics (HB methods only).
    pub harmonics: Option<usize>,
    /// AFT samples (HB), time steps per period (LCP, time marching).
    pub time_samples: usize,
    /// Time discretisation of the periodic LCP (LCP methods only).
    pub lcp_scheme: Option<LcpScheme>,
    /// What is known to make a run that did not converge hard (`None` when it converged or
    /// nothing is known).
    pub diagnosis: Option<Diagnosis>,
    /// Complementarity constant `c` (SSN-HB only).
    pub c: Option<f64>,
    /// Forcing frequency.
    pub omega: f64,
    /// First natural frequency of the structure.
    pub omega_1: f64,
    /// How the run ended ([`Solution::converged`]).
    pub termination: Termination,
    /// Newton iterations or Lemke pivots or periods marched.
    pub iterations: usize,
    /// Final residual norm (Newton methods), complementarity error (Lemke), period change
    /// (time marching).
    pub residual_norm: f64,
    /// The tolerance the run was judged against (Newton methods: the scene's tolerance, or
    /// the model's round-off floor when that is larger; the march tolerance for time
    /// marching; `None` for Lemke, which ends on a basis, not a tolerance).
    pub effective_tolerance: Option<f64>,
    /// The strategy of the Newton run that produced the answer (Newton methods).
    pub strategy: Option<Strategy>,
    /// Every strategy the Newton run tried, in order (Newton methods).
    pub attempts: Vec<semismooth::newton::Attempt>,
    /// Convergence order observed over the last Newton iterations (Newton methods).
    pub observed_order: Option<f64>,
    /// Residual norm of every Newton iterate, the initial guess first (Newton methods).
    pub residual_history: Vec<f64>,
    /// Wall time of the solve (not the set-up of the structure).
    pub solve_seconds: f64,
    /// Times over one period, `[0, T)` (the forcing is `cos(omega t)`).
    pub times: Vec<f64>,
    /// Displacement of the observed dof ([`Structure::observed_dof`]) at `times`.
    pub observed: Vec<f64>,
    /// Contact forces at `times`, one series per contact: each contact's law applied to the
    /// samples (never tension, `<= 0`).
    pub contact_forces: Vec<Vec<f64>>,
    /// SSN-HB: the truncated Fourier series of each contact force at `times` (the unknowns
    /// themselves; they ring above zero around a contact's transitions, by the truncation
    /// error). Empty for the other methods, whose forces are samples of the law.
    pub contact_force_series: Vec<Vec<f64>>,
    /// Statistics of the observed dof (penetration over all contacts; the mean contact
    /// force is the sum of the contacts' mean forces).
    pub stats: PeriodStatistics,
    /// Every contact point over the period.
    pub contacts: Vec<ContactReport>,
    /// Every friction point over the period, at [`Solution::times`] (harmonic balance and
    /// time marching; empty for the LCP, which has no friction).
    pub friction: Vec<FrictionReport>,
    /// Every 3-D frictional contact over the period (SSN-HB, time marching, and penalty HB
    /// with its regularised law; empty for the LCP, which refuses them).
    pub frictional_contacts: Vec<FrictionalContactReport>,
    /// Work counters.
    pub counters: RunCounters,
    /// The method's unknowns, for warm starts: HB coefficients, the LCP's `z`, the state
    /// `(u, v, lambda)` of time marching at the end of the reported period.
    pub state: Vec<f64>,
    /// The estimated relative error of the reported quantities, or why there is none
    /// ([`crate::accuracy`]).
    pub error_estimate: Result<ErrorEstimate, NoEstimate>,
    /// With an accuracy target ([`SolverSettings::accuracy`]): the discretisations tried,
    /// what was chosen and what the search cost.
    pub search: Option<DiscretisationSearch>,
    /// The settings that pose its equation again: the method and discretisation it was
    /// solved with and the complementarity constant it solved with
    /// ([`Solution::solved_settings`]); what its stability
    /// ([`crate::stability::solution_stability`]) or a second solve needs.
    pub settings: SolverSettings,
}

impl Solution {
    /// `settings` with the complementarity constant this solution solved with (SSN-HB
    /// raises the default when Newton cannot leave the start with it): the settings that
    /// pose its equation again, for a second solve or its stability.
    pub fn solved_settings(&self, settings: &SolverSettings) -> SolverSettings {
        SolverSettings {
            c: self.c.or(settings.c),
            ..settings.clone()
        }
    }

    /// Whether the run converged ([`Termination::converged`]).
    pub fn converged(&self) -> bool {
        self.termination.converged()
    }
}

/// The shape of a harmonic-balance method's unknowns: what a starting state must match.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StateShape {
    /// The scene's method.
    pub method: Method,
    /// The scene's harmonics.
    pub harmonics: usize,
    /// The structure's dofs.
    pub dofs: usize,
    /// The structure's contacts.
    pub contacts: usize,
}

/// SSN-HB options from scene settings.
pub(crate) fn hb_options(settings: &SolverSettings) -> HbOptions {
    HbOptions {
        harmonics: settings.harmonics,
        time_samples: Some(settings.time_samples),
        c: settings.c,
    }
}

/// Penalty-HB options from scene settings (the default penalty relative to the model's
/// contact stiffness scale).
pub(crate) fn penalty_options(
    settings: &SolverSettings,
    model: &crate::model::StructuralModel,
) -> PenaltyHbOptions {
    PenaltyHbOptions {
        harmonics: settings.harmonics,
        time_samples: Some(settings.time_samples),
        penalty_stiffness: settings
            .penalty_stiffness
            .unwrap_or_else(|| PenaltyHbOptions::default_penalty_stiffness(model)),
    }
}

/// The scene's penalty-HB problem at `omega`: [`penalty_options`] and the friction
/// regularisation of `settings`.
pub(crate) fn penalty_problem(
    model: &crate::model::StructuralModel,
    omega: f64,
    settings: &SolverSettings,
) -> Result<PenaltyHb, HbError> {
    let mut problem = PenaltyHb::new(model, omega, &penalty_options(settings, model))?;
    problem.set_friction_regularisation(settings.friction_regularisation)?;
    Ok(problem)
}

/// The periodic LCP's options of a scene and the index of the tip's contact: the tip is
/// observed (its history kept) when it is not a contact.
pub(crate) fn lcp_options(
    rod: &Structure,
    settings: &SolverSettings,
) -> (PeriodicLcpOptions, Option<usize>) {
    let tip = rod.observed_dof;
    let tip_contact = rod.model.contacts.iter().position(|c| c.dof() == tip);
    let options = PeriodicLcpOptions {
        time_samples: settings.time_samples,
        observed_dofs: if tip_contact.is_some() {
            Vec::new()
        } else {
            vec![tip]
        },
        scheme: settings.lcp_scheme,
    };
    (options, tip_contact)
}

/// Newton options from scene settings: one plain Newton run with the scene's globalization,
/// or (`auto`) the core's polyalgorithm.
pub fn newton_options(settings: &SolverSettings) -> SolveOptions {
    let plain = |globalization| {
        SolveOptions::Newton(NewtonOptions {
            tolerances: Tolerances::absolute(settings.tolerance),
            max_iterations: settings.max_iterations,
            globalization,
        })
    };
    match settings.globalization {
        GlobalizationChoice::None => plain(Globalization::None),
        GlobalizationChoice::Armijo => plain(Globalization::Armijo(Default::default())),
        GlobalizationChoice::Nonmonotone => plain(Globalization::non_monotone()),
        GlobalizationChoice::Hybrid => plain(Globalization::hybrid()),
        GlobalizationChoice::Auto => SolveOptions::Polyalgorithm(PolyalgorithmOptions {
            tolerances: Tolerances::absolute(settings.tolerance),
            max_iterations: settings.max_iterations,
            ..PolyalgorithmOptions::default()
        }),
    }
}

/// A Newton solve with the linear solver chosen by the settings (and the problem's
/// `smoothing` offered to the polyalgorithm), converged or not, to the tolerance scaled by
/// the load ([`load_scaled_tolerance`]).
///
/// The residual floor of the Newton options is the round-off level of the model
/// (`eps max K_ii sqrt(n) max|g|`: 4e-8 for 10^5 elements at H = 20, far below 1e-10 for
/// the shipped scenes): the tolerance is raised to it, and a run that stalls within 100
/// times of it has converged as far as floating point allows.
fn newton_hb<P>(
    problem: &mut P,
    x: &mut [f64],
    settings: &SolverSettings,
    model: &crate::model::StructuralModel,
    (extra_stiffness, smoothing): (f64, Option<SmoothingOf<P>>),
) -> Result<NewtonReport, RunError>
where
    P: GeneralizedJacobian<Jacobian = HbJacobian> + DisplacementBlock,
{
    let floor = displacement_floor(
        model,
        problem.dim(),
        problem.displacement_len(),
        extra_stiffness,
    );
    let settings = &SolverSettings {
        tolerance: load_scaled_tolerance(settings.tolerance, model),
        ..settings.clone()
    };
    let options = newton_options(settings).with_state_floor(floor);
    let report = match settings.linear_solver.condensed() {
        Some(condensed) => {
            let mut solver = structured_solver(condensed, settings.tolerance);
            options.solve(problem, &mut solver, x, smoothing)
        }
        None => options.solve(problem, &mut FaerDenseLu::new(), x, smoothing),
    };
    Ok(report?)
}

/// The structured solver of a Newton run with absolute tolerance `tolerance`: a
/// matrix-free condensed solve stops at `tolerance / 100` (or `1e-10` relative), so that a
/// step on the right piece leaves a residual well below the Newton tolerance.
pub fn structured_solver(condensed: CondensedSolve, tolerance: f64) -> StructuredHbSolver {
    StructuredHbSolver::new()
        .with_condensed_solve(condensed)
        .with_krylov_tolerance(0.01 * tolerance)
}

/// How a run ended, as its outputs report it.
struct Outcome<'a> {
    termination: Termination,
    iterations: usize,
    residual_norm: f64,
    effective_tolerance: Option<f64>,
    counters: RunCounters,
    solve_seconds: f64,
    /// The Newton report of a Newton method (order and residual history).
    newton: Option<&'a NewtonReport>,
}

impl<'a> Outcome<'a> {
    fn of_newton(report: &'a NewtonReport, solve_seconds: f64) -> Self {
        Self {
            termination: Termination::Newton(report.termination.clone()),
            iterations: report.iterations,
            residual_norm: report.residual_norm(),
            effective_tolerance: Some(report.effective_tolerance),
            counters: report.counters.into(),
            solve_seconds,
            newton: Some(report),
        }
    }
}

/// One period of a run's answer.
struct Period {
    times: Vec<f64>,
    observed: Vec<f64>,
    contact_forces: Vec<Vec<f64>>,
    /// The truncated series of each contact force (SSN-HB; empty otherwise).
    contact_force_series: Vec<Vec<f64>>,
    contact_displacements: Vec<Vec<f64>>,
    friction: Vec<FrictionReport>,
}

/// The solution record of a run of the scene's method at `omega`.
fn solution(
    request: SolveRequest<'_>,
    time_samples: usize,
    outcome: Outcome<'_>,
    period: Period,
    state: Vec<f64>,
) -> Solution {
    let (rod, omega, settings, _) = request.parts();
    let method = settings.method;
    let points: Vec<_> = rod
        .model
        .contacts
        .iter()
        .map(|c| (c.dof(), c.gap))
        .collect();
    let mut contacts = contact_reports(
        &points,
        &period.contact_forces,
        &period.contact_displacements,
    );
    set_series_means(
        &mut contacts,
        &points,
        &period.contact_force_series,
        &period.contact_displacements,
    );
    let mut stats = statistics(
        rod,
        &period.observed,
        &period.contact_forces,
        &period.contact_displacements,
    );
    stats.mean_contact_force = contacts.iter().map(|c| c.force_mean).sum();
    Solution {
        method,
        contacts,
        friction: period.friction,
        frictional_contacts: Vec::new(),
        harmonics: method.is_harmonic_balance().then_some(settings.harmonics),
        time_samples,
        lcp_scheme: method.is_lcp().then_some(settings.lcp_scheme),
        diagnosis: None,
        c: None,
        omega,
        omega_1: rod.omega_1,
        termination: outcome.termination,
        iterations: outcome.iterations,
        residual_norm: outcome.residual_norm,
        effective_tolerance: outcome.effective_tolerance,
        strategy: outcome.newton.map(|r| r.strategy),
        attempts: outcome.newton.map_or_else(Vec::new, |r| r.attempts.clone()),
        observed_order: outcome.newton.and_then(|r| r.observed_order),
        residual_history: outcome
            .newton
            .map_or_else(Vec::new, |r| r.residual_norms.clone()),
        solve_seconds: outcome.solve_seconds,
        stats,
        times: period.times,
        observed: period.observed,
        contact_forces: period.contact_forces,
        contact_force_series: period.contact_force_series,
        counters: outcome.counters,
        state,
        error_estimate: Err(NoEstimate::Off),
        search: None,
        settings: settings.clone(),
    }
}

/// The tip, the contact forces and the statistics of an HB solution on `points` times.
fn hb_outputs(
    problem: &impl HbReconstruction,
    request: SolveRequest<'_>,
    outcome: Outcome<'_>,
    x: Vec<f64>,
    points: usize,
) -> Result<Solution, RunError> {
    let (rod, omega, settings, _) = request.parts();
    let tip = problem.displacement(&x, rod.observed_dof, points)?;
    let contacts = rod.model.contacts.len();
    let contact_forces = (0..contacts)
        .map(|i| problem.contact_force(&x, i, points))
        .collect::<Result<Vec<_>, _>>()?;
    let contact_force_series = (0..contacts)
        .filter_map(|i| problem.contact_force_series(&x, i, points).transpose())
        .collect::<Result<Vec<_>, _>>()?;
    let contact_displacements = (0..contacts)
        .map(|i| problem.row_displacement(&x, i, points))
        .collect::<Result<Vec<_>, _>>()?;
    let period = 2.0 * std::f64::consts::PI / omega;
    let times = (0..points)
        .map(|n| period * n as f64 / points as f64)
        .collect();
    let closed = (0..contacts)
        .map(|i| problem.closed_intervals(&x, i))
        .collect::<Result<Vec<_>, _>>()?;
    let friction = (0..rod.model.friction.len())
        .map(|f| problem.friction(&x, f, points))
        .collect::<Result<Vec<_>, _>>()?;
    let period = Period {
        times,
        observed: tip,
        contact_forces,
        contact_force_series,
        contact_displacements,
        friction,
    };
    let mut solution = solution(request, settings.time_samples, outcome, period, x);
    set_closed_fractions(&mut solution.contacts, &closed);
    Ok(solution)
}

/// The contact fractions of harmonic-balance reports from the contact law's own closed
/// intervals instead of the reconstructed force, which rings between the samples.
pub(crate) fn set_closed_fractions(reports: &mut [ContactReport], closed: &[Vec<(f64, f64)>]) {
    for (report, intervals) in reports.iter_mut().zip(closed) {
        report.contact_fraction = semismooth::trigonometric::covered_fraction(intervals).min(1.0);
    }
}

/// Tip statistics; the penetration is the largest over all contacts (and the tip's).
fn statistics(
    rod: &Structure,
    tip: &[f64],
    forces: &[Vec<f64>],
    contact_displacements: &[Vec<f64>],
) -> PeriodStatistics {
    let tip_dof = rod.observed_dof;
    let contacts = &rod.model.contacts;
    let tip_contact = contacts
        .iter()
        .position(|c| c.row.single() == Some((tip_dof, 1.0)));
    let mut stats = match (tip_contact, forces.first()) {
        (Some(i), Some(_)) => period_statistics(tip, Some((contacts[i].gap, &forces[i]))),
        (None, Some(f)) => {
            let mut s = period_statistics(tip, None);
            s.mean_contact_force = f.iter().sum::<f64>() / f.len().max(1) as f64;
            s
        }
        _ => period_statistics(tip, None),
    };
    // A contact that never closes has a mean force of zero up to round-off (Newton lands on
    // +-1e-32): report it as 0 (never as a non-physical positive pull).
    let force_scale = forces.iter().flatten().fold(1.0f64, |a, f| a.max(f.abs()));
    if stats.mean_contact_force.abs() <= 1e-14 * force_scale {
        stats.mean_contact_force = 0.0;
    }
    for (c, u) in contacts.iter().zip(contact_displacements) {
        let p = u.iter().map(|v| (v - c.gap).max(0.0)).fold(0.0, f64::max);
        stats.max_penetration = stats.max_penetration.max(p);
    }
    stats
}

/// Solves the structure forced at the angular frequency `omega` with the scene's method, from a
/// zero initial guess (or `warm_start`, [`Solution::state`] of a solve with the same
/// discretisation), with the error estimate of [`crate::accuracy::estimate`] when
/// [`SolverSettings::estimate_error`] is on. With [`SolverSettings::accuracy`] the method
/// chooses its discretisation ([`crate::accuracy::search`]). An `omega` that is not finite
/// and `> 0` is the formulation's typed error.
pub fn solve(
    structure: &Structure,
    omega: f64,
    settings: &SolverSettings,
    warm_start: Option<&[f64]>,
) -> Result<Solution, RunError> {
    if let Some(target) = settings.accuracy {
        return accuracy::search::solve_to_accuracy(structure, omega, settings, target, warm_start);
    }
    let mut solution = solve_as_given(structure, omega, settings, warm_start)?;
    if settings.estimate_error {
        // The second solve poses the equation the first one solved (its `c` may be raised).
        let solved = solution.settings.clone();
        solution.error_estimate = accuracy::estimate(structure, omega, &solved, &solution);
    }
    Ok(solution)
}

/// [`solve`] with the settings' discretisation and no error estimate.
pub(crate) fn solve_as_given(
    rod: &Structure,
    omega: f64,
    settings: &SolverSettings,
    warm_start: Option<&[f64]>,
) -> Result<Solution, RunError> {
    let request = SolveRequest {
        rod,
        omega,
        settings,
        warm_start,
    };
    let mut solution = (formulation::of(settings.method).solver())(request)?;
    solution.settings = solution.solved_settings(settings);
    Ok(solution)
}

/// The SSN-HB solve of `rod` at `omega` (module documentation of [`solve`]).
pub(super) fn solve_ssn_hb(request: SolveRequest<'_>) -> Result<Solution, RunError> {
    let (rod, omega, settings, warm_start) = request.parts();
    let model = &rod.model;
    let mut problem = SsnHb::new(model, omega, &hb_options(settings))?;
    let mut x = initial_state(problem.dim(), warm_start);
    let start = Instant::now();
    let report = raised_c::ssn_hb_newton(&mut problem, &mut x, settings, model)?;
    let seconds = start.elapsed().as_secs_f64();
    let points = HB_OUTPUT_POINTS.max(settings.time_samples);
    let outcome = Outcome::of_newton(&report, seconds);
    ssn_hb_solution(&problem, request, outcome, x, points)
}

/// The outputs of an SSN-HB solution `x` of `problem` on `points` times, with its `c` and
/// frictional contacts.
fn ssn_hb_solution(
    problem: &SsnHb,
    request: SolveRequest<'_>,
    outcome: Outcome<'_>,
    x: Vec<f64>,
    points: usize,
) -> Result<Solution, RunError> {
    let mut sol = hb_outputs(problem, request, outcome, x, points)?;
    sol.c = (problem.contacts() > 0).then(|| problem.c());
    sol.frictional_contacts = (0..problem.frictional_contacts())
        .map(|p| problem.frictional_contact_report(&sol.state, p, points))
        .collect::<Result<_, _>>()?;
    Ok(sol)
}

/// The penalty-HB solve of `rod` at `omega`, through the penalty and regularisation
/// homotopies from a cold start.
pub(super) fn solve_penalty_hb(request: SolveRequest<'_>) -> Result<Solution, RunError> {
    let (rod, omega, settings, warm_start) = request.parts();
    let model = &rod.model;
    let tip = rod.observed_dof;
    let scale = model.contact_stiffness_scale();
    let options = penalty_options(settings, model);
    let target = options.penalty_stiffness;
    let mut problem = penalty_problem(model, omega, settings)?;
    let mut x = initial_state(problem.dim(), warm_start);
    let start = Instant::now();
    // Penalty homotopy: a stiff penalty from zero is hard for Newton (the first step
    // is the linear response, deep in the obstacle), so without a warm start the
    // stiffness is raised in log k_p from 10 x the static contact stiffness
    // (mesh-independent; the local one grows with the mesh and is already too stiff
    // a start on fine meshes) by factors of 10, a failed stage going back to the
    // last converged stiffness with the square root of the factor.
    let mut counters = WorkCounters::default();
    let mut homotopy_iterations = 0;
    // Regularisation homotopy: a narrow tanh law is a near-discontinuity Newton
    // cannot cross from zero, so without a warm start its width is narrowed in log
    // from the static slip itself (a soft, nearly viscous law) by factors of 10.
    let width = settings.friction_regularisation;
    if warm_start.is_none() && model.has_friction() && width < 1.0 {
        let stages = homotopy(
            0.0,
            -width.ln(),
            &HomotopySchedule::default(),
            &mut x,
            |narrowing, x| {
                problem.set_friction_regularisation((-narrowing).exp())?;
                newton_hb(&mut problem, x, settings, model, (target, None))
            },
        )?;
        counters += stages.counters;
        homotopy_iterations += stages.iterations;
        problem.set_friction_regularisation(width)?;
    }
    let unilateral = (model.frictional_contacts.iter())
        .any(|p| matches!(p.normal, crate::model::NormalLaw::Unilateral { .. }));
    if warm_start.is_none() && (!model.contacts.is_empty() || unilateral) {
        let k0 = model
            .static_contact_stiffness()
            .map(|s| DEFAULT_C_FACTOR * s)
            .unwrap_or(scale);
        let stages = homotopy(
            k0.ln(),
            target.ln(),
            &HomotopySchedule::default(),
            &mut x,
            |log_k, x| {
                let k = log_k.exp();
                problem.set_penalty_stiffness(k)?;
                newton_hb(&mut problem, x, settings, model, (k, None))
            },
        )?;
        counters += stages.counters;
        homotopy_iterations += stages.iterations;
        problem.set_penalty_stiffness(target)?;
    }
    let mut report = newton_hb(&mut problem, &mut x, settings, model, (target, None))?;
    counters += report.counters;
    report.counters = counters;
    // Iterations of the whole homotopy, so that costs compare across methods.
    report.iterations += homotopy_iterations;
    let seconds = start.elapsed().as_secs_f64();
    let points = HB_OUTPUT_POINTS.max(settings.time_samples);
    let outcome = Outcome::of_newton(&report, seconds);
    let mut sol = hb_outputs(&problem, request, outcome, x, points)?;
    // The mean penalty force as the equations see it: over the Nt AFT samples (a
    // finer grid resolves narrow force peaks the quadrature does not).
    if problem.contacts() > 0 {
        let summary = problem.summary(&sol.state, tip, points)?;
        for (c, mean) in sol.contacts.iter_mut().zip(&summary.contact_force_mean) {
            // (+0 for a contact that never closes, not -0.)
            c.force_mean = if *mean == 0.0 { 0.0 } else { *mean };
        }
        sol.stats.mean_contact_force = sol.contacts.iter().map(|c| c.force_mean).sum();
    }
    sol.frictional_contacts = (0..problem.frictional_contacts())
        .map(|p| problem.frictional_contact_report(&sol.state, p, points))
        .collect::<Result<_, _>>()?;
    Ok(sol)
}

fn initial_state(dim: usize, warm_start: Option<&[f64]>) -> Vec<f64> {
    match warm_start {
        Some(w) if w.len() == dim => w.to_vec(),
        _ => vec![0.0; dim],
    }
}

/// The periodic LCP of `rod` at `omega` solved by Lemke's pivoting.
pub(super) fn solve_lcp_by_lemke(request: SolveRequest<'_>) -> Result<Solution, RunError> {
    solve_lcp(request, &lcp_by_lemke)
}

/// The periodic LCP of `rod` at `omega` solved by semismooth Newton on its min map, from
/// `warm_start` (contact forces) when it fits.
pub(super) fn solve_lcp_by_min_map(request: SolveRequest<'_>) -> Result<Solution, RunError> {
    let (rod, omega, settings, warm_start) = request.parts();
    solve_lcp(request, &|lcp| {
        lcp_by_min_map(&rod.model, omega, settings, lcp, warm_start)
    })
}

/// The periodic LCP of `rod` at `omega` solved by `solve_lcp` and reduced to a [`Solution`].
fn solve_lcp(
    request: SolveRequest<'_>,
    solve_lcp: &dyn Fn(&PeriodicLcp) -> Result<LcpRun, RunError>,
) -> Result<Solution, RunError> {
    let (rod, omega, settings, _) = request.parts();
    let model = &rod.model;
    if model.contacts.is_empty() {
        return Err(RunError::Unsupported {
            method: settings.method.name(),
            what: "a [contact] section (the periodic LCP is posed on the contact forces)",
        });
    }
    let (options, tip_contact) = lcp_options(rod, settings);
    let start = Instant::now();
    let lcp = PeriodicLcp::new(model, omega, options)?;
    let LcpRun {
        z,
        termination,
        iterations,
        residual,
        counters,
        effective_tolerance,
        finest,
    } = solve_lcp(&lcp)?;
    let seconds = start.elapsed().as_secs_f64();
    let contact_u = lcp.contact_displacements(&z)?;
    let forces = lcp.contact_forces(&z)?;
    let tip_series = match tip_contact {
        Some(i) => contact_u[i].clone(),
        None => lcp.displacements(&z)?.remove(0),
    };
    let outcome = Outcome {
        termination,
        iterations,
        residual_norm: residual,
        effective_tolerance,
        counters,
        solve_seconds: seconds,
        newton: finest.as_ref(),
    };
    let period = Period {
        times: lcp.times(),
        observed: tip_series,
        contact_forces: forces,
        contact_force_series: Vec::new(),
        contact_displacements: contact_u,
        friction: Vec::new(),
    };
    let mut sol = solution(request, settings.time_samples, outcome, period, z);
    sol.stats.max_penetration = sol.stats.max_penetration.max(0.0);
    if !sol.converged() && lcp.has_alternating_null_vector() {
        sol.diagnosis = Some(Diagnosis::AlternatingNullVector);
    }
    Ok(sol)
}

/// The contact forces `z` of a periodic LCP solve and how it ended (`finest`: the Newton
/// report of the finest level of a min-map solve).
struct LcpRun {
    z: Vec<f64>,
    termination: Termination,
    iterations: usize,
    residual: f64,
    counters: RunCounters,
    effective_tolerance: Option<f64>,
    finest: Option<NewtonReport>,
}

/// The periodic LCP `lcp` solved by Lemke's pivoting.
fn lcp_by_lemke(lcp: &PeriodicLcp) -> Result<LcpRun, RunError> {
    let mut lemke = Lemke::new(lcp.dim());
    let lemke_options = LemkeOptions::default();
    let report = lemke.solve(lcp.matrix(), lcp.q(), &lemke_options)?;
    let termination = Termination::Lemke {
        outcome: report.termination,
        pivots: report.pivots,
        pivot_limit: lemke_options.pivot_limit(lcp.dim()),
        order: lcp.dim(),
        smallest_symmetric_eigenvalue: (report.termination == LemkeTermination::Ray)
            .then(|| lcp.symmetric_part_spectrum().0),
    };
    let counters = RunCounters {
        lemke_pivots: report.pivots as u64,
        ..RunCounters::default()
    };
    Ok(LcpRun {
        z: report.z.clone(),
        termination,
        iterations: report.pivots,
        residual: report.complementarity_error,
        counters,
        effective_tolerance: None,
        finest: None,
    })
}

/// The periodic LCP `lcp` of `model` at `omega` solved by semismooth Newton on its
/// min-map, from `warm_start` when it fits, else by mesh sequencing.
fn lcp_by_min_map(
    model: &StructuralModel,
    omega: f64,
    settings: &SolverSettings,
    lcp: &PeriodicLcp,
    warm_start: Option<&[f64]>,
) -> Result<LcpRun, RunError> {
    // Mesh sequencing (Nt/2^j from 128 up, each level warm-started by the coarser
    // one) unless a warm start is given: from z = 0 the active set of a fine LCP
    // creeps one time node per iteration. Residual floor: the min-map residual
    // min(z, q + A z) is a length; one ulp of its largest term is eps max|q|, summed
    // over sqrt(n) entries (a tolerance below it is raised to it, as for HB).
    let q_scale = lcp.q().iter().fold(0.0f64, |a, v| a.max(v.abs()));
    let options = newton_options(settings)
        .with_residual_floor(f64::EPSILON * (lcp.dim() as f64).sqrt() * q_scale);
    let (z, report_list) = match warm_start {
        Some(w) if w.len() == lcp.dim() => {
            let mut problem = lcp.min_map();
            let mut z = w.to_vec();
            let mut solver =
                ActiveSetSolver::new().with_regularization(DEFAULT_ACTIVE_SET_REGULARIZATION)?;
            let report = options.solve(&mut problem, &mut solver, &mut z, None)?;
            (z, vec![report])
        }
        _ => {
            let sequenced = crate::lcp::solve_min_map_sequenced(model, omega, lcp, &options)?;
            let reports = sequenced.levels.into_iter().map(|l| l.report).collect();
            (sequenced.z, reports)
        }
    };
    let last = report_list.last().expect("at least one level");
    let counters = report_list
        .iter()
        .map(|r| r.counters)
        .sum::<WorkCounters>()
        .into();
    Ok(LcpRun {
        z,
        termination: Termination::Newton(last.termination.clone()),
        iterations: report_list.iter().map(|r| r.iterations).sum(),
        residual: last.residual_norm(),
        counters,
        effective_tolerance: Some(last.effective_tolerance),
        // The finest level's run: its strategy, attempts and residual history
        // are the answer's (the iterations and counters are the levels' sums).
        finest: report_list.last().cloned(),
    })
}
