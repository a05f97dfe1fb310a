//! The formulations behind [`Method`]: one type each, answering what a solve, the accuracy
//! search and estimate, a sweep and stability ask of it. [`of`] is the one place a method
//! is matched to its type: a new formulation adds a type, its impl of [`Formulation`] and
//! one arm there.

use super::accuracy::search::{
    MAX_SEARCH_HARMONICS, MAX_SEARCH_LCP_STEPS, MAX_SEARCH_MARCH_STEPS, MAX_SEARCH_UNKNOWNS,
};
use super::accuracy::{self, Comparison, NoEstimate};
use super::{hb_options, penalty_problem, RunError, Solution};
use crate::hb::{HbError, PenaltyHb, ResponseSummary, SsnHb};
use crate::model::{StructuralModel, Structure};
use crate::settings::{default_hb_time_samples, Method, SolverSettings};

/// The parameter a formulation's discretisation is refined in (exhaustive: a formulation
/// with a new kind of discretisation is to be met by every match on the kind).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DiscretisationKind {
    /// Harmonics `H`, with the default AFT samples for them (harmonic balance).
    Harmonics,
    /// Time steps per period of the periodic LCP (`time_samples`).
    TimeSamples,
    /// Time-marching steps per period (`steps_per_period`).
    StepsPerPeriod,
}

impl DiscretisationKind {
    /// The level `settings` give this parameter.
    pub fn level(self, settings: &SolverSettings) -> usize {
        match self {
            Self::Harmonics => settings.harmonics,
            Self::TimeSamples => settings.time_samples,
            Self::StepsPerPeriod => settings.steps_per_period,
        }
    }

    /// Sets the parameter of `settings` to `level` (harmonic balance: with `sample_factor`
    /// times the default AFT samples of `level` harmonics).
    pub fn set_level(self, settings: &mut SolverSettings, level: usize, sample_factor: usize) {
        match self {
            Self::Harmonics => {
                settings.harmonics = level;
                settings.time_samples = sample_factor * default_hb_time_samples(level);
            }
            Self::TimeSamples => settings.time_samples = level,
            Self::StepsPerPeriod => settings.steps_per_period = level,
        }
    }
}

impl Method {
    /// The scene spelling of the method.
    pub fn name(self) -> &'static str {
        of(self).name()
    }

    /// The parameter the method's discretisation is refined in.
    pub fn discretisation(self) -> DiscretisationKind {
        of(self).discretisation()
    }

    /// Whether the method represents the response by harmonics.
    pub fn is_harmonic_balance(self) -> bool {
        self.discretisation() == DiscretisationKind::Harmonics
    }

    /// Whether the method solves the periodic LCP.
    pub fn is_lcp(self) -> bool {
        self.discretisation() == DiscretisationKind::TimeSamples
    }

    /// Whether a sweep with an accuracy target chooses the harmonics point by point.
    pub fn adapts_harmonics(self) -> bool {
        of(self).adapts_harmonics()
    }

    /// Whether the method's unknowns hold the contact forces beside the displacements
    /// (the multipliers of SSN-HB).
    pub fn carries_contact_forces(self) -> bool {
        of(self).carries_contact_forces()
    }

    /// Whether contact is a penalty law (the solve raises its stiffness from a soft one;
    /// the error estimate adds the change against a softer penalty).
    pub fn penalises_contact(self) -> bool {
        of(self).penalises_contact()
    }

    /// How the method models friction.
    pub fn friction(self) -> FrictionSupport {
        of(self).friction()
    }

    /// Whether the method marches in time to a steady state (its tolerance is
    /// `march_tolerance`, its run the long one).
    pub fn marches(self) -> bool {
        of(self).marches()
    }

    /// Whether the method applies only to a model with contact (the periodic LCP is posed
    /// on the contact forces; penalty HB without contact is linear harmonic balance).
    pub fn needs_contact(self) -> bool {
        of(self).needs_contact()
    }
}

/// How a formulation models friction.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrictionSupport {
    /// Exact Coulomb friction, under any normal load.
    Exact,
    /// A regularised law, only under a prescribed normal load.
    RegularisedUnderPrescribedLoad,
    /// None.
    Unsupported,
}

impl SolverSettings {
    /// The defaults for `method`, with its own time discretisation: the AFT samples of
    /// harmonic balance, the time steps per period of the periodic LCP.
    pub fn for_method(method: Method) -> Self {
        let mut settings = Self {
            method,
            ..Self::default()
        };
        if method.is_lcp() {
            settings.time_samples = crate::lcp::PeriodicLcpOptions::default().time_samples;
        }
        settings
    }

    /// These settings with the discretisation `level` of their method
    /// ([`DiscretisationKind::set_level`], the default AFT samples), no error estimate
    /// and no accuracy target.
    pub fn at_level(&self, level: usize) -> Self {
        let mut s = self.clone();
        s.accuracy = None;
        s.estimate_error = false;
        self.method.discretisation().set_level(&mut s, level, 1);
        s
    }
}

/// A harmonic-balance problem of a formulation: its reconstructions over one period do not
/// depend on the frequency it was built at.
pub(crate) enum HarmonicProblem {
    /// SSN-HB (displacements and contact multipliers).
    Ssn(SsnHb),
    /// Penalty HB (displacements).
    Penalty(PenaltyHb),
}

impl HarmonicProblem {
    /// The harmonic-balance problem of `settings`' method at `omega` (`Unsupported` for a
    /// method that is not harmonic balance).
    pub(crate) fn of(
        model: &StructuralModel,
        omega: f64,
        settings: &SolverSettings,
    ) -> Result<Self, RunError> {
        let problem = of(settings.method)
            .harmonic_problem(model, omega, settings)
            .ok_or(RunError::Unsupported {
                method: settings.method.name(),
                what: "a harmonic-balance method (ssn-hb or penalty-hb)",
            })??;
        Ok(problem)
    }

    /// The closed intervals of every contact of `x`, as fractions of the period (the
    /// friction rows of SSN-HB follow the contacts' and have no closed phase).
    pub(crate) fn closed_intervals(&self, x: &[f64]) -> Result<Vec<Vec<(f64, f64)>>, HbError> {
        match self {
            Self::Ssn(p) => (0..p.contacts() - p.friction_points())
                .map(|i| p.closed_intervals(x, i))
                .collect(),
            Self::Penalty(p) => (0..p.contacts())
                .map(|i| p.closed_intervals(x, i))
                .collect(),
        }
    }

    /// SSN-HB's complementarity constant `c` (`None` for penalty HB).
    pub(crate) fn complementarity_constant(&self) -> Option<f64> {
        match self {
            Self::Ssn(p) => Some(p.c()),
            Self::Penalty(_) => None,
        }
    }

    /// The AFT samples per period `Nt`.
    pub(crate) fn time_samples(&self) -> usize {
        match self {
            Self::Ssn(p) => p.basis().time_samples(),
            Self::Penalty(p) => p.basis().time_samples(),
        }
    }

    /// The stiffness of a closed contact: `None` where the contact holds exactly
    /// (SSN-HB), the penalty stiffness of penalty HB.
    pub(crate) fn closed_contact_stiffness(&self) -> Option<f64> {
        match self {
            Self::Ssn(_) => None,
            Self::Penalty(p) => Some(p.penalty_stiffness()),
        }
    }

    /// The summary of `x` observed at `dof` on `points` times.
    pub(crate) fn summary(
        &self,
        x: &[f64],
        dof: usize,
        points: usize,
    ) -> Result<ResponseSummary, HbError> {
        match self {
            Self::Ssn(p) => p.summary(x, dof, points),
            Self::Penalty(p) => p.summary(x, dof, points),
        }
    }

    /// `g_i . u` of row `i` of `G` on `points` times over one period.
    pub(crate) fn row_displacement_samples(
        &self,
        x: &[f64],
        i: usize,
        points: usize,
    ) -> Result<Vec<f64>, HbError> {
        match self {
            Self::Ssn(p) => p.row_displacement_samples(x, i, points),
            Self::Penalty(p) => p.row_displacement_samples(x, i, points),
        }
    }

    /// The problem as a reconstruction of its solutions over one period.
    pub(crate) fn into_reconstruction(self) -> Box<dyn super::HbReconstruction> {
        match self {
            Self::Ssn(p) => Box::new(p),
            Self::Penalty(p) => Box::new(p),
        }
    }
}

/// What a formulation's solve is asked: the structure `rod` at `omega` from a warm start
/// (used where it fits) with the discretisation of `settings`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SolveRequest<'a> {
    pub(crate) rod: &'a Structure,
    pub(crate) omega: f64,
    pub(crate) settings: &'a SolverSettings,
    pub(crate) warm_start: Option<&'a [f64]>,
}

impl<'a> SolveRequest<'a> {
    /// `(rod, omega, settings, warm_start)`.
    pub(crate) fn parts(self) -> (&'a Structure, f64, &'a SolverSettings, Option<&'a [f64]>) {
        (self.rod, self.omega, self.settings, self.warm_start)
    }
}

/// A formulation's solve of a [`SolveRequest`], without error estimate.
pub(crate) type SolveAt = fn(SolveRequest<'_>) -> Result<Solution, RunError>;

/// A formulation's harmonic-balance problem of a model at `omega` with the settings'
/// discretisation.
pub(crate) type BuildHarmonicProblem =
    fn(&StructuralModel, f64, &SolverSettings) -> Result<HarmonicProblem, HbError>;

/// What the library asks of a formulation (module documentation). The defaults are those
/// of a formulation that is neither harmonic balance nor continuable in the frequency.
pub(crate) trait Formulation: Sync {
    /// The scene spelling.
    fn name(&self) -> &'static str;

    /// The parameter its discretisation is refined in.
    fn discretisation(&self) -> DiscretisationKind;

    /// Its solve ([`SolveAt`]).
    fn solver(&self) -> SolveAt;

    /// The accuracy search's ladder: the order in the discretisation, the first level and
    /// the finest (by default those of its kind of discretisation).
    fn search_ladder(&self, rod: &Structure, settings: &SolverSettings) -> (f64, usize, usize) {
        match self.discretisation() {
            DiscretisationKind::Harmonics => {
                let width = rod.model.dofs() + rod.model.contact_count();
                let by_size = (MAX_SEARCH_UNKNOWNS / width.max(1)).saturating_sub(1) / 2;
                (
                    accuracy::HB_ORDER,
                    5,
                    MAX_SEARCH_HARMONICS.min(by_size).max(10),
                )
            }
            DiscretisationKind::TimeSamples => {
                let m = rod.model.contact_count().max(1);
                let limit = MAX_SEARCH_LCP_STEPS.min(crate::lcp::MAX_LCP_SIZE / m);
                (
                    2.0,
                    64.min(limit / 2).max(crate::lcp::MIN_LCP_TIME_SAMPLES),
                    limit,
                )
            }
            DiscretisationKind::StepsPerPeriod => (
                accuracy::march_order(rod, settings),
                64,
                MAX_SEARCH_MARCH_STEPS,
            ),
        }
    }

    /// The discretisation a solve with `settings` is compared with for its error estimate
    /// (by default that of its kind of discretisation).
    fn comparison(
        &self,
        rod: &Structure,
        settings: &SolverSettings,
    ) -> Result<Comparison, NoEstimate> {
        match self.discretisation() {
            DiscretisationKind::Harmonics => accuracy::harmonic_comparison(settings, rod),
            DiscretisationKind::TimeSamples => accuracy::lcp_comparison(settings),
            DiscretisationKind::StepsPerPeriod => accuracy::march_comparison(settings, rod),
        }
    }

    /// The start of a solve with the discretisation of `to` from `solution` (`None`: the
    /// formulation's own start); by default that of its kind of discretisation: harmonic
    /// coefficients truncated or lifted, time-step values interpolated periodically, the
    /// march's final state.
    fn carried_start(
        &self,
        rod: &Structure,
        solution: &Solution,
        to: &SolverSettings,
    ) -> Option<Vec<f64>> {
        let state = &solution.state;
        match self.discretisation() {
            DiscretisationKind::Harmonics => Some(crate::hb::resize_harmonics(
                state,
                solution.harmonics?,
                to.harmonics,
                rod.model.dofs(),
                if self.carries_contact_forces() {
                    rod.model.row_count()
                } else {
                    0
                },
            )),
            DiscretisationKind::TimeSamples => {
                let m = rod.model.contact_count().max(1);
                Some(crate::lcp::interpolate_periodic(state, m, to.time_samples))
            }
            DiscretisationKind::StepsPerPeriod => Some(state.clone()),
        }
    }

    /// How its harmonic-balance problem is built ([`BuildHarmonicProblem`]; `None`: it is
    /// not harmonic balance).
    fn harmonic_builder(&self) -> Option<BuildHarmonicProblem> {
        None
    }

    /// Its harmonic-balance problem at `omega` (`None`: not harmonic balance).
    fn harmonic_problem(
        &self,
        model: &StructuralModel,
        omega: f64,
        settings: &SolverSettings,
    ) -> Option<Result<HarmonicProblem, HbError>> {
        self.harmonic_builder()
            .map(|build| build(model, omega, settings))
    }

    /// Why it cannot be continued in the frequency (`None`: it can).
    fn continuation_refusal(&self) -> Option<&'static str> {
        None
    }

    /// Whether a sweep with an accuracy target chooses the harmonics point by point.
    fn adapts_harmonics(&self) -> bool {
        false
    }

    /// Whether contact is a penalty law ([`Method::penalises_contact`]).
    fn penalises_contact(&self) -> bool {
        false
    }

    /// Whether its unknowns hold the contact forces ([`Method::carries_contact_forces`]).
    fn carries_contact_forces(&self) -> bool {
        false
    }

    /// How it models friction.
    fn friction(&self) -> FrictionSupport {
        FrictionSupport::Unsupported
    }

    /// Whether it marches to a steady state, so that a comparison that did not settle from
    /// the solve's own orbit is not tried again from rest, and runs no longer than the solve.
    fn marches(&self) -> bool {
        false
    }

    /// Whether it applies only with contact ([`Method::needs_contact`]).
    fn needs_contact(&self) -> bool {
        false
    }
}

/// The formulation of `method`: the one match on the method in the library.
pub(crate) fn of(method: Method) -> &'static dyn Formulation {
    match method {
        Method::SsnHb => &SsnHbFormulation,
        Method::PenaltyHb => &PenaltyHbFormulation,
        Method::LcpLemke => &LcpLemkeFormulation,
        Method::LcpSsn => &LcpSsnFormulation,
        Method::March => &MarchFormulation,
    }
}

/// Harmonic balance with exact contact, semismooth Newton (`ssn-hb`).
struct SsnHbFormulation;

impl Formulation for SsnHbFormulation {
    fn name(&self) -> &'static str {
        "ssn-hb"
    }
    fn discretisation(&self) -> DiscretisationKind {
        DiscretisationKind::Harmonics
    }
    fn solver(&self) -> SolveAt {
        super::solve_ssn_hb
    }
    fn harmonic_builder(&self) -> Option<BuildHarmonicProblem> {
        Some(|model, omega, settings| {
            SsnHb::new(model, omega, &hb_options(settings)).map(HarmonicProblem::Ssn)
        })
    }
    fn adapts_harmonics(&self) -> bool {
        true
    }
    fn carries_contact_forces(&self) -> bool {
        true
    }
    fn friction(&self) -> FrictionSupport {
        FrictionSupport::Exact
    }
}

/// Harmonic balance with a penalty contact law (`penalty-hb`).
struct PenaltyHbFormulation;

impl Formulation for PenaltyHbFormulation {
    fn needs_contact(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "penalty-hb"
    }
    fn discretisation(&self) -> DiscretisationKind {
        DiscretisationKind::Harmonics
    }
    fn solver(&self) -> SolveAt {
        super::solve_penalty_hb
    }
    fn harmonic_builder(&self) -> Option<BuildHarmonicProblem> {
        Some(|model, omega, settings| {
            penalty_problem(model, omega, settings).map(HarmonicProblem::Penalty)
        })
    }
    fn penalises_contact(&self) -> bool {
        true
    }
    fn friction(&self) -> FrictionSupport {
        FrictionSupport::RegularisedUnderPrescribedLoad
    }
}

/// The periodic LCP by Lemke's pivoting (`lcp-lemke`).
struct LcpLemkeFormulation;

impl Formulation for LcpLemkeFormulation {
    fn needs_contact(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "lcp-lemke"
    }
    fn discretisation(&self) -> DiscretisationKind {
        DiscretisationKind::TimeSamples
    }
    fn solver(&self) -> SolveAt {
        super::solve_lcp_by_lemke
    }
    fn carried_start(&self, _: &Structure, _: &Solution, _: &SolverSettings) -> Option<Vec<f64>> {
        // Lemke starts from its own basis.
        None
    }
    fn continuation_refusal(&self) -> Option<&'static str> {
        Some(
            "a method continuable in omega (Lemke's pivoting is not a smooth equation): \
             sweep with ssn-hb or penalty-hb, or solve frequency by frequency \
             with `ssn solve`",
        )
    }
}

/// The periodic LCP by semismooth Newton on its min map (`lcp-ssn`).
struct LcpSsnFormulation;

impl Formulation for LcpSsnFormulation {
    fn needs_contact(&self) -> bool {
        true
    }
    fn name(&self) -> &'static str {
        "lcp-ssn"
    }
    fn discretisation(&self) -> DiscretisationKind {
        DiscretisationKind::TimeSamples
    }
    fn solver(&self) -> SolveAt {
        super::solve_lcp_by_min_map
    }
}

/// Time marching to the steady state (`march`).
struct MarchFormulation;

impl Formulation for MarchFormulation {
    fn name(&self) -> &'static str {
        "march"
    }
    fn discretisation(&self) -> DiscretisationKind {
        DiscretisationKind::StepsPerPeriod
    }
    fn solver(&self) -> SolveAt {
        super::march::solve_march
    }
    fn continuation_refusal(&self) -> Option<&'static str> {
        Some(
            "a method continuable in omega (time marching has no equation to continue): \
             sweep with ssn-hb or penalty-hb, or march frequency by frequency \
             with `ssn solve`",
        )
    }
    fn marches(&self) -> bool {
        true
    }
    fn friction(&self) -> FrictionSupport {
        FrictionSupport::Exact
    }
}
