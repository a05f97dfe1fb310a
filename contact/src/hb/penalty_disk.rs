//! Penalty harmonic balance on 3-D frictional contacts: the normal force of the penalty
//! spring `N = k_p max(0, g_n . u - gap(t))` (or the prescribed load) and the regularised
//! vector Coulomb law `lambda_t = -mu N v / max(|v|, eps)` on the slip velocity `v` (the
//! structure's tangential velocity minus the obstacle's).
//!
//! As for the one-dimensional points, the law is written on the phase velocity
//! `y = v / w`: `lambda_t = -mu N y / max(|y|, eta)`, `eps = w eta`, so the residual
//! depends on `w` only through the dynamic blocks and the obstacle's offset `s / w`. The
//! width `eta` is the relative regularisation times the static compliance `C_tt` of the
//! contact's first tangent row (times `mu N` under a prescribed load `N`), as for a
//! friction point. Inside the band `|y| < eta` the force is viscous, `-mu N y / eta`; outside
//! it has Coulomb's magnitude `mu N` and the direction of the slip, so as `eta -> 0` it tends
//! to the disk law's force wherever the contact slips, the stick phases replaced by creep.
//!
//! Per sample, with `r = |y|`: `d lambda_t / d y = -(mu N / r) (I - y y^T / r^2)` outside the
//! band and `-(mu N / eta) I` inside; `d lambda_t / d s_n = -mu k_p [s_n > 0] y / max(r, eta)`
//! on the penetration `s_n` (the Jacobian's blocks `X` on the normal row).

use semismooth::harmonic::{Aft, FourierBasis};
use semismooth::{EvaluationError, Residual};

use super::disk::FrictionalContactReport;
use super::jacobian::HbJacobian;
use super::penalty::PenaltyHb;
use super::{check_len, HbError, LinearData};
use crate::model::NormalLaw;

/// The regularised force of one sample (`normal` the force `N >= 0`, `y` the phase
/// velocity, `r = |y|`, `eta` the band), and `d lambda / d y` (row-major 2 x 2).
fn regularised_disk(
    coefficient: f64,
    normal: f64,
    (y, r): ([f64; 2], f64),
    eta: f64,
) -> ([f64; 2], [f64; 4]) {
    let d = r.max(eta);
    let b = coefficient * normal;
    let force = [-b * y[0] / d, -b * y[1] / d];
    let slope = if r > eta {
        let s = -b / r;
        let (u0, u1) = (y[0] / r, y[1] / r);
        [
            s * (1.0 - u0 * u0),
            -s * u0 * u1,
            -s * u0 * u1,
            s * (1.0 - u1 * u1),
        ]
    } else {
        let s = -b / eta;
        [s, 0.0, 0.0, s]
    };
    (force, slope)
}

/// One frictional contact's samples on a grid: the normal force `N >= 0`, whether the
/// penalty spring acts, the two phase velocities and, once [`DiskSamples::evaluate_law`]
/// ran, the law at each sample. The buffers are reused from call to call.
#[derive(Debug, Default)]
pub(crate) struct DiskSamples {
    normal: Vec<f64>,
    closed: Vec<bool>,
    y: [Vec<f64>; 2],
    law: Vec<LawSample>,
}

/// The regularised law at one sample: `|y|`, the force and its slope `d lambda / d y`
/// (row-major 2 x 2).
#[derive(Debug, Clone, Copy)]
struct LawSample {
    speed: f64,
    force: [f64; 2],
    slope: [f64; 4],
}

/// Writes the samples of the series whose coefficient `j` is `coefficient(j)` into `aft`'s
/// samples.
fn to_samples(aft: &mut Aft, coefficient: impl Fn(usize) -> f64) {
    for (j, c) in aft.coefficients_mut().iter_mut().enumerate() {
        *c = coefficient(j);
    }
    aft.coefficients_to_samples();
}

impl DiskSamples {
    /// The samples of frictional contact `p` of `lin` at `u` on the grid of `aft`, with the
    /// penalty stiffness `kp` and the response's frequency `omega`.
    pub(crate) fn sample(
        &mut self,
        aft: &mut Aft,
        (lin, p): (&LinearData, usize),
        u: &[f64],
        (kp, omega): (f64, f64),
    ) {
        let (first, contact) = &lin.frictional[p];
        let (normal, tangents) = contact.rows_from(*first);
        let nt = aft.samples().len();
        self.closed.clear();
        self.normal.clear();
        match (normal, &contact.normal) {
            (Some(n), NormalLaw::Unilateral { .. }) => {
                to_samples(aft, |j| {
                    lin.row_dot(n, u, j) - lin.laws.offset_coefficient(n, j)
                });
                let penetration = aft.samples();
                self.closed.extend(penetration.iter().map(|s| *s > 0.0));
                self.normal
                    .extend(penetration.iter().map(|s| kp * s.max(0.0)));
            }
            (_, NormalLaw::Prescribed(load)) => {
                self.normal.resize(nt, *load);
                self.closed.resize(nt, true);
            }
            _ => {}
        }
        for (a, &t) in tangents.iter().enumerate() {
            let sliding = lin.laws.sliding[t];
            to_samples(aft, |j| match j {
                0 => -sliding / omega,
                j => lin.measured_coefficient(t, u, j),
            });
            self.y[a].clear();
            self.y[a].extend_from_slice(aft.samples());
        }
    }

    /// `|y|`, the regularised force and its slope at every sample (band `eta`, coefficient
    /// `mu`): the law and its hypot evaluated once per sample.
    fn evaluate_law(&mut self, mu: f64, eta: f64) {
        self.law.clear();
        for (n, normal) in self.normal.iter().enumerate() {
            let y = [self.y[0][n], self.y[1][n]];
            let speed = y[0].hypot(y[1]);
            let (force, slope) = regularised_disk(mu, *normal, (y, speed), eta);
            self.law.push(LawSample {
                speed,
                force,
                slope,
            });
        }
    }

    /// The number of samples where the penalty spring acts.
    fn closed_count(&self) -> usize {
        self.closed.iter().filter(|c| **c).count()
    }
}

impl PenaltyHb {
    /// The samples of frictional contact `p` at `u` on the AFT's grid and its law at them
    /// (in the reused storage: give it back to `disk_samples`).
    fn sampled(&mut self, lin: &LinearData, p: usize, u: &[f64]) -> DiskSamples {
        let (kp, omega) = (self.penalty_stiffness(), self.state.omega);
        let mut samples = std::mem::take(&mut self.disk_samples);
        samples.sample(&mut self.state.aft, (lin, p), u, (kp, omega));
        samples.evaluate_law(lin.frictional[p].1.coefficient, self.disk_eta[p]);
        samples
    }

    /// `out += -G^T P lambda` of every frictional contact at `u`: the penalty normal force
    /// on its normal row and the regularised disk law on its tangent rows.
    pub(super) fn add_frictional_residual(&mut self, u: &[f64], out: &mut [f64]) {
        let lin = self.state.linear.clone();
        for p in 0..lin.frictional.len() {
            let (first, contact) = &lin.frictional[p];
            let (normal, tangents) = contact.rows_from(*first);
            let samples = self.sampled(&lin, p, u);
            let mut add = |aft: &mut Aft, row: usize, value: &dyn Fn(usize) -> f64| {
                for (n, s) in aft.samples_mut().iter_mut().enumerate() {
                    *s = value(n);
                }
                aft.samples_to_coefficients();
                for (j, c) in aft.coefficients().iter().enumerate() {
                    lin.add_row_transpose(row, *c, out, j);
                }
            };
            if let Some(n) = normal {
                // - G_n^T P lambda_n = + G_n^T P N.
                add(&mut self.state.aft, n, &|k| samples.normal[k]);
            }
            for (a, &t) in tangents.iter().enumerate() {
                add(&mut self.state.aft, t, &|k| -samples.law[k].force[a]);
            }
            self.disk_samples = samples;
        }
    }

    /// Writes every frictional contact's blocks at `u` into `jac` (the penalty coupling
    /// `k_p G_a^T Q_ab M_b G_b + k_p G_a^T X_as G_s`: each block's weights are the law's
    /// slope divided by `-k_p`).
    pub(super) fn write_frictional_jacobian(
        &mut self,
        u: &[f64],
        jac: &mut HbJacobian,
    ) -> Result<(), EvaluationError> {
        let lin = self.state.linear.clone();
        let kp = self.penalty_stiffness();
        for p in 0..lin.frictional.len() {
            let (first, contact) = &lin.frictional[p];
            let (normal, tangents) = contact.rows_from(*first);
            let samples = self.sampled(&lin, p, u);
            let (eta, mu) = (self.disk_eta[p], contact.coefficient);
            let aft = &mut self.state.aft;
            let mut write = |block: &mut faer::Mat<f64>, weight: &dyn Fn(usize) -> f64| {
                for (n, s) in aft.samples_mut().iter_mut().enumerate() {
                    *s = weight(n);
                }
                aft.samples_multiplication_matrix(block);
            };
            let active = samples.closed_count();
            if let Some(n) = normal {
                let closed = |k: usize| if samples.closed[k] { 1.0 } else { 0.0 };
                jac.active[n] = active;
                write(&mut jac.q[lin.laws.diagonal[n]], &closed);
                for (a, &t) in tangents.iter().enumerate() {
                    let Some(x) = lin.laws.x_block(t, n) else {
                        continue;
                    };
                    // -(d lambda_a / d s_n) / k_p = mu [s_n > 0] y_a / max(|y|, eta).
                    write(&mut jac.cross[x], &|k| {
                        mu * closed(k) * samples.y[a][k] / samples.law[k].speed.max(eta)
                    });
                }
            }
            for (a, &ta) in tangents.iter().enumerate() {
                jac.active[ta] = active;
                for (b, &tb) in tangents.iter().enumerate() {
                    let Some(q) = lin.laws.q_block(ta, tb) else {
                        continue;
                    };
                    write(&mut jac.q[q], &|k| -samples.law[k].slope[2 * a + b] / kp);
                }
            }
            self.disk_samples = samples;
        }
        Ok(())
    }

    /// `dR/dw` of the obstacles' sliding: the offset `-s / w` of the phase velocity moves
    /// by `s / w^2`, so `out += -G_t^T P (d lambda_t / d y) s / w^2`.
    pub(crate) fn add_sliding_omega_derivative(&mut self, u: &[f64], out: &mut [f64]) {
        let lin = self.state.linear.clone();
        let omega = self.state.omega;
        for p in 0..lin.frictional.len() {
            let (first, contact) = &lin.frictional[p];
            let (_, tangents) = contact.rows_from(*first);
            let rate = tangents.map(|t| lin.laws.sliding[t] / (omega * omega));
            if rate == [0.0; 2] {
                continue;
            }
            let samples = self.sampled(&lin, p, u);
            for (a, &t) in tangents.iter().enumerate() {
                let aft = &mut self.state.aft;
                for (s, law) in aft.samples_mut().iter_mut().zip(&samples.law) {
                    *s = -(law.slope[2 * a] * rate[0] + law.slope[2 * a + 1] * rate[1]);
                }
                aft.samples_to_coefficients();
                for (j, c) in aft.coefficients().iter().enumerate() {
                    lin.add_row_transpose(t, *c, out, j);
                }
            }
            self.disk_samples = samples;
        }
    }

    /// Number of frictional contacts.
    pub fn frictional_contacts(&self) -> usize {
        self.state.linear.frictional.len()
    }

    /// Frictional contact `p` over one period on `points > 2H` equally spaced times: the
    /// normal force as the equations see it (the truncated series of the penalty force's
    /// Galerkin projection from the `Nt` AFT samples, where the nearest AFT sample's spring
    /// acts, else 0: a stiff penalty evaluated between the samples, or the sign of the
    /// penetration's series there, would read the displacement's truncation ringing as
    /// contact), the regularised law's tangential force under it, the slip velocity, and
    /// sticking where `|v| < eps` (the law's band).
    pub fn frictional_contact_report(
        &self,
        u: &[f64],
        p: usize,
        points: usize,
    ) -> Result<FrictionalContactReport, HbError> {
        check_len("HB unknowns", self.dim(), u.len())?;
        let lin = &self.state.linear;
        let Some((_, contact)) = lin.frictional.get(p) else {
            return Err(HbError::IndexOutOfRange {
                what: "frictional contact",
                index: p,
                count: lin.frictional.len(),
            });
        };
        let (kp, omega) = (self.penalty_stiffness(), self.state.omega);
        let mut samples = DiskSamples::default();
        // The normal force's series from the AFT samples.
        let mut aft = Aft::new(lin.basis);
        samples.sample(&mut aft, (lin, p), u, (kp, omega));
        let active = std::mem::take(&mut samples.closed);
        aft.samples_mut().copy_from_slice(&samples.normal);
        aft.samples_to_coefficients();
        let series = aft.coefficients().to_vec();
        let mut fine = Aft::new(FourierBasis::new(lin.basis.harmonics(), points)?);
        let mut projected = vec![0.0; points];
        fine.to_time(&series, &mut projected)?;
        samples.sample(&mut fine, (lin, p), u, (kp, omega));
        let nt = active.len();
        for (k, (n, projected)) in samples.normal.iter_mut().zip(projected).enumerate() {
            // The nearest AFT sample: round(k Nt / points).
            let nearest = ((2 * k * nt + points) / (2 * points)) % nt;
            *n = if active[nearest] {
                projected.max(0.0)
            } else {
                0.0
            };
        }
        let eta = self.disk_eta[p];
        samples.evaluate_law(contact.coefficient, eta);
        let stuck = samples.law.iter().map(|law| law.speed < eta).collect();
        let force = [0, 1].map(|a| samples.law.iter().map(|law| law.force[a]).collect());
        let velocity = samples.y.map(|y| y.iter().map(|v| omega * v).collect());
        let normal = samples.normal.iter().map(|n| -n).collect();
        Ok(FrictionalContactReport::from_series(
            p,
            normal,
            (force, velocity),
            stuck,
            omega,
        ))
    }
}

/// The band `eta` of each frictional contact of `lin` for the relative width `relative`:
/// `relative C_tt` times `mu N` under a prescribed load (module documentation).
pub(crate) fn disk_widths(lin: &LinearData, compliance: &[f64], relative: f64) -> Vec<f64> {
    lin.frictional
        .iter()
        .zip(compliance)
        .map(|((_, contact), c)| match contact.normal {
            NormalLaw::Prescribed(load) if contact.coefficient * load > 0.0 => {
                relative * contact.coefficient * load * c
            }
            _ => relative * c,
        })
        .collect()
}
