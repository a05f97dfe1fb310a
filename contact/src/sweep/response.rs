//! The result of a sweep: a frequency-response curve and its JSON form.

use semismooth::continuation::{ContinuationCounters, ContinuationTermination, CorrectorFailure};
use semismooth::harmonic::{Aft, FourierBasis};

use crate::contacts::{ContactReport, FrictionSummary};
use crate::hb::{FrictionalContactSummary, HbError};
use crate::settings::{Method, SolverSettings, SweepSettings};
use crate::solve::{RunCounters, RunError};
use crate::stability::Undecided;
use crate::sweep::adaptive::BranchAccuracy;
use crate::sweep::branch::{BifurcationEvent, BranchStability, PointStability};

/// One number of a [`ContactReport`].
type ContactField = fn(&ContactReport) -> f64;

/// A frequency-response curve: one record per branch point ([`ResponsePoint`]), in branch
/// order (the frequency is not monotone across folds), and what belongs to the branch
/// (folds and corners as indices into the points, termination, work, timings).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FrequencyResponse {
    /// Method used.
    pub method: Method,
    /// First natural frequency of the structure (the curve's frequency unit).
    pub omega_1: f64,
    /// The branch points, in branch order.
    pub points: Vec<ResponsePoint>,
    /// Frequencies `ω` (absolute) where the branch turns back, in branch order: the turning
    /// points whose frequency excursion to the next one is at least
    /// [`TURNING_POINT_EXCURSION`] `ω_1` (the core continuation's `fold_excursion`).
    pub folds: Vec<f64>,
    /// Index of the extreme point at each fold (same order as `folds`).
    pub fold_indices: Vec<usize>,
    /// Frequencies `ω` of the smaller reversals, in branch order: the corners of a
    /// piecewise-smooth branch where the frequency goes back by less than
    /// [`TURNING_POINT_EXCURSION`] `ω_1` (an AFT sample or time node entering contact, the
    /// pieces of a penalty branch).
    pub corner_folds: Vec<f64>,
    /// Index of the extreme point at each corner reversal (same order as `corner_folds`).
    pub corner_fold_indices: Vec<usize>,
    /// The start of the sweep (`omega_ratio_from omega_1`).
    pub omega_from: f64,
    /// The end of the sweep (`omega_ratio_to omega_1`).
    pub omega_to: f64,
    /// Why the sweep stopped ([`FrequencyResponse::converged`]).
    pub termination: SweepTermination,
    /// Wall time of the whole computation after the structure was built (reference
    /// amplitude, initial Newton solve, continuation, reconstructions of the observed dof).
    pub solve_seconds: f64,
    /// Work counters (initial Newton solve + continuation).
    pub counters: RunCounters,
    /// The continuation's own counters (corrector iterations, rejected steps).
    pub continuation: ContinuationCounters,
    /// Iterations of the initial globalized Newton solve at `omega_from`.
    pub initial_iterations: usize,
    /// Continuation restarts after failed steps (the core's restart policy).
    pub restarts: usize,
    /// Corners of a piecewise-affine (penalty) branch crossed exactly.
    pub corners: usize,
    /// `u_ref` of the step scaling (module documentation).
    pub reference_amplitude: f64,
    /// Samples per period of the observed dof used for the points' extremes and amplitude.
    pub output_points: usize,
    /// Stability changes between neighbouring points, in branch order.
    pub events: Vec<BifurcationEvent>,
    /// Why points are undecided (the first reason met), `None` when all are decided.
    pub undecided: Option<Undecided>,
    /// Wall time of the stability analysis (not in `solve_seconds`).
    pub stability_seconds: f64,
    /// With an accuracy target ([`SolverSettings::accuracy`], SSN-HB): the harmonics chosen
    /// point by point, what they achieved ([`super::adaptive`]; each point's estimate is its
    /// [`ResponsePoint::error_estimate`]).
    pub accuracy: Option<BranchAccuracy>,
    /// The period-2 branches born at the branch's period doublings (SSN-HB with
    /// stability; [`super::doubling`]), in branch order.
    pub period_two: Vec<super::doubling::PeriodTwoOutcome>,
    /// The peak located between the branch points (harmonic balance;
    /// [`super::peak::locate_peak`]), `None` for other methods or an empty branch.
    pub located_peak: Option<super::peak::LocatedPeak>,
    /// What the points' [`ResponsePoint::state`] hold: the full unknowns, or the contact
    /// forces alone (full states by [`super::StateRecovery`]).
    pub state_storage: StateStorage,
}

/// One point of a frequency-response branch: its frequency, the extremes of the observed
/// dof over one period, the solver's state and work, its stability and its contacts.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ResponsePoint {
    /// Forcing frequency `ω` (absolute).
    pub omega: f64,
    /// `max_t u(t)` of the observed dof over one period.
    pub observed_max: f64,
    /// `min_t u(t)` of the observed dof over one period.
    pub observed_min: f64,
    /// `max_t |u(t)|` of the observed dof over one period.
    pub amplitude: f64,
    /// Corrector iterations (the first point: those of the start correction).
    pub iterations: usize,
    /// The method's unknowns (HB coefficients `[U; Lambda]` or `U`, LCP `[w; z]`),
    /// unscaled, for warm starts and re-solves; with
    /// [`StateStorage::ContactForces`] ([`FrequencyResponse::state_storage`]) SSN-HB's
    /// `Lambda` alone, the full state given by [`super::StateRecovery`].
    pub state: Vec<f64>,
    /// Harmonic balance: the harmonics of the state (`None` for the LCP).
    pub harmonics: Option<usize>,
    /// Harmonic balance: the AFT samples of the state (`None` for the LCP).
    pub time_samples: Option<usize>,
    /// With an accuracy target (SSN-HB, harmonics chosen point by point): the estimated
    /// relative error of the observed extremes ([`super::adaptive`]; `None` without a
    /// target or where the solve at `H/2` did not converge).
    pub error_estimate: Option<f64>,
    /// Stability and contact diagnostics (undecided until the branch's stability is
    /// computed).
    pub stability: PointStability,
    /// Every contact, in the scene's order (as `ssn solve` reports them).
    pub contacts: Vec<ContactReport>,
    /// Every friction point, in the model's order (stick fraction, force and slip velocity
    /// amplitudes, as `ssn solve` reports them).
    pub friction: Vec<FrictionSummary>,
    /// Every 3-D frictional contact, in the model's order (SSN-HB branches; its largest
    /// forces, energy per cycle and fractions, as `ssn solve` reports them).
    pub frictional_contacts: Vec<FrictionalContactSummary>,
}

impl ResponsePoint {
    /// A point at `omega` with the observed extremes `(max, min)`, its corrector
    /// `iterations` and `state`, not yet analysed.
    pub(super) fn new(
        omega: f64,
        (max, min): (f64, f64),
        iterations: usize,
        state: Vec<f64>,
    ) -> Self {
        Self {
            omega,
            observed_max: max,
            observed_min: min,
            amplitude: max.abs().max(min.abs()),
            iterations,
            state,
            harmonics: None,
            time_samples: None,
            error_estimate: None,
            stability: PointStability::default(),
            contacts: Vec::new(),
            friction: Vec::new(),
            frictional_contacts: Vec::new(),
        }
    }

    /// The point's mean contact force: the sum of its contacts' mean forces.
    pub fn contact_force_mean(&self) -> f64 {
        self.contacts.iter().map(|c| c.force_mean).sum()
    }
}

/// What a sweep keeps of each branch point's state ([`ResponsePoint::state`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum StateStorage {
    /// The method's full unknowns (SSN-HB: `[U; Lambda]`, `(2H + 1)(N + m)` numbers).
    #[default]
    Full,
    /// SSN-HB: the contact-force coefficients `Lambda` alone (`m (2H + 1)` numbers, the
    /// trailing part of `[U; Lambda]`); the full state is recovered on demand by
    /// [`super::StateRecovery`]. Other methods, and branches whose harmonics change point by point
    /// (an accuracy target), keep their full states.
    ContactForces,
}

/// Why a sweep stopped.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SweepTermination {
    /// The globalized Newton solve at the start frequency did not converge.
    StartNotConverged {
        /// The Newton run's termination.
        termination: semismooth::newton::Termination,
        /// Its iterations.
        iterations: usize,
        /// Its final `|F|`.
        residual_norm: f64,
    },
    /// The continuation could not correct its start point (or a segment's start after a
    /// restart).
    StartNotCorrected(CorrectorFailure),
    /// The continuation's own termination: the branch reached a bound, or stopped with
    /// the numbers that explain why.
    Branch(ContinuationTermination),
    /// The continuation ended without saying why.
    Unexplained,
}

/// The short name of a sweep's termination: the core's words for the branch, or
/// `start-not-converged (...)`, `start-not-corrected (...)`, `unexplained`.
impl std::fmt::Display for SweepTermination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SweepTermination::StartNotConverged { termination, .. } => {
                write!(f, "start-not-converged ({termination})")
            }
            SweepTermination::StartNotCorrected(failure) => {
                write!(f, "start-not-corrected ({failure})")
            }
            SweepTermination::Branch(t) => write!(f, "{t}"),
            SweepTermination::Unexplained => f.write_str("unexplained"),
        }
    }
}

impl FrequencyResponse {
    /// A curve of `method` over `sweep` without points yet.
    pub(super) fn empty(method: Method, omega_1: f64, sweep: &SweepSettings, u_ref: f64) -> Self {
        Self {
            method,
            omega_1,
            points: Vec::new(),
            folds: Vec::new(),
            fold_indices: Vec::new(),
            corner_folds: Vec::new(),
            corner_fold_indices: Vec::new(),
            omega_from: sweep.omega_ratio_from * omega_1,
            omega_to: sweep.omega_ratio_to * omega_1,
            termination: SweepTermination::Unexplained,
            solve_seconds: 0.0,
            counters: RunCounters::default(),
            continuation: Default::default(),
            initial_iterations: 0,
            restarts: 0,
            corners: 0,
            reference_amplitude: u_ref,
            output_points: 0,
            events: Vec::new(),
            undecided: None,
            stability_seconds: 0.0,
            accuracy: None,
            period_two: Vec::new(),
            located_peak: None,
            state_storage: StateStorage::Full,
        }
    }

    /// The numbers the points keep of their states (the sum of their
    /// [`ResponsePoint::state`] lengths): `(2H + 1)(N + m)` a point for full SSN-HB
    /// states, `m (2H + 1)` with [`StateStorage::ContactForces`].
    pub fn stored_state_numbers(&self) -> usize {
        self.points.iter().map(|p| p.state.len()).sum()
    }

    /// `settings` with the harmonics and AFT samples of point `i` (as given for the LCP or
    /// a point out of range).
    pub fn point_settings(&self, settings: &SolverSettings, i: usize) -> SolverSettings {
        let mut s = settings.clone();
        if let Some(&ResponsePoint {
            harmonics: Some(h),
            time_samples: Some(nt),
            ..
        }) = self.points.get(i)
        {
            s.harmonics = h;
            s.time_samples = nt;
        }
        s.accuracy = None;
        s
    }

    /// Whether the branch reached the end of the sweep (`omega_to`).
    pub fn converged(&self) -> bool {
        matches!(
            self.termination,
            SweepTermination::Branch(ContinuationTermination::ReachedBound { bound, .. })
                if bound == self.omega_to
        )
    }

    /// Each point's stability from `stability` (one record per point), with the branch's
    /// events and the reason for undecided points.
    pub(super) fn set_stability(&mut self, stability: BranchStability) {
        for (point, s) in self.points.iter_mut().zip(stability.points) {
            point.stability = s;
        }
        self.events = stability.events;
        self.undecided = stability.undecided;
    }

    /// Whether the branch has harmonic-balance points (their harmonics and AFT samples).
    pub fn is_harmonic_balance(&self) -> bool {
        self.points.first().is_some_and(|p| p.harmonics.is_some())
    }

    /// Harmonic balance: the harmonics of each point (empty for the LCP).
    pub fn harmonics(&self) -> Vec<usize> {
        self.points.iter().filter_map(|p| p.harmonics).collect()
    }

    /// With an accuracy target: the largest error estimate over the points (`None` if none
    /// was estimated).
    pub fn worst_estimate(&self) -> Option<f64> {
        self.points
            .iter()
            .filter_map(|p| p.error_estimate)
            .reduce(f64::max)
    }

    /// Harmonic balance: the AFT samples of each point (empty for the LCP).
    pub fn time_samples(&self) -> Vec<usize> {
        self.points.iter().filter_map(|p| p.time_samples).collect()
    }

    /// One value of each point, in branch order (a column of the branch: e.g.
    /// `response.column(|p| p.observed_max)`).
    pub fn column<T>(&self, value: impl Fn(&ResponsePoint) -> T) -> Vec<T> {
        self.points.iter().map(value).collect()
    }

    /// `ω` of each point (absolute).
    pub fn omegas(&self) -> Vec<f64> {
        self.points.iter().map(|p| p.omega).collect()
    }

    /// `ω / ω_1` of each point.
    pub fn omega_ratio(&self) -> Vec<f64> {
        self.points.iter().map(|p| p.omega / self.omega_1).collect()
    }

    /// Stable / unstable / undecided, one per point.
    pub fn stable(&self) -> Vec<Option<bool>> {
        self.points.iter().map(|p| p.stability.stable).collect()
    }

    /// `max_t |u(t)|` of the observed dof at each point.
    pub fn amplitudes(&self) -> Vec<f64> {
        self.points.iter().map(|p| p.amplitude).collect()
    }

    /// The mean contact force of each point: the sum of its contacts' mean forces.
    pub fn contact_force_mean(&self) -> Vec<f64> {
        self.points
            .iter()
            .map(ResponsePoint::contact_force_mean)
            .collect()
    }

    /// The CSV columns of the contacts: for contact `k` (the scene's order, from 0, as the
    /// `lambda_k` of `ssn solve --csv`) `contact{k}_force_mean`, `contact{k}_max_penetration`,
    /// `contact{k}_contact_fraction`, `contact{k}_displacement_min` and
    /// `contact{k}_displacement_max`, one value per point (NaN where not computed); then
    /// for 3-D frictional contact `p` (from 1, as `ssn solve --csv`)
    /// `contact3d_{p}_max_normal_force`, `_max_tangential_force`, `_dissipated_energy`,
    /// `_stick_fraction`, `_slip_fraction`, `_separated_fraction`; then the friction points'
    /// numbers, `friction{f}_<name>` for each name of [`FrictionSummary::NAMES`] (point `f`
    /// from 0, as the JSON's `point`).
    pub fn contact_columns(&self) -> Vec<(String, Vec<f64>)> {
        let mut columns = self.unilateral_contact_columns();
        columns.extend(self.frictional_contact_columns());
        columns.extend(self.friction_point_columns());
        columns
    }

    /// The friction points' columns of [`Self::contact_columns`]: for friction point `f`
    /// (the model's order, from 0, as the `point` of the JSON) `friction{f}_<name>` for each
    /// name of [`FrictionSummary::NAMES`], one value per point (NaN where not computed).
    fn friction_point_columns(&self) -> Vec<(String, Vec<f64>)> {
        let count = (self.points.iter())
            .map(|p| p.friction.len())
            .max()
            .unwrap_or(0);
        let mut columns = Vec::with_capacity(count * FrictionSummary::NAMES.len());
        for f in 0..count {
            for (k, name) in FrictionSummary::NAMES.iter().enumerate() {
                let values = (self.points.iter())
                    .map(|point| point.friction.get(f).map_or(f64::NAN, |s| s.named()[k].1))
                    .collect();
                columns.push((format!("friction{f}_{name}"), values));
            }
        }
        columns
    }

    /// The 3-D frictional contacts' columns of [`Self::contact_columns`].
    fn frictional_contact_columns(&self) -> Vec<(String, Vec<f64>)> {
        type Field = fn(&FrictionalContactSummary) -> f64;
        let count = (self.points.iter())
            .map(|p| p.frictional_contacts.len())
            .max()
            .unwrap_or(0);
        let fields: [(&str, Field); 6] = [
            ("max_normal_force", |c| c.max_normal_force),
            ("max_tangential_force", |c| c.max_tangential_force),
            ("dissipated_energy", |c| c.dissipated_energy),
            ("stick_fraction", |c| c.stick_fraction),
            ("slip_fraction", |c| c.slip_fraction),
            ("separated_fraction", |c| c.separated_fraction),
        ];
        let mut columns = Vec::with_capacity(count * fields.len());
        for k in 0..count {
            for (name, field) in fields {
                let values = (self.points.iter())
                    .map(|point| point.frictional_contacts.get(k).map_or(f64::NAN, field))
                    .collect();
                columns.push((format!("contact3d_{}_{name}", k + 1), values));
            }
        }
        columns
    }

    /// The 1-D contacts' columns of [`Self::contact_columns`].
    fn unilateral_contact_columns(&self) -> Vec<(String, Vec<f64>)> {
        let count = self
            .points
            .iter()
            .map(|p| p.contacts.len())
            .max()
            .unwrap_or(0);
        let fields: [(&str, ContactField); 5] = [
            ("force_mean", |c| c.force_mean),
            ("max_penetration", |c| c.max_penetration),
            ("contact_fraction", |c| c.contact_fraction),
            ("displacement_min", |c| c.displacement_min),
            ("displacement_max", |c| c.displacement_max),
        ];
        let mut columns = Vec::with_capacity(count * fields.len());
        for k in 0..count {
            for (name, field) in fields {
                let values = self
                    .points
                    .iter()
                    .map(|point| point.contacts.get(k).map_or(f64::NAN, field))
                    .collect();
                columns.push((format!("contact{k}_{name}"), values));
            }
        }
        columns
    }

    /// Index and value of the largest amplitude (`None` for an empty curve).
    pub fn peak(&self) -> Option<(usize, f64)> {
        self.points
            .iter()
            .map(|p| p.amplitude)
            .enumerate()
            .fold(None, |best, (i, a)| match best {
                Some((_, b)) if b >= a => best,
                _ => Some((i, a)),
            })
    }
}

/// Reconstructs one dof over a period from HB coefficients (index `j N + dof`).
pub(super) struct HbTip {
    aft: Aft,
    coeffs: Vec<f64>,
    samples: Vec<f64>,
    dofs: usize,
    dof: usize,
}

impl HbTip {
    pub(super) fn new(
        harmonics: usize,
        points: usize,
        dofs: usize,
        dof: usize,
    ) -> Result<Self, RunError> {
        let basis = FourierBasis::new(harmonics, points).map_err(HbError::from)?;
        Ok(Self {
            aft: Aft::new(basis),
            coeffs: vec![0.0; 2 * harmonics + 1],
            samples: vec![0.0; points],
            dofs,
            dof,
        })
    }

    /// `(max, min)` of the dof over a period.
    pub(super) fn extremes(&mut self, x: &[f64]) -> Result<(f64, f64), RunError> {
        for (j, c) in self.coeffs.iter_mut().enumerate() {
            *c = x[j * self.dofs + self.dof];
        }
        self.aft
            .to_time(&self.coeffs, &mut self.samples)
            .map_err(HbError::from)?;
        Ok(extremes(&self.samples))
    }
}

/// `(max, min)` of samples.
pub(super) fn extremes(samples: &[f64]) -> (f64, f64) {
    samples
        .iter()
        .fold((f64::NEG_INFINITY, f64::INFINITY), |(hi, lo), v| {
            (hi.max(*v), lo.min(*v))
        })
}

/// Smallest frequency excursion, in units of `ω_1`, by which a branch leaves a reversal for
/// it to be a turning point (a fold) rather than a corner (the core's
/// [`fold_excursion`](semismooth::continuation::ContinuationOptions::fold_excursion)).
/// Measured: on the 20-element rod at `H = 20` the micro-zigzags of fine steps (step
/// 0.002) go back by at most 1.1e-3 `ω_1`, the corners of a penalty branch at
/// `k_p = 1000` by at most 6e-4 `ω_1`; on the two-dof chain with a stop on its free mass
/// the branch zigzags by 2.1e-3 to 3.4e-3 `ω_1` at `H = 10` and `20` below the resonance
/// (the largest multiplier stays near 0.4 through them: no fold of the flow) and not at
/// `H = 40`; the overhangs of the paper's forcings are 9.8e-3 (p0 = 0.04) and 8.6e-2
/// (p0 = 0.2) `ω_1` wide.
pub const TURNING_POINT_EXCURSION: f64 = 5e-3;
