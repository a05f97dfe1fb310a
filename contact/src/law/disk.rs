//! Coulomb friction on a two-dimensional tangent plane: the friction disk.
//!
//! With the tangential force `lambda_t` in R^2 (two rows of `G`) and the slip velocity per
//! radian `y_t`, the law in velocity form (Alart–Curnier's augmented Lagrangian, as the
//! one-dimensional [`super::Coulomb`]) is `lambda_t - proj_D(z) = 0`, `z = lambda_t - c y_t`,
//! with `D` the disk of radius `R = mu_c N` (`N` prescribed, or `N = max(0, -lambda_n)` of
//! a unilateral contact read: liftoff shrinks the disk to a point). The projection is
//! radial, `proj_D(z) = R z / max(|z|, R)`; smoothed, `R z / d` with
//! `d = R + phi_mu(|z| - R)` (`phi_mu` the smoothing of `max(0, .)`).
//!
//! Generalized Jacobian per sample: on `z` the 2 x 2 block `(R / d) (I - phi' z z^T / (d |z|))`
//! (`(R / |z|) (I - z z^T / |z|^2)` when sliding, `I` when sticking), and on the normal
//! force the column `d proj / dR dR / d lambda_n` with `d proj / dR = (z / d)(1 - R (1 - phi') / d)`
//! (`z / |z|` when sliding, 0 when sticking) and `dR / d lambda_n = -mu_c [lambda_n < 0]`.
//!
//! Two independent one-dimensional laws (a square instead of the disk) dissipate the wrong
//! energy on a turning slip: on a circle of radius `r`, `8 mu N r` per cycle instead of
//! `2 pi mu N r`.

use super::{smoothed_max, smoothed_max_mu_derivative, smoothed_max_slope};
use super::{ContactLaw, Coulomb, LawSamples, Measure};
use crate::model::NormalForce;

/// Coulomb friction on two tangential rows (module documentation): `proj` onto the disk of
/// radius `mu_c N`.
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionDisk {
    /// The one-dimensional law with the same slip limit: the disk's radius.
    limit: Coulomb,
}

/// One sample of the disk law: the argument, its norm, the radius, `d` and `phi'`, `dphi/dmu`.
struct DiskSample {
    z: [f64; 2],
    norm: f64,
    radius: f64,
    denominator: f64,
    slope: f64,
    mu_derivative: f64,
}

impl FrictionDisk {
    /// The disk law with coefficient `mu_c` under `normal`: a prescribed load, or the force
    /// of row `p` (read: `N = max(0, -lambda_p)`), the index in the model's rows of `G`.
    pub fn new(coefficient: f64, normal: NormalForce) -> Self {
        Self {
            limit: Coulomb::new(coefficient, normal),
        }
    }

    fn sample(&self, at: &LawSamples<'_>, n: usize) -> DiskSample {
        let z = [at.z[n], at.z[at.samples + n]];
        let norm = z[0].hypot(z[1]);
        let radius = self.limit.bound(at.read, n);
        let mu = at.smoothing;
        let (excess, slope, mu_derivative) = if mu == 0.0 {
            let slope = if norm > radius { 1.0 } else { 0.0 };
            ((norm - radius).max(0.0), slope, 0.0)
        } else {
            (
                smoothed_max(norm - radius, mu),
                smoothed_max_slope(norm - radius, mu),
                smoothed_max_mu_derivative(norm - radius, mu),
            )
        };
        DiskSample {
            z,
            norm,
            radius,
            denominator: radius + excess,
            slope,
            mu_derivative,
        }
    }
}

/// The radial projection `R z / d` of one sample (0 on a disk of radius 0 at `z = 0`).
fn projected(s: &DiskSample) -> [f64; 2] {
    if s.denominator > 0.0 {
        let scale = s.radius / s.denominator;
        [scale * s.z[0], scale * s.z[1]]
    } else {
        [0.0; 2]
    }
}

impl ContactLaw for FrictionDisk {
    fn rows(&self) -> usize {
        2
    }

    fn measure(&self) -> Measure {
        Measure::Velocity
    }

    fn reads(&self) -> &[usize] {
        self.limit.reads()
    }

    fn project(&self, at: &LawSamples<'_>, out: &mut [f64]) {
        let nt = at.samples;
        for n in 0..nt {
            let p = projected(&self.sample(at, n));
            out[n] = p[0];
            out[nt + n] = p[1];
        }
    }

    /// The 2 x 2 block on `z` and, on a contact's force, the column
    /// `-mu_c [lambda_n < 0] d proj / dR` (module documentation).
    fn jacobian(&self, at: &LawSamples<'_>, dz: &mut [f64], dread: &mut [f64]) {
        let nt = at.samples;
        let on_contact = matches!(self.limit.normal, NormalForce::Contact(_));
        for n in 0..nt {
            let s = self.sample(at, n);
            if s.denominator <= 0.0 {
                dz[n..]
                    .iter_mut()
                    .step_by(nt)
                    .take(4)
                    .for_each(|d| *d = 0.0);
                if on_contact {
                    dread[n] = 0.0;
                    dread[nt + n] = 0.0;
                }
                continue;
            }
            let scale = s.radius / s.denominator;
            let radial = if s.norm > 0.0 {
                s.slope / (s.denominator * s.norm)
            } else {
                0.0
            };
            for a in 0..2 {
                for b in 0..2 {
                    let identity = if a == b { 1.0 } else { 0.0 };
                    dz[(2 * a + b) * nt + n] = scale * (identity - radial * s.z[a] * s.z[b]);
                }
            }
            if on_contact {
                let closed = if at.read[n] < 0.0 { 1.0 } else { 0.0 };
                let shrink = 1.0 - s.radius * (1.0 - s.slope) / s.denominator;
                for a in 0..2 {
                    dread[a * nt + n] =
                        -(self.limit.coefficient * closed * shrink * s.z[a] / s.denominator);
                }
            }
        }
    }

    /// `d (R z / d) / d mu = -R z phi_mu_mu / d^2`.
    fn smoothing_derivative(&self, at: &LawSamples<'_>, out: &mut [f64]) {
        let nt = at.samples;
        for n in 0..nt {
            let s = self.sample(at, n);
            let scale = if s.denominator > 0.0 {
                -s.radius * s.mu_derivative / (s.denominator * s.denominator)
            } else {
                0.0
            };
            out[n] = scale * s.z[0];
            out[nt + n] = scale * s.z[1];
        }
    }

    fn force_scale(&self) -> f64 {
        self.limit.force_scale()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Evaluates the law on one sample.
    fn eval(law: &FrictionDisk, z: [f64; 2], read: f64, mu: f64) -> ([f64; 2], [f64; 4], [f64; 2]) {
        let reads = [read];
        let at = LawSamples {
            z: &z,
            read: if law.reads().is_empty() { &[] } else { &reads },
            samples: 1,
            smoothing: mu,
        };
        let (mut value, mut dz, mut dread) = ([0.0; 2], [0.0; 4], [0.0; 2]);
        law.project(&at, &mut value);
        law.jacobian(&at, &mut dz, &mut dread);
        (value, dz, dread)
    }

    /// The projection is radial onto the disk of radius `mu N`, the disk shrinks to a
    /// point when the contact opens, and the reported Jacobian (on `z`, on `lambda_n`)
    /// matches central differences where the law is differentiable (exact and smoothed:
    /// a step of 1e-6 on O(1) values leaves differences within 1e-7).
    #[test]
    fn the_disk_projection_is_radial_and_has_the_jacobian_it_reports() {
        let law = FrictionDisk::new(0.5, NormalForce::Contact(0));
        // Radius 0.5 * 2 = 1: inside stays, outside is scaled onto the circle.
        assert_eq!(eval(&law, [0.3, -0.4], -2.0, 0.0).0, [0.3, -0.4]);
        let (value, _, _) = eval(&law, [3.0, 4.0], -2.0, 0.0);
        assert!((value[0] - 0.6).abs() < 1e-15 && (value[1] - 0.8).abs() < 1e-15);
        // Liftoff: lambda_n >= 0 gives no force and no slope.
        assert_eq!(
            eval(&law, [3.0, 4.0], 0.5, 0.0),
            ([0.0; 2], [0.0; 4], [0.0; 2])
        );
        assert_eq!(eval(&law, [0.0, 0.0], 0.0, 0.0).0, [0.0; 2]);
        let h = 1e-6;
        for mu in [0.0, 0.05] {
            for (z, read) in [([0.3, -0.4], -2.0), ([3.0, 4.0], -2.0), ([-1.5, 0.2], -1.0)] {
                let (_, dz, dread) = eval(&law, z, read, mu);
                for b in 0..2 {
                    let (mut zp, mut zm) = (z, z);
                    zp[b] += h;
                    zm[b] -= h;
                    let (p, _, _) = eval(&law, zp, read, mu);
                    let (m, _, _) = eval(&law, zm, read, mu);
                    for a in 0..2 {
                        let fd = (p[a] - m[a]) / (2.0 * h);
                        assert!((dz[2 * a + b] - fd).abs() < 1e-7, "dz[{a}{b}] at {z:?}");
                    }
                }
                let (p, _, _) = eval(&law, z, read + h, mu);
                let (m, _, _) = eval(&law, z, read - h, mu);
                for a in 0..2 {
                    let fd = (p[a] - m[a]) / (2.0 * h);
                    assert!((dread[a] - fd).abs() < 1e-7, "dread[{a}] at {z:?}");
                }
            }
        }
        // The mu-derivative against a central difference.
        let (z, mu) = ([0.9f64, 0.5], 0.05);
        let at = |mu| LawSamples {
            z: &z,
            read: &[-2.0],
            samples: 1,
            smoothing: mu,
        };
        let mut derivative = [0.0; 2];
        law.smoothing_derivative(&at(mu), &mut derivative);
        let (mut p, mut m) = ([0.0; 2], [0.0; 2]);
        law.project(&at(mu + h), &mut p);
        law.project(&at(mu - h), &mut m);
        for a in 0..2 {
            assert!((derivative[a] - (p[a] - m[a]) / (2.0 * h)).abs() < 1e-7);
        }
    }
}
