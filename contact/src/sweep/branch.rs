//! Stability and contact diagnostics along a frequency-response branch, and the
//! bifurcations where the stability changes.
//!
//! For each point of a harmonic-balance branch ([`FrequencyResponse`] of `ssn-hb` or
//! `penalty-hb`): the Floquet multipliers of [`crate::stability::hb_stability`] (stable,
//! unstable or undecided with a reason), the mean contact force and the largest
//! penetration of the reconstructed solution. Between two neighbouring decided points the
//! number of multipliers outside the unit circle is compared
//! ([`semismooth::floquet::crossing`]): a real one through `+1` is a fold, through `-1` a
//! period doubling, a complex pair a Neimark–Sacker bifurcation. The event's frequency is
//! interpolated linearly where the largest modulus crosses 1.
//!
//! The LCP branches (`lcp-ssn`) carry gaps and forces at time nodes instead of harmonic
//! coefficients: their points are undecided, with that reason.

use semismooth::floquet::{crossing_of, BifurcationKind, Outside};

use crate::contacts::ContactSummary;
use crate::hb::HbError;
use crate::model::{StructuralModel, Structure};
use crate::settings::SolverSettings;
use crate::solve::{HarmonicProblem, RunError};
use crate::stability::{HbStability, Stability, StabilityError, Undecided};
use crate::sweep::{FrequencyResponse, StateRecovery};

/// Reconstruction points per period for the contact diagnostics.
const DIAGNOSTIC_POINTS: usize = 1024;

/// A change of stability between two neighbouring points of a branch.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct BifurcationEvent {
    /// Fold, period doubling or Neimark–Sacker.
    pub kind: BifurcationKind,
    /// Angular frequency (interpolated where the largest multiplier has modulus 1).
    pub omega: f64,
    /// Index of the point after the change.
    pub index: usize,
    /// A stability change interpolated between two points (not a fold of the branch): the
    /// larger distance from `omega` to their frequencies, so that the crossing, which lies
    /// between them, is within it (the points' own discretisation error aside). `None` for a fold of the branch, located instead by the
    /// continuation (and to an accuracy by [`super::fold_accuracy`]).
    pub uncertainty: Option<f64>,
}

/// Stability and contact diagnostics of one point of a branch.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct PointStability {
    /// Stable / unstable / undecided.
    pub stable: Option<bool>,
    /// Largest multiplier modulus (`None`: undecided).
    pub floquet_max_abs: Option<f64>,
    /// Mean contact force of the first contact over a period (0 without contact).
    pub contact_force_mean: f64,
    /// Largest penetration `max(0, u - g)` over the period and the contacts.
    pub max_penetration: f64,
    /// Whether the verdict comes from the branch's fold count: the point's real multiplier
    /// nearest `+1`, within [`FOLD_BAND`], lies on the other side of `+1` than the number
    /// of folds before it requires, and is counted on that side (module documentation).
    pub placed_by_fold: bool,
}

impl Default for PointStability {
    /// Undecided, its diagnostics not computed (NaN).
    fn default() -> Self {
        Self {
            stable: None,
            floquet_max_abs: None,
            contact_force_mean: f64::NAN,
            max_penetration: f64::NAN,
            placed_by_fold: false,
        }
    }
}

/// The stability of a branch: one record per point, and the stability changes between
/// them.
#[derive(Debug, Clone, PartialEq, Default)]
#[non_exhaustive]
pub struct BranchStability {
    /// Stability and contact diagnostics of each point, in branch order.
    pub points: Vec<PointStability>,
    /// Stability changes in branch order.
    pub events: Vec<BifurcationEvent>,
    /// Why points are undecided (the first reason met), `None` when all are decided.
    pub undecided: Option<Undecided>,
}

impl BranchStability {
    /// `points` undecided points, all for `reason`.
    pub fn not_decided(points: usize, reason: Undecided) -> Self {
        Self {
            points: vec![PointStability::default(); points],
            events: Vec::new(),
            undecided: Some(reason),
        }
    }
}

/// The harmonic-balance problem whose reconstructions a branch's states belong to.
pub(crate) struct Reconstruction(HarmonicProblem);

impl Reconstruction {
    /// The scene's harmonic-balance problem at `omega` (`Unsupported` for other methods);
    /// its reconstructions over one period do not depend on the frequency.
    pub(crate) fn new(
        model: &StructuralModel,
        omega: f64,
        settings: &SolverSettings,
    ) -> Result<Self, RunError> {
        let problem = HarmonicProblem::of(model, omega, settings)?;
        Ok(Self(problem))
    }

    /// Mean force and largest penetration of each contact.
    pub(crate) fn contacts(
        &self,
        model: &StructuralModel,
        x: &[f64],
    ) -> Result<Vec<ContactSummary>, HbError> {
        let first = model.contacts.first().map_or(0, |c| c.dof());
        let summary = self.0.summary(x, first, DIAGNOSTIC_POINTS)?;
        let samples = (0..model.contacts.len())
            .map(|i| self.0.row_displacement_samples(x, i, DIAGNOSTIC_POINTS))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(model
            .contacts
            .iter()
            .zip(samples)
            .enumerate()
            .map(|(k, (c, u))| ContactSummary {
                dof: c.dof(),
                gap: c.gap,
                contact_force_mean: summary.contact_force_mean.get(k).copied().unwrap_or(0.0),
                max_penetration: u.iter().fold(0.0f64, |a, v| a.max(v - c.gap)),
            })
            .collect())
    }

    fn summary(&self, x: &[f64], dof: usize) -> Result<(f64, f64), HbError> {
        let s = self.0.summary(x, dof, DIAGNOSTIC_POINTS)?;
        let mean = s.contact_force_mean.first().copied().unwrap_or(0.0);
        Ok((
            if mean.abs() < f64::MIN_POSITIVE {
                0.0
            } else {
                mean
            },
            s.max_penetration,
        ))
    }
}

/// Outside the folds of an overhang, a real multiplier above `+1` and within this distance
/// of it is counted below `+1` where the branch's fold count requires; a farther one is
/// left as computed (`fold_consistent_counts`). Near a fold the multiplier moves like the square root of the distance to it,
/// so the harmonic-balance error of the switching instants moves it far: on the strongly
/// forced modified-mass rod at `H = 20` the point `1.3e-3 omega_1` past the upper fold has
/// its real multiplier at 0.88 (measured, `ssn/tests/stability.rs`).
pub const FOLD_BAND: f64 = 0.25;

/// Stability and diagnostics of every point of `response`, computed with the scene's
/// settings (module documentation); `progress(points)` after each point. Without
/// `multipliers` only the contact diagnostics are computed and every point is undecided
/// ([`Undecided::NotRequested`]).
pub fn branch_stability(
    structure: &Structure,
    settings: &SolverSettings,
    response: &FrequencyResponse,
    multipliers: bool,
    progress: Option<&dyn Fn(usize)>,
) -> Result<BranchStability, StabilityError> {
    let points = response.points.len();
    let mut out = BranchStability::default();
    if !settings.method.is_harmonic_balance() {
        return Ok(BranchStability::not_decided(
            points,
            Undecided::NotHarmonicBalance(settings.method),
        ));
    }
    let analyses = point_analyses(
        structure,
        settings,
        response,
        multipliers,
        progress,
        &mut out,
    )?;
    // The folds only: a zigzag of the truncated balance (`corner_folds`) turns back and
    // forth within the fold excursion, and counting its two reversals would flip the
    // verdict of the points between them.
    // They come in branch order, with their frequencies in `folds`.
    let reversals = &response.fold_indices;
    let outside = fold_consistent_counts(&analyses, reversals);
    for ((s, counts), point) in analyses.iter().zip(&outside).zip(&mut out.points) {
        if s.stable.is_none() && out.undecided.is_none() {
            out.undecided.clone_from(&s.undecided);
        }
        point.stable = counts.map(|(c, _)| c.is_stable());
        point.floquet_max_abs = s.floquet_max_abs;
        point.placed_by_fold = counts.is_some_and(|(_, placed)| placed);
    }
    out.events = bifurcation_events(response, &analyses, &outside);
    Ok(out)
}

/// The reconstruction and the stability analysis of `rod` with `settings`.
fn analysers(
    rod: &Structure,
    settings: &SolverSettings,
) -> Result<(Reconstruction, HbStability), StabilityError> {
    let model = &rod.model;
    let reconstruction =
        Reconstruction::new(model, rod.omega_1, settings).map_err(|e| match e {
            RunError::HarmonicBalance(e) => StabilityError::Hb(e),
            _ => StabilityError::InvalidOption {
                name: "method",
                value: f64::NAN,
                allowed: "a harmonic-balance method (ssn-hb or penalty-hb)",
            },
        })?;
    Ok((reconstruction, HbStability::new(model, settings)?))
}

/// The stability of each point of `response` (undecided without `multipliers`), its
/// contact diagnostics pushed onto `out`; `progress(points)` after each point.
fn point_analyses(
    rod: &Structure,
    settings: &SolverSettings,
    response: &FrequencyResponse,
    multipliers: bool,
    progress: Option<&dyn Fn(usize)>,
    out: &mut BranchStability,
) -> Result<Vec<Stability>, StabilityError> {
    // The reconstructions over one period do not depend on the frequency: any valid one,
    // with the point's harmonics (built again where they change along the branch).
    let mut current = response.point_settings(settings, 0);
    let (mut reconstruction, mut analysis) = analysers(rod, &current)?;
    let mut analyses: Vec<Stability> = Vec::with_capacity(response.points.len());
    let mut states = StateRecovery::new(rod, settings, response);
    for (i, point) in response.points.iter().enumerate() {
        let x = &*states.state(i)?;
        let at = response.point_settings(settings, i);
        if (at.harmonics, at.time_samples) != (current.harmonics, current.time_samples) {
            (reconstruction, analysis) = analysers(rod, &at)?;
            current = at;
        }
        let s = if multipliers {
            analysis.of(point.omega, x)?
        } else {
            Stability::not_decided(Undecided::NotRequested)
        };
        let (mean, penetration) = reconstruction
            .summary(x, rod.observed_dof)
            .unwrap_or((f64::NAN, f64::NAN));
        out.points.push(PointStability {
            contact_force_mean: mean,
            max_penetration: penetration,
            ..PointStability::default()
        });
        analyses.push(s);
        if let Some(report) = progress {
            report(i + 1);
        }
    }
    Ok(analyses)
}

/// The stability changes between neighbouring decided points (counts `outside`), in
/// branch order: at the branch's fold between them for a fold, else interpolated where
/// the largest multiplier modulus crosses 1.
fn bifurcation_events(
    response: &FrequencyResponse,
    analyses: &[Stability],
    outside: &[Option<(Outside, bool)>],
) -> Vec<BifurcationEvent> {
    let reversals = &response.fold_indices;
    let mut events = Vec::new();
    let mut last: Option<usize> = None;
    for i in 0..response.points.len() {
        let Some((after, _)) = outside[i] else {
            continue;
        };
        if let Some(j) = last {
            let (before, _) = outside[j].expect("decided");
            if let Some(kind) = crossing_of(before, after) {
                let (w0, w1) = (response.points[j].omega, response.points[i].omega);
                let (omega, uncertainty) = match reversals.iter().position(|&r| j <= r && r <= i) {
                    // A fold of the branch between the two: the crossing is the fold.
                    Some(k) if kind == BifurcationKind::Fold => (response.folds[k], None),
                    _ => {
                        let a0 = analyses[j].floquet_max_abs.unwrap_or(1.0);
                        let a1 = analyses[i].floquet_max_abs.unwrap_or(1.0);
                        let t = if (a1 - a0).abs() > 0.0 {
                            ((1.0 - a0) / (a1 - a0)).clamp(0.0, 1.0)
                        } else {
                            0.5
                        };
                        let omega = w0 + t * (w1 - w0);
                        (omega, Some((omega - w0).abs().max((w1 - omega).abs())))
                    }
                };
                events.push(BifurcationEvent {
                    kind,
                    omega,
                    index: i,
                    uncertainty,
                });
            }
        }
        last = Some(i);
    }
    events
}

/// The counts of multipliers outside the unit circle of each decided point, with the
/// parity of the real multipliers above `+1` that the number of folds of the branch
/// before the point requires (the flag says where that changed the count): a point that
/// needs one more (the middle branch of an overhang, a saddle between its folds, whatever
/// the impact model's own multipliers say far from the fold) gets its real multiplier
/// nearest `+1` counted above it, or one more when it has none; a point that needs one
/// fewer gets its real multiplier nearest `+1` counted below it only within [`FOLD_BAND`]
/// of `+1` (a multiplier far above `+1`, e.g. where the orbit grazes the stop, is an
/// instability of its own). The parity of the first segment is the one most points agree
/// with. Points at a reversal keep their own counts.
fn fold_consistent_counts(
    analyses: &[Stability],
    reversals: &[usize],
) -> Vec<Option<(Outside, bool)>> {
    let segment = |i: usize| reversals.iter().filter(|&&r| r < i).count();
    let at_reversal = |i: usize| reversals.binary_search(&i).is_ok();
    let mut votes = [0usize; 2];
    for (i, s) in analyses.iter().enumerate() {
        if s.stable.is_some() && !at_reversal(i) {
            let parity = (s.multipliers.outside().real_above_one + segment(i)) % 2;
            votes[parity] += 1;
        }
    }
    let offset = usize::from(votes[1] > votes[0]);
    analyses
        .iter()
        .enumerate()
        .map(|(i, s)| {
            s.stable?;
            let mut counts = s.multipliers.outside();
            let wanted = (offset + segment(i)) % 2;
            if at_reversal(i) || counts.real_above_one % 2 == wanted {
                return Some((counts, false));
            }
            if counts.real_above_one % 2 != wanted && wanted == (offset + 1) % 2 {
                // Between the folds of an overhang: one more above +1.
                counts.real_above_one += 1;
                return Some((counts, true));
            }
            match s.multipliers.nearest_real_to_one() {
                Some(mu) if mu > 1.0 && mu - 1.0 <= FOLD_BAND => {
                    counts.real_above_one -= 1;
                    Some((counts, true))
                }
                _ => Some((counts, false)),
            }
        })
        .collect()
}
