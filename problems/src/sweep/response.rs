//! The result of a sweep: a frequency-response curve and its JSON form.

use semismooth::continuation::ContinuationCounters;
use semismooth::harmonic::{Aft, FourierBasis};
use serde_json::json;

use crate::branch::BranchStability;
use crate::contacts::ContactReport;
use crate::hb::HbError;
use crate::runner::{RunCounters, RunError};
use crate::scene::Method;

/// One number of a [`ContactReport`].
type ContactField = fn(&ContactReport) -> f64;

/// A frequency-response curve: one entry per branch point, in branch order (the frequency
/// is not monotone across folds).
#[derive(Debug, Clone, PartialEq)]
pub struct FrequencyResponse {
    /// Method used.
    pub method: Method,
    /// First natural frequency of the rod (the curve's frequency unit).
    pub omega_1: f64,
    /// Forcing frequency `ω` of each point (absolute).
    pub omega: Vec<f64>,
    /// `max_t u_tip(t)` over one period.
    pub tip_max: Vec<f64>,
    /// `min_t u_tip(t)` over one period.
    pub tip_min: Vec<f64>,
    /// `max_t |u_tip(t)|` over one period.
    pub amplitude: Vec<f64>,
    /// Corrector iterations of each point (the first: those of the start correction).
    pub iterations: Vec<usize>,
    /// Frequencies `ω` (absolute) where the branch turns back, in branch order.
    pub folds: Vec<f64>,
    /// Index of the extreme point at each fold (same order as `folds`).
    pub fold_indices: Vec<usize>,
    /// Whether the branch reached `omega_ratio_to` (the bound at the end of the sweep).
    pub converged: bool,
    /// Why the continuation stopped, in words.
    pub termination: String,
    /// Wall time of the whole computation after the rod was built (reference amplitude,
    /// initial Newton solve, continuation, tip reconstructions).
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
    /// Tip samples per period used for `tip_max`, `tip_min`, `amplitude`.
    pub output_points: usize,
    /// The method's unknowns at each point (HB coefficients `[U; Lambda]` or `U`, LCP
    /// `[w; z]`), unscaled, for warm starts and re-solves.
    pub states: Vec<Vec<f64>>,
    /// Stability, contact diagnostics and bifurcations of the points.
    pub stability: BranchStability,
    /// Wall time of the stability analysis (not in `solve_seconds`).
    pub stability_seconds: f64,
    /// Every contact of each point, in the scene's order (as `ssn solve` reports them).
    pub contacts: Vec<Vec<ContactReport>>,
}

impl FrequencyResponse {
    pub(super) fn push(
        &mut self,
        omega: f64,
        max: f64,
        min: f64,
        iterations: usize,
        state: Vec<f64>,
    ) {
        self.omega.push(omega);
        self.tip_max.push(max);
        self.tip_min.push(min);
        self.amplitude.push(max.abs().max(min.abs()));
        self.iterations.push(iterations);
        self.states.push(state);
    }

    /// Number of branch points.
    pub fn points(&self) -> usize {
        self.omega.len()
    }

    /// `ω / ω_1` of each point.
    pub fn omega_ratio(&self) -> Vec<f64> {
        self.omega.iter().map(|w| w / self.omega_1).collect()
    }

    /// The mean contact force of each point: the sum of its contacts' mean forces (the
    /// stability diagnostics' value, NaN, where the contacts were not computed).
    pub fn contact_force_mean(&self) -> Vec<f64> {
        (0..self.points())
            .map(|i| match self.contacts.get(i) {
                Some(point) => point.iter().map(|c| c.force_mean).sum(),
                None => self
                    .stability
                    .contact_force_mean
                    .get(i)
                    .copied()
                    .unwrap_or(f64::NAN),
            })
            .collect()
    }

    /// The CSV columns of the contacts: for contact `k` (the scene's order, from 0, as the
    /// `lambda_k` of `ssn solve --csv`) `contact{k}_force_mean`, `contact{k}_max_penetration`,
    /// `contact{k}_contact_fraction`, `contact{k}_displacement_min` and
    /// `contact{k}_displacement_max`, one value per point (NaN where not computed).
    pub fn contact_columns(&self) -> Vec<(String, Vec<f64>)> {
        let count = self.contacts.iter().map(Vec::len).max().unwrap_or(0);
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
                    .contacts
                    .iter()
                    .map(|point| point.get(k).map_or(f64::NAN, field))
                    .collect();
                columns.push((format!("contact{k}_{name}"), values));
            }
        }
        columns
    }

    /// Index and value of the largest amplitude (`None` for an empty curve).
    pub fn peak(&self) -> Option<(usize, f64)> {
        self.amplitude
            .iter()
            .copied()
            .enumerate()
            .fold(None, |best, (i, a)| match best {
                Some((_, b)) if b >= a => best,
                _ => Some((i, a)),
            })
    }

    /// The JSON object of `ssn sweep --json`: `points`, `omega`, `omega_ratio`, `tip_max`,
    /// `tip_min`, `amplitude`, per point `stable` (true / false / null), `floquet_max_abs`,
    /// `contact_force_mean` (the sum over the contacts), `max_penetration`, `contacts` (per
    /// point, the list of [`ContactReport`]s), then `stability_note` (why points are
    /// undecided), `stability_seconds`, `events` ({`kind`, `omega`, `omega_ratio`,
    /// `index`}), `folds`, `converged`, `solve_seconds`, `termination`, `counters`.
    /// Non-finite numbers become `null`.
    pub fn to_json(&self) -> serde_json::Value {
        let mut counters = self.counters.newton_json();
        for (name, value) in [
            (
                "corrector_iterations",
                self.continuation.corrector_iterations,
            ),
            ("rejected_steps", self.continuation.rejected_steps),
            ("corner_passes", self.continuation.corner_passes),
            ("restarts", self.restarts as u64),
            ("corners", self.corners as u64),
        ] {
            counters.insert(name.to_string(), value.into());
        }
        let st = &self.stability;
        let events: Vec<serde_json::Value> = st
            .events
            .iter()
            .map(|e| {
                json!({
                    "kind": e.kind.name(),
                    "omega": e.omega,
                    "omega_ratio": e.omega / self.omega_1,
                    "index": e.index,
                })
            })
            .collect();
        json!({
            "points": self.points(),
            "omega": self.omega,
            "omega_ratio": self.omega_ratio(),
            "tip_max": self.tip_max,
            "tip_min": self.tip_min,
            "amplitude": self.amplitude,
            "stable": st.stable,
            "floquet_max_abs": st.floquet_max_abs,
            "contact_force_mean": self.contact_force_mean(),
            "max_penetration": st.max_penetration,
            "contacts": self
                .contacts
                .iter()
                .map(|point| point.iter().map(ContactReport::to_json).collect::<Vec<_>>())
                .collect::<Vec<_>>(),
            "stability_note": st.note,
            "stability_seconds": self.stability_seconds,
            "events": events,
            "folds": self.folds,
            "converged": self.converged,
            "solve_seconds": self.solve_seconds,
            "termination": self.termination,
            "counters": counters,
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
