//! Per-contact diagnostics of one period: for every contact point its gap, mean force,
//! largest penetration, fraction of the period in contact and displacement range, so that
//! no contact is left out of a run's report (`contacts` in `ssn solve --json`).

use serde_json::{json, Value};

/// One contact point over one period.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactReport {
    /// Node of the rod (node 0 is clamped).
    pub node: usize,
    /// Degree of freedom (`node - 1`).
    pub dof: usize,
    /// Initial gap.
    pub gap: f64,
    /// Mean contact force over the period (<= 0; 0 for a contact that never closes).
    pub force_mean: f64,
    /// Largest penetration `max(0, u - gap)` over the period.
    pub max_penetration: f64,
    /// Fraction of the period with a compressive force larger than `1e-9` times the
    /// largest force magnitude of the run.
    pub contact_fraction: f64,
    /// Smallest displacement of the contact dof.
    pub displacement_min: f64,
    /// Largest displacement of the contact dof.
    pub displacement_max: f64,
}

impl ContactReport {
    /// The JSON object of one contact (non-finite numbers as null).
    pub fn to_json(&self) -> Value {
        let num = |v: f64| if v.is_finite() { json!(v) } else { Value::Null };
        json!({
            "node": self.node,
            "dof": self.dof,
            "gap": num(self.gap),
            "force_mean": num(self.force_mean),
            "max_penetration": num(self.max_penetration),
            "contact_fraction": num(self.contact_fraction),
            "displacement_min": num(self.displacement_min),
            "displacement_max": num(self.displacement_max),
        })
    }
}

/// The reports of the contacts `(dof, gap)` from their force and displacement samples at
/// equal time steps over one period. A mean force below `1e-14` times the largest force
/// magnitude is round-off of a contact that never closes and is reported as 0.
pub fn contact_reports(
    contacts: &[(usize, f64)],
    forces: &[Vec<f64>],
    displacements: &[Vec<f64>],
) -> Vec<ContactReport> {
    let force_scale = forces.iter().flatten().fold(0.0f64, |a, f| a.max(f.abs()));
    contacts
        .iter()
        .enumerate()
        .map(|(i, &(dof, gap))| {
            let f = forces.get(i).map_or(&[][..], Vec::as_slice);
            let u = displacements.get(i).map_or(&[][..], Vec::as_slice);
            let mut force_mean = if f.is_empty() {
                0.0
            } else {
                f.iter().sum::<f64>() / f.len() as f64
            };
            if force_mean.abs() <= 1e-14 * force_scale.max(1.0) {
                force_mean = 0.0;
            }
            let closed = f.iter().filter(|&&v| v < -1e-9 * force_scale).count();
            ContactReport {
                node: dof + 1,
                dof,
                gap,
                force_mean,
                max_penetration: u.iter().map(|v| (v - gap).max(0.0)).fold(0.0, f64::max),
                contact_fraction: if f.is_empty() {
                    0.0
                } else {
                    closed as f64 / f.len() as f64
                },
                displacement_min: u.iter().copied().fold(f64::INFINITY, f64::min),
                displacement_max: u.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_contact_is_reported_with_its_own_numbers() {
        // Contact 0 closes for a quarter of the period, contact 1 never.
        let f0 = vec![-2.0, 0.0, 0.0, 0.0];
        let f1 = vec![1e-30, -1e-30, 0.0, 0.0];
        let u0 = vec![0.5 + 1e-3, 0.2, -0.4, 0.1];
        let u1 = vec![0.1, 0.0, -0.1, 0.0];
        let r = contact_reports(&[(19, 0.5), (9, 0.3)], &[f0, f1], &[u0, u1]);
        assert_eq!(r.len(), 2);
        assert_eq!((r[0].node, r[0].dof), (20, 19));
        assert_eq!(r[0].force_mean, -0.5);
        assert_eq!(r[0].contact_fraction, 0.25);
        assert!((r[0].max_penetration - 1e-3).abs() < 1e-15);
        assert_eq!(
            (r[0].displacement_min, r[0].displacement_max),
            (-0.4, 0.5 + 1e-3)
        );
        assert_eq!(r[1].force_mean, 0.0);
        assert_eq!(r[1].contact_fraction, 0.0);
        assert_eq!(r[1].max_penetration, 0.0);
        assert_eq!(r[1].to_json()["node"], 10);
    }
}
