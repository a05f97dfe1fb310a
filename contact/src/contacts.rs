//! Per-contact diagnostics of one period: for every contact point its gap, mean force,
//! largest penetration, fraction of the period in contact and displacement range, so that
//! no contact is left out of a run's report (`contacts` in `ssn solve --json`).

/// One contact point over one period.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
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

/// One friction point over one period: its tangential force and slip velocity at the
/// run's output times, with the numbers a sweep keeps per point ([`FrictionSummary`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FrictionReport {
    /// Index of the friction point (the model's order).
    pub point: usize,
    /// Tangential force `lambda_t` at the run's times (for harmonic balance the law's force
    /// `proj_[-b, b](lambda_t - c y_t)` of the truncated series, inside the slip limit by
    /// construction; the series of `lambda_t` itself rings past it like a square wave's).
    pub force: Vec<f64>,
    /// Slip velocity `v_t = d (g_t . u) / dt` at the same times.
    pub slip_velocity: Vec<f64>,
    /// Stick fraction, force and velocity amplitudes.
    pub summary: FrictionSummary,
}

/// The per-point numbers of a friction point over one period.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct FrictionSummary {
    /// Fraction of the period the point sticks: for harmonic balance the samples where the
    /// law's argument is strictly inside the slip limit (`|lambda_t - c y_t| < b`), for
    /// regularised friction where `|v_t| < eps`, for time marching the steps with a slip
    /// velocity below `1e-8` of its largest magnitude.
    pub stick_fraction: f64,
    /// Largest tangential force magnitude `max |lambda_t|` over the period.
    pub force_amplitude: f64,
    /// Largest slip velocity magnitude `max |v_t|` over the period.
    pub slip_velocity_amplitude: f64,
    /// Largest slip limit `max mu N` over the period.
    pub slip_limit_max: f64,
}

impl FrictionSummary {
    /// The names of [`FrictionSummary::named`]'s numbers, as the outputs (JSON, sweep CSV,
    /// study table) spell them.
    pub const NAMES: [&'static str; 4] = [
        "stick_fraction",
        "force_amplitude",
        "slip_velocity_amplitude",
        "slip_limit_max",
    ];

    /// The summary's numbers with their names ([`FrictionSummary::NAMES`]): the one list
    /// every output of a friction point takes.
    pub fn named(&self) -> [(&'static str, f64); 4] {
        let [stick, force, velocity, limit] = Self::NAMES;
        [
            (stick, self.stick_fraction),
            (force, self.force_amplitude),
            (velocity, self.slip_velocity_amplitude),
            (limit, self.slip_limit_max),
        ]
    }
}

impl FrictionReport {
    /// The report of friction point `point` from its force, slip velocity and slip limit
    /// samples and the samples where it sticks (all at the same equally spaced times).
    pub fn from_samples(
        point: usize,
        force: Vec<f64>,
        slip_velocity: Vec<f64>,
        slip_limit: &[f64],
        stuck: impl Iterator<Item = bool>,
    ) -> Self {
        let samples = force.len().max(1) as f64;
        let largest = |v: &[f64]| v.iter().fold(0.0f64, |a, x| a.max(x.abs()));
        let summary = FrictionSummary {
            stick_fraction: stuck.filter(|s| *s).count() as f64 / samples,
            force_amplitude: largest(&force),
            slip_velocity_amplitude: largest(&slip_velocity),
            slip_limit_max: largest(slip_limit),
        };
        Self {
            point,
            force,
            slip_velocity,
            summary,
        }
    }
}

/// Slip velocity, relative to the run's velocity scale, below which a time-marching step
/// counts as stuck: the step's friction problem is solved to `1e-12` of its impulse scale,
/// so a stuck point's velocity is round-off far below it.
pub const MARCH_STICK_VELOCITY: f64 = 1e-8;

/// The report of a time-marched friction point from its force and slip velocity at the
/// steps of one period and its slip limits there; a step sticks where `|v_t|` is below
/// [`MARCH_STICK_VELOCITY`] times the largest of `velocity_scale` and `max |v_t|`.
pub fn march_friction_report(
    point: usize,
    force: Vec<f64>,
    slip_velocity: Vec<f64>,
    slip_limit: &[f64],
    velocity_scale: f64,
) -> FrictionReport {
    let scale = slip_velocity
        .iter()
        .fold(velocity_scale, |a, v| a.max(v.abs()));
    let stuck: Vec<bool> = slip_velocity
        .iter()
        .map(|v| v.abs() <= MARCH_STICK_VELOCITY * scale)
        .collect();
    FrictionReport::from_samples(point, force, slip_velocity, slip_limit, stuck.into_iter())
}

/// One contact's diagnostics over a period.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
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

/// Sets each report's mean force to the mean of its contact's truncated force series
/// (`series`, one per contact; nothing when empty): a harmonic-balance contact's mean force
/// is the series' constant term, what the mean of the equations balances, not the mean of
/// the law's samples on the output grid.
pub(crate) fn set_series_means(
    reports: &mut [ContactReport],
    contacts: &[(usize, f64)],
    series: &[Vec<f64>],
    displacements: &[Vec<f64>],
) {
    if series.is_empty() {
        return;
    }
    let of_series = contact_reports(contacts, series, displacements);
    for (report, of_series) in reports.iter_mut().zip(of_series) {
        report.force_mean = of_series.force_mean;
    }
}

/// Summary of one period of a contact response, from samples at equal time steps.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
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
