//! How accurate an answer is, and the cheapest discretisation for a given accuracy.
//!
//! # The reported quantities and their relative error
//!
//! A [`Solution`] reports the observed dof's extremes over one period and each contact's
//! mean force ([`ReportedQuantities`]). Their relative error against a reference
//! ([`RelativeErrors::between`]) has three parts:
//!
//! - `displacement_max`, `displacement_min`: `|u - u_ref|` of the largest and smallest
//!   displacement, divided by the reference's largest excursion `max(|max|, |min|)`;
//! - `contact_force`: `max_k |F_k - F_ref,k|` over the contacts, divided by the largest
//!   `|F_ref,k|` (`None` without contact force);
//!
//! and the error is the largest part ([`RelativeErrors::largest`]).
//!
//! # The estimate of a solve ([`ErrorEstimate`])
//!
//! Every solve is compared with a second solve of the same method on another
//! discretisation, started from the first one's answer carried over to it (a few Newton
//! iterations, or a short march), and the change is scaled by the method's order
//! (Richardson): with a refinement ratio `r` and an error `C h^p`, the finer answer's error
//! is the change divided by `r^p - 1`, the coarser one's the change times
//! `r^p / (r^p - 1)`.
//!
//! - Harmonic balance: `2H` harmonics and `2Nt` AFT samples, the finer solve started from
//!   the lifted coefficients; order [`HB_ORDER`] = 0.75 (the estimate is 2.5 times the
//!   change). The error of the
//!   contact's own displacement maximum (the Galerkin penetration) falls like `H^-0.85` on
//!   the paper's rod and on the strongly forced rod (H = 20 to 320), the mean force faster
//!   at first (an error of 3e-2 at H = 10, 5e-4 at H = 20) and then not monotonically: a
//!   coarser partner would see the first and overestimate tenfold, while the finer
//!   partner's factor `r^p / (r^p - 1)` is within `[1, 2.5]` for any order `p >= 0.75`. A
//!   model too large to be solved at `2H` (more than
//!   [`search::MAX_SEARCH_UNKNOWNS`] unknowns) is compared with `H/2` instead (the change
//!   is the estimate).
//! - Penalty harmonic balance: the same, plus the change against `k_p / 10` divided by 9
//!   (first order in `1 / k_p`).
//! - The periodic LCP: `Nt/2` time steps, order 2 (trapezoidal rule and BDF2); `lcp-ssn`
//!   started from the forces at every other node.
//! - Time marching: `steps/2` steps per period marched from the final state, order 2 for
//!   the trapezoidal scheme of a massless contact dof, 1 for Moreau–Jean. The comparison
//!   may march as many periods as the solve did (at least [`MIN_COMPARISON_PERIODS`]): it
//!   starts on the solve's orbit, so a coarser march that has not settled by then does not
//!   settle at all (Moreau–Jean chatter at the coarser step) and the solve has no estimate
//!   ([`NoEstimate::ComparisonNotConverged`]) rather than one that costs far more than it.
//!
//! `ssn::accuracy_targets` (the `accuracy-targets` table of docs/accuracy-cost.md) and
//! `contact/tests/error_estimate.rs` check the estimate against converged references.

pub mod search;

use crate::model::Structure;
use crate::settings::SolverSettings;
use crate::solve::DiscretisationKind;
use crate::solve::{RunCounters, RunError, Solution, Termination};

pub use search::{DiscretisationSearch, SearchStep, SearchStop};

/// What a solution reports: the observed dof's extremes and the contacts' mean forces.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportedQuantities {
    /// Largest displacement of the observed dof over one period.
    pub displacement_max: f64,
    /// Smallest displacement of the observed dof over one period.
    pub displacement_min: f64,
    /// Mean force of each contact over one period.
    pub contact_forces: Vec<f64>,
}

impl ReportedQuantities {
    /// The quantities `solution` reports.
    pub fn of(solution: &Solution) -> Self {
        Self {
            displacement_max: solution.stats.max,
            displacement_min: solution.stats.min,
            contact_forces: solution.contacts.iter().map(|c| c.force_mean).collect(),
        }
    }
}

/// Relative errors of the reported quantities (module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelativeErrors {
    /// Of the largest displacement, relative to the largest excursion.
    pub displacement_max: f64,
    /// Of the smallest displacement, relative to the largest excursion.
    pub displacement_min: f64,
    /// Of the mean contact forces, relative to the largest mean force (`None` without
    /// contact force).
    pub contact_force: Option<f64>,
}

impl RelativeErrors {
    /// The relative errors of `value` against `reference` (module documentation). A zero
    /// scale with a nonzero difference gives an infinite part.
    pub fn between(value: &ReportedQuantities, reference: &ReportedQuantities) -> Self {
        let relative = |difference: f64, scale: f64| {
            if difference == 0.0 {
                0.0
            } else if scale > 0.0 {
                difference / scale
            } else {
                f64::INFINITY
            }
        };
        let excursion = reference
            .displacement_max
            .abs()
            .max(reference.displacement_min.abs());
        let force_scale = reference
            .contact_forces
            .iter()
            .chain(&value.contact_forces)
            .fold(0.0f64, |a, f| a.max(f.abs()));
        let force_difference = value
            .contact_forces
            .iter()
            .zip(&reference.contact_forces)
            .fold(0.0f64, |a, (f, r)| a.max((f - r).abs()));
        let reference_force = reference
            .contact_forces
            .iter()
            .fold(0.0f64, |a, f| a.max(f.abs()));
        Self {
            displacement_max: relative(
                (value.displacement_max - reference.displacement_max).abs(),
                excursion,
            ),
            displacement_min: relative(
                (value.displacement_min - reference.displacement_min).abs(),
                excursion,
            ),
            contact_force: (force_scale > 0.0).then(|| relative(force_difference, reference_force)),
        }
    }

    /// The largest part: the relative error of the reported quantities.
    pub fn largest(&self) -> f64 {
        self.displacement_max
            .max(self.displacement_min)
            .max(self.contact_force.unwrap_or(0.0))
    }

    /// Every part times `factor`.
    pub fn scaled(&self, factor: f64) -> Self {
        Self {
            displacement_max: factor * self.displacement_max,
            displacement_min: factor * self.displacement_min,
            contact_force: self.contact_force.map(|f| factor * f),
        }
    }

    /// The parts of `self` and `other` added (errors from two sources).
    pub fn plus(&self, other: &Self) -> Self {
        Self {
            displacement_max: self.displacement_max + other.displacement_max,
            displacement_min: self.displacement_min + other.displacement_min,
            contact_force: match (self.contact_force, other.contact_force) {
                (None, None) => None,
                (a, b) => Some(a.unwrap_or(0.0) + b.unwrap_or(0.0)),
            },
        }
    }
}

/// A discretisation of a method: harmonics (HB) and time samples (HB: AFT samples; the
/// LCP and time marching: time steps per period, as [`Solution::time_samples`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Discretisation {
    /// Harmonics `H` (harmonic-balance methods).
    pub harmonics: Option<usize>,
    /// AFT samples, or time steps per period.
    pub time_samples: usize,
}

impl Discretisation {
    /// The discretisation `settings` give `method` (`settings.method`).
    pub fn of(settings: &SolverSettings) -> Self {
        let kind = settings.method.discretisation();
        let by_harmonics = kind == DiscretisationKind::Harmonics;
        Self {
            harmonics: by_harmonics.then_some(settings.harmonics),
            time_samples: if by_harmonics {
                settings.time_samples
            } else {
                kind.level(settings)
            },
        }
    }
}

/// What an [`ErrorEstimate`] is based on (module documentation): the change of the
/// reported quantities against another discretisation of the method, times Richardson's
/// factor `1 / (r^order - 1)` (`r` the ratio of the finer to the coarser discretisation;
/// `r^order / (r^order - 1)` when the compared one is the finer).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EstimateBasis {
    /// The discretisation compared with.
    pub against: Discretisation,
    /// The order of the method in its discretisation ([`HB_ORDER`] for harmonic balance in
    /// `H`, 1 for Moreau–Jean, 2 for the periodic LCP and the trapezoidal march).
    pub order: f64,
    /// Penalty HB: the softer penalty stiffness also compared with (`k_p / 10`, the change
    /// divided by 9, order 1 in `1 / k_p`), its part added.
    pub softer_penalty: Option<f64>,
    /// Harmonic balance in a search: the AFT samples also compared with at the same `H`
    /// (order 2 in `Nt`), its part added.
    pub time_samples_check: Option<usize>,
}

/// An estimate of the relative error of a solution's reported quantities (module
/// documentation).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ErrorEstimate {
    /// The estimated relative error: the largest of `parts`.
    pub relative: f64,
    /// The estimate of each reported quantity.
    pub parts: RelativeErrors,
    /// The comparison it is based on.
    pub basis: EstimateBasis,
    /// Wall time of the comparison solves.
    pub seconds: f64,
    /// Work of the comparison solves.
    pub counters: RunCounters,
}

/// Why a solution has no error estimate.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum NoEstimate {
    /// Not asked for ([`SolverSettings::estimate_error`] is off).
    Off,
    /// The solve did not converge: its answer has no accuracy to speak of.
    NotConverged,
    /// The discretisation has no coarser one of the method (`H = 1`; fewer than
    /// `2 minimum` time steps).
    Coarsest {
        /// The smallest coarser discretisation the method accepts (harmonics or steps).
        minimum: usize,
    },
    /// The comparison solve did not converge.
    ComparisonNotConverged(Termination),
    /// The comparison solve could not run (it has the settings of the solve but for its
    /// discretisation, so this is unexpected).
    ComparisonFailed,
}

/// Fewest periods a time-marching comparison may march (module documentation).
pub const MIN_COMPARISON_PERIODS: usize = 20;

/// The coarser settings a solve is compared with, and the scaling of the change.
pub(crate) struct Comparison {
    settings: SolverSettings,
    /// The change times this is the error.
    factor: f64,
    /// The method's order in its discretisation.
    order: f64,
}

/// The discretisation `settings` are compared with (module documentation), or why there is
/// none.
fn comparison(settings: &SolverSettings, rod: &Structure) -> Result<Comparison, NoEstimate> {
    crate::solve::formulation::of(settings.method).comparison(rod, settings)
}

/// `settings` without an estimate or a target: the start of a comparison's settings.
fn compared(settings: &SolverSettings) -> SolverSettings {
    let mut other = settings.clone();
    other.estimate_error = false;
    other.accuracy = None;
    other
}

/// The comparison of a harmonic-balance solve: twice the harmonics while the problem stays
/// within the search's size, else half of them.
pub(crate) fn harmonic_comparison(
    settings: &SolverSettings,
    rod: &Structure,
) -> Result<Comparison, NoEstimate> {
    let mut other = compared(settings);
    let h = settings.harmonics;
    let width = rod.model.dofs() + rod.model.contact_count();
    if width.saturating_mul(4 * h + 1) <= search::MAX_SEARCH_UNKNOWNS {
        // The finer partner: the coarser side of Richardson's pair, r = 2, p = 1.
        other.harmonics = 2 * h;
        other.time_samples = 2 * settings.time_samples;
        let rp = HB_RATIO.powf(HB_ORDER);
        return Ok(Comparison {
            settings: other,
            factor: rp / (rp - 1.0),
            order: HB_ORDER,
        });
    }
    if h < 2 {
        return Err(NoEstimate::Coarsest { minimum: 1 });
    }
    other.harmonics = h / 2;
    other.time_samples = (settings.time_samples / 2).max(2 * other.harmonics + 1);
    Ok(Comparison {
        settings: other,
        factor: 1.0 / (HB_RATIO.powf(HB_ORDER) - 1.0),
        order: HB_ORDER,
    })
}

/// The comparison of a periodic-LCP solve: half the time steps (second order).
pub(crate) fn lcp_comparison(settings: &SolverSettings) -> Result<Comparison, NoEstimate> {
    let mut other = compared(settings);
    let minimum = crate::lcp::MIN_LCP_TIME_SAMPLES;
    if settings.time_samples < 2 * minimum {
        return Err(NoEstimate::Coarsest { minimum });
    }
    other.time_samples = settings.time_samples / 2;
    let r = settings.time_samples as f64 / other.time_samples as f64;
    Ok(Comparison {
        settings: other,
        factor: 1.0 / (r * r - 1.0),
        order: 2.0,
    })
}

/// The comparison of a time-marching solve: half the steps per period, at the order of
/// its scheme ([`march_order`]).
pub(crate) fn march_comparison(
    settings: &SolverSettings,
    rod: &Structure,
) -> Result<Comparison, NoEstimate> {
    let mut other = compared(settings);
    let minimum = COARSEST_STEPS_PER_PERIOD;
    if settings.steps_per_period < 2 * minimum {
        return Err(NoEstimate::Coarsest { minimum });
    }
    other.steps_per_period = settings.steps_per_period / 2;
    let r = settings.steps_per_period as f64 / other.steps_per_period as f64;
    let order = march_order(rod, settings);
    Ok(Comparison {
        settings: other,
        factor: 1.0 / (r.powf(order) - 1.0),
        order,
    })
}

/// Order in the step of the time-marching scheme `settings` selects for `rod`: 2 for the
/// trapezoidal rule of a massless contact dof, 1 for Moreau–Jean (positions near impacts).
pub(crate) fn march_order(rod: &Structure, settings: &SolverSettings) -> f64 {
    use crate::march::{resolve_scheme, MarchScheme};
    let scheme = crate::solve::march_scheme(settings);
    match resolve_scheme(&rod.model, scheme) {
        MarchScheme::MoreauJean { .. } => 1.0,
        _ => 2.0,
    }
}

/// The start of a solve with the discretisation of `to` from `solution` (module
/// documentation): HB coefficients truncated or lifted, the LCP's forces interpolated
/// periodically in time onto the other nodes, the march's final state; `None` for Lemke
/// (which starts from its own basis).
pub(crate) fn carried_start(
    rod: &Structure,
    solution: &Solution,
    to: &SolverSettings,
) -> Option<Vec<f64>> {
    crate::solve::formulation::of(solution.method).carried_start(rod, solution, to)
}

/// Solves with `settings` from `start`, the answer of another discretisation carried
/// over, and again from zero when that did not converge (a carried start can lead Newton
/// astray where the method's own start, e.g. the LCP's mesh sequencing, does not); a
/// solve that did not converge is passed to `failed` before the retry.
pub(crate) fn solve_carried(
    rod: &Structure,
    omega: f64,
    settings: &SolverSettings,
    start: Option<&[f64]>,
    mut failed: impl FnMut(&Solution),
) -> Result<Solution, RunError> {
    let first = crate::solve::solve_as_given(rod, omega, settings, start)?;
    if first.converged() || start.is_none() {
        return Ok(first);
    }
    failed(&first);
    crate::solve::solve_as_given(rod, omega, settings, None)
}

/// Runs the comparison `coarse` from `start` and returns the change of the reported
/// quantities of `solution` against it, with its time and work.
fn change_against(
    rod: &Structure,
    omega: f64,
    solution: &Solution,
    coarse: &SolverSettings,
    start: Option<&[f64]>,
) -> Result<(RelativeErrors, f64, RunCounters), NoEstimate> {
    // A march from the solve's own orbit that did not settle will not settle from rest in
    // the same budget: no second march.
    let other = if crate::solve::formulation::of(coarse.method).marches() {
        crate::solve::solve_as_given(rod, omega, coarse, start)
    } else {
        solve_carried(rod, omega, coarse, start, |_| {})
    }
    .map_err(|_: RunError| NoEstimate::ComparisonFailed)?;
    if !other.converged() {
        return Err(NoEstimate::ComparisonNotConverged(other.termination));
    }
    let change = RelativeErrors::between(
        &ReportedQuantities::of(&other),
        &ReportedQuantities::of(solution),
    );
    Ok((change, other.solve_seconds, other.counters))
}

/// The error estimate of `solution`, a converged solve of `structure` at `omega` with `settings`
/// (module documentation).
pub fn estimate(
    structure: &Structure,
    omega: f64,
    settings: &SolverSettings,
    solution: &Solution,
) -> Result<ErrorEstimate, NoEstimate> {
    if !solution.converged() {
        return Err(NoEstimate::NotConverged);
    }
    let mut comparison = comparison(settings, structure)?;
    let formulation = crate::solve::formulation::of(settings.method);
    if formulation.marches() {
        comparison.settings.max_periods = comparison
            .settings
            .max_periods
            .min(solution.iterations.max(MIN_COMPARISON_PERIODS));
    }
    let start = carried_start(structure, solution, &comparison.settings);
    let (change, mut seconds, mut counters) = change_against(
        structure,
        omega,
        solution,
        &comparison.settings,
        start.as_deref(),
    )?;
    let mut parts = change.scaled(comparison.factor);
    let mut basis = EstimateBasis {
        against: Discretisation::of(&comparison.settings),
        order: comparison.order,
        softer_penalty: None,
        time_samples_check: None,
    };
    if formulation.penalises_contact() {
        let (penalty, penalty_parts, s, c) = penalty_part(structure, omega, settings, solution)?;
        parts = parts.plus(&penalty_parts);
        seconds += s;
        counters = counters + c;
        basis.softer_penalty = Some(penalty);
    }
    Ok(ErrorEstimate {
        relative: parts.largest(),
        parts,
        basis,
        seconds,
        counters,
    })
}

/// Penalty HB's penalty part: the change against `k_p / 10`, started from the solution,
/// divided by 9; with the softer stiffness, the comparison's time and work.
pub(crate) fn penalty_part(
    rod: &Structure,
    omega: f64,
    settings: &SolverSettings,
    solution: &Solution,
) -> Result<(f64, RelativeErrors, f64, RunCounters), NoEstimate> {
    let stiffness = crate::solve::penalty_options(settings, &rod.model).penalty_stiffness;
    let softer = SolverSettings {
        penalty_stiffness: Some(stiffness / PENALTY_RATIO),
        estimate_error: false,
        accuracy: None,
        ..settings.clone()
    };
    let (change, seconds, counters) =
        change_against(rod, omega, solution, &softer, Some(&solution.state))?;
    Ok((
        stiffness / PENALTY_RATIO,
        change.scaled(1.0 / (PENALTY_RATIO - 1.0)),
        seconds,
        counters,
    ))
}

/// The order in `H` harmonic balance's estimate assumes: the error of the contact's own
/// displacement maximum, the largest part on the rods, falls like `H^-0.85` (measured
/// from H = 20 to 320; the displacement has a kink where the contact closes, so its
/// truncation error tends to `H^-1`); 0.75 keeps the estimate above the measured errors.
pub const HB_ORDER: f64 = 0.75;

/// Ratio of the harmonics of harmonic balance's comparison (2H, or H/2 for a model too
/// large to solve at 2H).
const HB_RATIO: f64 = 2.0;

/// Fewest steps per period of a time-marching comparison.
const COARSEST_STEPS_PER_PERIOD: usize = 8;

/// Ratio of the penalty stiffnesses of penalty HB's penalty comparison.
const PENALTY_RATIO: f64 = 10.0;
