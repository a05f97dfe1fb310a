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

use semismooth::floquet::{crossing, BifurcationKind};

use crate::contacts::ContactSummary;
use crate::hb::{HbError, PenaltyHb, ResponseSummary, SsnHb};
use crate::model::{StructuralModel, Structure};
use crate::settings::{Method, SolverSettings};
use crate::solve::{hb_options, penalty_options, RunError};
use crate::stability::{hb_stability, Stability, StabilityError, StabilityOptions, Undecided};
use crate::sweep::FrequencyResponse;

/// Reconstruction points per period for the contact diagnostics.
const DIAGNOSTIC_POINTS: usize = 1024;

/// A change of stability between two neighbouring points of a branch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BifurcationEvent {
    /// Fold, period doubling or Neimark–Sacker.
    pub kind: BifurcationKind,
    /// Angular frequency (interpolated where the largest multiplier has modulus 1).
    pub omega: f64,
    /// Index of the point after the change.
    pub index: usize,
}

/// Per-point stability and contact diagnostics of a branch.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BranchStability {
    /// Stable / unstable / undecided, one per point.
    pub stable: Vec<Option<bool>>,
    /// Largest multiplier modulus, one per point (`None`: undecided).
    pub floquet_max_abs: Vec<Option<f64>>,
    /// Mean contact force of the first contact over a period (0 without contact).
    pub contact_force_mean: Vec<f64>,
    /// Largest penetration `max(0, u - g)` over the period and the contacts.
    pub max_penetration: Vec<f64>,
    /// Stability changes in branch order.
    pub events: Vec<BifurcationEvent>,
    /// Why points are undecided (the first reason met), `None` when all are decided.
    pub undecided: Option<Undecided>,
}

impl BranchStability {
    /// `points` undecided points, all for `reason`.
    pub fn not_decided(points: usize, reason: Undecided) -> Self {
        Self {
            stable: vec![None; points],
            floquet_max_abs: vec![None; points],
            contact_force_mean: vec![f64::NAN; points],
            max_penetration: vec![f64::NAN; points],
            events: Vec::new(),
            undecided: Some(reason),
        }
    }
}

/// The harmonic-balance problem whose reconstructions a branch's states belong to.
pub(crate) enum Reconstruction {
    Ssn(SsnHb),
    Penalty(PenaltyHb),
}

impl Reconstruction {
    /// The scene's harmonic-balance problem at `omega` (`Unsupported` for other methods);
    /// its reconstructions over one period do not depend on the frequency.
    pub(crate) fn new(
        model: &StructuralModel,
        omega: f64,
        settings: &SolverSettings,
    ) -> Result<Self, RunError> {
        Ok(match settings.method {
            Method::SsnHb => Self::Ssn(SsnHb::new(model, omega, &hb_options(settings))?),
            Method::PenaltyHb => Self::Penalty(PenaltyHb::new(
                model,
                omega,
                &penalty_options(settings, model),
            )?),
            other => {
                return Err(RunError::Unsupported {
                    method: other.name(),
                    what: "a harmonic-balance method (ssn-hb or penalty-hb)",
                })
            }
        })
    }

    /// Mean force and largest penetration of each contact.
    pub(crate) fn contacts(
        &self,
        model: &StructuralModel,
        x: &[f64],
    ) -> Result<Vec<ContactSummary>, HbError> {
        let first = model.contacts.first().map_or(0, |c| c.dof);
        // Both formulations offer the same summary and reconstruction.
        let gather = |summary: Result<ResponseSummary, HbError>,
                      samples: &dyn Fn(usize) -> Result<Vec<f64>, HbError>| {
            let samples = model
                .contacts
                .iter()
                .map(|c| samples(c.dof))
                .collect::<Result<Vec<_>, _>>()?;
            Ok::<_, HbError>((summary?, samples))
        };
        let (summary, samples) = match self {
            Self::Ssn(p) => gather(p.summary(x, first, DIAGNOSTIC_POINTS), &|dof| {
                p.displacement_samples(x, dof, DIAGNOSTIC_POINTS)
            })?,
            Self::Penalty(p) => gather(p.summary(x, first, DIAGNOSTIC_POINTS), &|dof| {
                p.displacement_samples(x, dof, DIAGNOSTIC_POINTS)
            })?,
        };
        Ok(model
            .contacts
            .iter()
            .zip(samples)
            .enumerate()
            .map(|(k, (c, u))| ContactSummary {
                dof: c.dof,
                gap: c.gap,
                contact_force_mean: summary.contact_force_mean.get(k).copied().unwrap_or(0.0),
                max_penetration: u.iter().fold(0.0f64, |a, v| a.max(v - c.gap)),
            })
            .collect())
    }

    fn summary(&self, x: &[f64], dof: usize) -> Result<(f64, f64), HbError> {
        let s = match self {
            Self::Ssn(p) => p.summary(x, dof, DIAGNOSTIC_POINTS)?,
            Self::Penalty(p) => p.summary(x, dof, DIAGNOSTIC_POINTS)?,
        };
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

/// Stability and diagnostics of every point of `response`, computed with the scene's
/// settings (module documentation).
pub fn branch_stability(
    rod: &Structure,
    settings: &SolverSettings,
    response: &FrequencyResponse,
    options: &StabilityOptions,
) -> Result<BranchStability, StabilityError> {
    let points = response.points();
    let mut out = BranchStability::default();
    let model = &rod.model;
    // The reconstructions over one period do not depend on the frequency: any valid one.
    let omega = rod.omega_1;
    let reconstruction = match settings.method {
        Method::SsnHb => SsnHb::new(model, omega, &hb_options(settings)).map(Reconstruction::Ssn),
        Method::PenaltyHb => PenaltyHb::new(model, omega, &penalty_options(settings, model))
            .map(Reconstruction::Penalty),
        _ => {
            return Ok(BranchStability::not_decided(
                points,
                Undecided::NotHarmonicBalance(settings.method),
            ))
        }
    };
    let reconstruction = reconstruction?;
    let harmonics = settings.harmonics;
    let len = model.dofs() * (2 * harmonics + 1);
    let mut analyses: Vec<Option<Stability>> = Vec::with_capacity(points);
    for (i, x) in response.states.iter().enumerate() {
        let s = hb_stability(model, harmonics, response.omega[i], &x[..len], options)?;
        if s.stable.is_none() && out.undecided.is_none() {
            out.undecided.clone_from(&s.undecided);
        }
        out.stable.push(s.stable);
        out.floquet_max_abs.push(s.floquet_max_abs);
        let (mean, penetration) = reconstruction
            .summary(x, rod.observed_dof)
            .unwrap_or((f64::NAN, f64::NAN));
        out.contact_force_mean.push(mean);
        out.max_penetration.push(penetration);
        analyses.push(s.stable.is_some().then_some(s));
    }
    let mut last: Option<usize> = None;
    for i in 0..points {
        let Some(after) = &analyses[i] else { continue };
        if let Some(j) = last {
            let before = analyses[j].as_ref().expect("decided");
            if let Some(kind) = crossing(&before.multipliers, &after.multipliers) {
                let (a0, a1) = (before.multipliers.max_abs(), after.multipliers.max_abs());
                let (w0, w1) = (response.omega[j], response.omega[i]);
                let t = if (a1 - a0).abs() > 0.0 {
                    ((1.0 - a0) / (a1 - a0)).clamp(0.0, 1.0)
                } else {
                    0.5
                };
                out.events.push(BifurcationEvent {
                    kind,
                    omega: w0 + t * (w1 - w0),
                    index: i,
                });
            }
        }
        last = Some(i);
    }
    Ok(out)
}
