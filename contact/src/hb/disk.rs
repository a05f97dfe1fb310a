//! A 3-D frictional contact's period from an SSN-HB solution: its normal force, the
//! tangential force vector of the disk law and the slip velocity vector at equally spaced
//! times, the energy it dissipates per cycle and the fractions of the period it sticks,
//! slips and is separated.

use semismooth::harmonic::{Aft, FourierBasis};

use super::ssn::SsnHb;
use super::HbError;
use crate::model::NormalLaw;

/// One frictional contact over one period (at `points` equally spaced times).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct FrictionalContactReport {
    /// Index of the frictional contact (the model's order).
    pub point: usize,
    /// Normal force `lambda_n <= 0`: the unilateral law's `min(0, lambda_n - c (g_n . u -
    /// gap))` of the truncated series, or `-N` under a prescribed load.
    pub normal_force: Vec<f64>,
    /// Tangential force, two components: the disk law's projection of the truncated series
    /// (inside the disk by construction).
    pub tangential_force: [Vec<f64>; 2],
    /// Slip velocity `(g_1 . u', g_2 . u')` relative to the obstacle (minus its sliding
    /// velocity).
    pub slip_velocity: [Vec<f64>; 2],
    /// Energy dissipated per cycle, `-int_0^T lambda_t . v_t dt` (rectangle rule on the
    /// samples: exact for trigonometric polynomials of degree below `points`).
    pub dissipated_energy: f64,
    /// Fraction of the samples that stick (`|z_t| < mu N`, closed).
    pub stick_fraction: f64,
    /// Fraction of the samples that slip (closed, on the disk's boundary).
    pub slip_fraction: f64,
    /// Fraction of the samples where the contact is open (normal force 0).
    pub separated_fraction: f64,
}

/// The numbers of a [`FrictionalContactReport`] without its series: what a sweep keeps
/// per point and contact.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub struct FrictionalContactSummary {
    /// Index of the frictional contact (the model's order).
    pub point: usize,
    /// Largest normal force magnitude over the period, `max_t -lambda_n(t)`.
    pub max_normal_force: f64,
    /// Largest tangential force magnitude over the period, `max_t |lambda_t(t)|`.
    pub max_tangential_force: f64,
    /// Energy dissipated per cycle (as the report's).
    pub dissipated_energy: f64,
    /// Fraction of the period it sticks.
    pub stick_fraction: f64,
    /// Fraction of the period it slips.
    pub slip_fraction: f64,
    /// Fraction of the period it is open.
    pub separated_fraction: f64,
}

impl FrictionalContactReport {
    /// Its numbers: the largest force magnitudes over the samples, the energy and the
    /// fractions.
    pub fn summary(&self) -> FrictionalContactSummary {
        let [t1, t2] = &self.tangential_force;
        let largest = |values: &mut dyn Iterator<Item = f64>| values.fold(0.0f64, f64::max);
        FrictionalContactSummary {
            point: self.point,
            max_normal_force: largest(&mut self.normal_force.iter().map(|f| -f)),
            max_tangential_force: largest(&mut t1.iter().zip(t2).map(|(a, b)| a.hypot(*b))),
            dissipated_energy: self.dissipated_energy,
            stick_fraction: self.stick_fraction,
            slip_fraction: self.slip_fraction,
            separated_fraction: self.separated_fraction,
        }
    }
}

impl SsnHb {
    /// Number of frictional contacts.
    pub fn frictional_contacts(&self) -> usize {
        self.state.linear.frictional.len()
    }

    /// Frictional contact `p` over one period on `points > 2H` equally spaced times.
    pub fn frictional_contact_report(
        &self,
        x: &[f64],
        p: usize,
        points: usize,
    ) -> Result<FrictionalContactReport, HbError> {
        let (u, lambda) = (
            self.displacement_coefficients(x)?,
            self.force_coefficients(x)?,
        );
        let lin = &self.state.linear;
        let Some((first, contact)) = lin.frictional.get(p) else {
            return Err(HbError::IndexOutOfRange {
                what: "frictional contact",
                index: p,
                count: lin.frictional.len(),
            });
        };
        let (m, c, omega) = (lin.contacts(), self.c(), self.state.omega);
        let mut aft = Aft::new(FourierBasis::new(lin.basis.harmonics(), points)?);
        let mut sample = |coefficient: &dyn Fn(usize) -> f64| -> Result<Vec<f64>, HbError> {
            let coeffs: Vec<f64> = (0..lin.size()).map(coefficient).collect();
            let mut out = vec![0.0; points];
            aft.to_time(&coeffs, &mut out)?;
            Ok(out)
        };
        let (_, tangents) = contact.rows_from(*first);
        // Closed-law normal force (the unilateral projection), and the disk's radius from
        // the normal force series as the residual samples it.
        let (normal_force, radius) = match &contact.normal {
            NormalLaw::Unilateral { .. } => {
                // c times the (moving) gap's coefficient j.
                let offset = |j: usize| c * lin.laws.offset_coefficient(*first, j);
                let z = sample(&|j| {
                    lambda[j * m + first] - c * lin.measured_coefficient(*first, u, j) + offset(j)
                })?;
                let series = sample(&|j| lambda[j * m + first])?;
                let radius = series
                    .iter()
                    .map(|l| contact.coefficient * (-l).max(0.0))
                    .collect();
                (z.iter().map(|z| z.min(0.0)).collect(), radius)
            }
            NormalLaw::Prescribed(load) => (
                vec![-load; points],
                vec![contact.coefficient * load; points],
            ),
        };
        let mut argument = [Vec::new(), Vec::new()];
        let mut slip_velocity = [Vec::new(), Vec::new()];
        for (a, i) in tangents.into_iter().enumerate() {
            let sliding = lin.laws.sliding[i];
            // The slip velocity relative to the obstacle, without the mean-slip anchor on
            // its constant; the argument with the obstacle's offset `s / w`.
            let slip = |j: usize| match j {
                0 => -sliding,
                j => omega * lin.measured_coefficient(i, u, j),
            };
            let offset = |j: usize| if j == 0 { c * sliding / omega } else { 0.0 };
            slip_velocity[a] = sample(&slip)?;
            argument[a] =
                sample(&|j| lambda[j * m + i] - c * lin.measured_coefficient(i, u, j) + offset(j))?;
        }
        Ok(FrictionalContactReport::from_samples(
            p,
            normal_force,
            (&argument, &radius),
            slip_velocity,
            omega,
        ))
    }
}

impl FrictionalContactReport {
    /// The report of a time-marched contact from its normal force, tangential force and
    /// slip velocity at the equal steps of one period (the closing sample dropped) of a
    /// response at `omega`: a closed step sticks where `|v_t|` is below `stick_velocity`,
    /// the energy is the rectangle rule on the steps.
    pub fn from_march(
        point: usize,
        normal_force: Vec<f64>,
        (tangential_force, slip_velocity): ([Vec<f64>; 2], [Vec<f64>; 2]),
        omega: f64,
        stick_velocity: f64,
    ) -> Self {
        let stuck = (0..normal_force.len())
            .map(|n| slip_velocity[0][n].hypot(slip_velocity[1][n]) <= stick_velocity)
            .collect();
        Self::from_series(
            point,
            normal_force,
            (tangential_force, slip_velocity),
            stuck,
            omega,
        )
    }

    /// The report from the series and whether each sample sticks (when closed): the
    /// energy `-int lambda_t . v_t dt` by the rectangle rule, the fractions.
    pub(super) fn from_series(
        point: usize,
        normal_force: Vec<f64>,
        (tangential_force, slip_velocity): ([Vec<f64>; 2], [Vec<f64>; 2]),
        stuck: Vec<bool>,
        omega: f64,
    ) -> Self {
        let points = normal_force.len();
        let (mut stick, mut slip, mut work) = (0usize, 0usize, 0.0);
        for n in 0..points {
            work += tangential_force[0][n] * slip_velocity[0][n]
                + tangential_force[1][n] * slip_velocity[1][n];
            match (normal_force[n] < 0.0, stuck[n]) {
                (true, true) => stick += 1,
                (true, false) => slip += 1,
                (false, _) => {}
            }
        }
        let fraction = |k: usize| k as f64 / points.max(1) as f64;
        let period = 2.0 * std::f64::consts::PI / omega;
        Self {
            point,
            normal_force,
            tangential_force,
            slip_velocity,
            dissipated_energy: -work * period / points.max(1) as f64,
            stick_fraction: fraction(stick),
            slip_fraction: fraction(slip),
            separated_fraction: fraction(points - stick - slip),
        }
    }

    /// The report from the normal force, the disk law's arguments `z_t` and radii, the slip
    /// velocity samples and the angular frequency (the period `2 pi / omega`).
    fn from_samples(
        point: usize,
        normal_force: Vec<f64>,
        (argument, radius): (&[Vec<f64>; 2], &[f64]),
        slip_velocity: [Vec<f64>; 2],
        omega: f64,
    ) -> Self {
        let points = normal_force.len();
        let mut force = [vec![0.0; points], vec![0.0; points]];
        let mut stuck = vec![false; points];
        for n in 0..points {
            let z = [argument[0][n], argument[1][n]];
            let (norm, r) = (z[0].hypot(z[1]), radius[n]);
            let scale = if norm > r { r / norm } else { 1.0 };
            for a in 0..2 {
                force[a][n] = scale * z[a];
            }
            stuck[n] = norm < r;
        }
        Self::from_series(point, normal_force, (force, slip_velocity), stuck, omega)
    }
}
