//! Per-contact diagnostics of one period: for every contact point its gap, mean force,
//! largest penetration, fraction of the period in contact and displacement range, so that
//! no contact is left out of a run's report (`contacts` in `ssn solve --json`).

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
    /// Fraction of the period in contact: for harmonic balance the measure of the set where
    /// the contact law is active (its switching function positive on the truncated series,
    /// the samples the generalized Jacobian treats as active, ends refined between
    /// samples: [`semismooth::trigonometric::covered_fraction`]); for the exact methods the fraction of the time
    /// samples with a compressive force larger than `1e-9` times the largest force
    /// magnitude of the run.
    pub contact_fraction: f64,
    /// Smallest displacement of the contact dof.
    pub displacement_min: f64,
    /// Largest displacement of the contact dof.
    pub displacement_max: f64,
}

/// One contact's diagnostics over a period.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSummary {
    /// The contact dof.
    pub dof: usize,
    /// Its gap.
    pub gap: f64,
    /// Mean contact force over a period (`<= 0`).
    pub contact_force_mean: f64,
    /// Largest `max(0, u - g)` over the period.
    pub max_penetration: f64,
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

/// Summary of one period of a contact response, from samples at equal time steps.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PeriodStatistics {
    /// Largest displacement of the observed dof.
    pub max: f64,
    /// Smallest displacement.
    pub min: f64,
    /// Largest penetration `max(0, u - gap)` (0 without contact).
    pub max_penetration: f64,
    /// Mean contact force over the period (<= 0 with the sign convention; 0 without contact).
    pub mean_contact_force: f64,
}

/// Statistics of a displacement series (and, with contact, its gap and force series).
pub fn period_statistics(displacement: &[f64], contact: Option<(f64, &[f64])>) -> PeriodStatistics {
    let max = displacement
        .iter()
        .cloned()
        .fold(f64::NEG_INFINITY, f64::max);
    let min = displacement.iter().cloned().fold(f64::INFINITY, f64::min);
    let (max_penetration, mean_contact_force) = match contact {
        Some((gap, force)) => (
            displacement
                .iter()
                .map(|u| (u - gap).max(0.0))
                .fold(0.0, f64::max),
            if force.is_empty() {
                0.0
            } else {
                force.iter().sum::<f64>() / force.len() as f64
            },
        ),
        None => (0.0, 0.0),
    };
    PeriodStatistics {
        max,
        min,
        max_penetration,
        mean_contact_force,
    }
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
        assert_eq!(r[1].node, 10);
    }

    #[test]
    fn period_statistics_of_a_clipped_cosine() {
        let u: Vec<f64> = (0..100)
            .map(|n| (2.0 * std::f64::consts::PI * n as f64 / 100.0).cos())
            .collect();
        let force = vec![-1.0; 100];
        let s = period_statistics(&u, Some((0.5, &force)));
        assert_eq!(s.max, 1.0);
        assert!((s.min + 1.0).abs() < 1e-3);
        assert!((s.max_penetration - 0.5).abs() < 1e-15);
        assert_eq!(s.mean_contact_force, -1.0);
    }
}
