//! Coulomb friction in SSN-HB: the tangential law as a Lipschitz equation sampled in the
//! AFT like the normal one.
//!
//! For a friction point with tangential row `g_t`, force `lambda_t` and slip limit
//! `b = mu N` (`N` prescribed, or `N = max(0, -lambda_n)` of its contact), Coulomb's law
//! (`|lambda_t| <= b`; `lambda_t = -b sign(v_t)` when it slips, `v_t = 0` when it sticks) is,
//! for any `c > 0`, the projection equation of the augmented Lagrangian (Alart–Curnier)
//!
//! `lambda_t - proj_[-b, b](lambda_t - c y_t) = 0`,
//!
//! in *velocity form* with `y_t = d (g_t . u) / d(w t) = v_t / w` (the slip velocity per
//! radian of the forcing: the same `c` as the normal law converts it into a force, and the
//! residual depends on `w` only through the dynamic blocks). Stick: `|z| < b` with
//! `z = lambda_t - c y_t` gives `y_t = 0`; slip: `lambda_t = b sign(z)` on the boundary,
//! opposing `y_t`. Its Galerkin projection with `Nt` samples is
//!
//! `R_t = Lambda_t - P proj_[-b_n, b_n](E Lambda_t - c D E G_t U)`, with
//! `proj_[-b, b](z) = z - max(0, z - b) + max(0, -z - b)`.
//!
//! Generalized Jacobian, with `h+ = [z - b > 0]`, `h- = [-z - b > 0]`, `stick = 1 - h+ - h-`:
//! `dR_t/dLambda_t = I - P diag(stick) E`, `dR_t/dU = c P diag(stick) E D G_t` (`D` the
//! phase derivative, with the mean-slip anchor `delta` on the constant: a point stuck all
//! period is otherwise free to carry any constant force), and on a
//! contact's force `dR_t/dLambda_n = P diag(mu [lambda_n < 0] (h+ - h-)) E`: the same
//! structure as the normal law (a `Q` block per row, the row measuring `D G_t u` instead of
//! `G u`), so the structured solve, its condensation onto the contact unknowns, the
//! polyalgorithm and continuation carry over with one more block per friction point on a
//! contact. Smoothed (`mu_s > 0`), each `max` is `phi_mu` of [`super::ssn`].
//!
//! The dynamic Lagrangian of Nacivet et al. (2003) is the fixed-point iteration
//! `lambda = proj(lambda_lin - c (v - v_lin))` on the same projection; the displacement
//! form (`u_t - w_slider` with an internal slider state) needs one more unknown per point;
//! De Saxcé's bipotential gives the same projection for a one-dimensional tangent.
//!
//! References: P. Alart, A. Curnier, CMAME 92 (1991) 353–375; S. Nacivet, C. Pierre,
//! F. Thouverez, L. Jézéquel, J. Sound Vib. 265 (2003) 201–219; J. P. Den Hartog, Trans.
//! ASME 53 (1931) 107–115 (the exact single-dof solution in continuous sliding).

use semismooth::harmonic::{Aft, FourierBasis};

use super::ssn::{smoothed_max, smoothed_max_mu_derivative, smoothed_max_slope, SsnHb};
use super::{HbError, LinearData};
use crate::contacts::FrictionReport;
use crate::model::NormalForce;

/// `proj_[-b, b](z)` as `z - phi_mu(z - b) + phi_mu(-z - b)` (exact clamp at `mu = 0`).
pub(crate) fn projection(z: f64, b: f64, mu: f64) -> f64 {
    z - smoothed_max(z - b, mu) + smoothed_max(-z - b, mu)
}

/// The slopes `(w+, w-)` of the two `max` terms of [`projection`] (at `mu = 0` the
/// indicators of `z >= b` and `z <= -b` outside the open interval `|z| < b`):
/// `d proj / dz = 1 - w+ - w-`,
/// `d proj / db = w+ - w-`.
pub(crate) fn projection_slopes(z: f64, b: f64, mu: f64) -> (f64, f64) {
    if mu == 0.0 {
        // Strictly inside the interval: stick; else the side of the boundary reached (on
        // an interval of zero width, b = 0, every z is on it: slope 0).
        match (z.abs() < b, z >= 0.0) {
            (true, _) => (0.0, 0.0),
            (false, true) => (1.0, 0.0),
            (false, false) => (0.0, 1.0),
        }
    } else {
        (
            smoothed_max_slope(z - b, mu),
            smoothed_max_slope(-z - b, mu),
        )
    }
}

/// `d proj / d mu`.
pub(crate) fn projection_mu_derivative(z: f64, b: f64, mu: f64) -> f64 {
    -smoothed_max_mu_derivative(z - b, mu) + smoothed_max_mu_derivative(-z - b, mu)
}

/// Sample buffers of the friction law (`Nt` each).
#[derive(Debug, Clone, Default)]
pub(crate) struct FrictionSamples {
    /// Slip limits `b_n`.
    bound: Vec<f64>,
    /// The contact's normal force `lambda_n(t_n)` (contact normals only).
    normal: Vec<f64>,
}

impl FrictionSamples {
    pub(crate) fn new(time_samples: usize) -> Self {
        Self {
            bound: vec![0.0; time_samples],
            normal: vec![0.0; time_samples],
        }
    }
}

/// Samples of friction point `f` (row `i = m_n + f`) into `aft`'s samples,
/// `z_n = lambda_t - c y_t`, and its slip limits `b_n` (and the normal force on a contact)
/// into `samples`; `forces` are the rows' force coefficients (index `j m + i`) and
/// `measured(j)` the coefficient `j` of the row's measured slip `y_t`
/// ([`LinearData::gather_measured`]).
pub(crate) fn point_samples(
    aft: &mut Aft,
    lin: &LinearData,
    f: usize,
    c: f64,
    forces: &[f64],
    measured: impl Fn(usize) -> f64,
    samples: &mut FrictionSamples,
) {
    let m = lin.contacts();
    let i = lin.normal_rows() + f;
    let (mu, normal) = lin.friction[f];
    match normal {
        NormalForce::Prescribed(load) => samples.bound.fill(mu * load),
        NormalForce::Contact(p) => {
            for (j, coeff) in aft.coefficients_mut().iter_mut().enumerate() {
                *coeff = forces[j * m + p];
            }
            aft.coefficients_to_samples();
            samples.normal.copy_from_slice(aft.samples());
            for (b, l) in samples.bound.iter_mut().zip(&samples.normal) {
                *b = mu * (-l).max(0.0);
            }
        }
    }
    for (j, coeff) in aft.coefficients_mut().iter_mut().enumerate() {
        *coeff = forces[j * m + i] - c * measured(j);
    }
    aft.coefficients_to_samples();
}

/// `R_t = Lambda_t - P proj(z)` of friction point `f` into `out` (index `j m + i`), from
/// its samples `z_n` in `aft` ([`point_samples`]) and the smoothing `mu_s`.
pub(crate) fn point_residual(
    aft: &mut Aft,
    lin: &LinearData,
    f: usize,
    forces: &[f64],
    samples: &FrictionSamples,
    mu_s: f64,
    out: &mut [f64],
) {
    let (m, i) = (lin.contacts(), lin.normal_rows() + f);
    for (z, b) in aft.samples_mut().iter_mut().zip(&samples.bound) {
        *z = projection(*z, *b, mu_s);
    }
    aft.samples_to_coefficients();
    for (j, p) in aft.coefficients().iter().enumerate() {
        out[j * m + i] = forces[j * m + i] - p;
    }
}

/// Turns friction point `f`'s samples `z_n` in `aft` into its stick weights
/// `1 - w+ - w-` (then `Q = P diag(stick) E`) and `samples.normal` into the weights
/// `mu [lambda_n < 0] (w+ - w-)` of its block `X` on its contact's force (zero under a
/// prescribed load); true when the point has a contact (a block `X`).
pub(crate) fn point_jacobian_weights(
    aft: &mut Aft,
    lin: &LinearData,
    f: usize,
    samples: &mut FrictionSamples,
    mu_s: f64,
) -> bool {
    let (coefficient, normal) = lin.friction[f];
    let on_contact = matches!(normal, NormalForce::Contact(_));
    for ((z, b), l) in aft
        .samples_mut()
        .iter_mut()
        .zip(&samples.bound)
        .zip(samples.normal.iter_mut())
    {
        let (plus, minus) = projection_slopes(*z, *b, mu_s);
        *z = 1.0 - plus - minus;
        *l = if on_contact && *l < 0.0 {
            coefficient * (plus - minus)
        } else {
            0.0
        };
    }
    on_contact
}

impl FrictionSamples {
    /// The weights of the block `X` left by [`point_jacobian_weights`].
    pub(crate) fn cross_weights(&self) -> &[f64] {
        &self.normal
    }

    /// The slip limits `b_n` left by [`point_samples`].
    pub(crate) fn bounds(&self) -> &[f64] {
        &self.bound
    }
}

impl SsnHb {
    /// [`point_samples`] of friction point `f` from the full unknowns `x = [U; Lambda]`.
    fn friction_samples(&mut self, x: &[f64], f: usize, samples: &mut FrictionSamples) {
        let lin = self.state.linear.clone();
        let offset = lin.dofs * lin.size();
        let i = lin.normal_rows() + f;
        let (u, forces) = x.split_at(offset);
        let c = self.c();
        point_samples(
            &mut self.state.aft,
            &lin,
            f,
            c,
            forces,
            |j| lin.measured_coefficient(i, u, j),
            samples,
        );
    }

    /// `out_l[j m + i] = Lambda_t - P proj(z)` for every friction point (rows after the
    /// contacts; `out_l` the force equations).
    pub(super) fn friction_residual(&mut self, x: &[f64], out_l: &mut [f64]) {
        let offset = self.state.linear.dofs * self.state.linear.size();
        self.project_friction_samples(x, out_l, projection, |index, p| x[offset + index] - p);
    }

    /// For every friction point `f` (row `i`): its samples `z_n` mapped by `law(z_n, b_n,
    /// mu_s)`, projected on the harmonics, and `out_l[j m + i] = equation(j m + i, P_j)`.
    fn project_friction_samples(
        &mut self,
        x: &[f64],
        out_l: &mut [f64],
        law: fn(f64, f64, f64) -> f64,
        equation: impl Fn(usize, f64) -> f64,
    ) {
        let lin = self.state.linear.clone();
        let m = lin.contacts();
        let mut samples = std::mem::take(&mut self.friction);
        let mu = self.smoothing();
        for f in 0..lin.friction.len() {
            let i = lin.normal_rows() + f;
            self.friction_samples(x, f, &mut samples);
            for (z, b) in self.state.aft.samples_mut().iter_mut().zip(&samples.bound) {
                *z = law(*z, *b, mu);
            }
            self.state.aft.samples_to_coefficients();
            for (j, p) in self.state.aft.coefficients().iter().enumerate() {
                out_l[j * m + i] = equation(j * m + i, *p);
            }
        }
        self.friction = samples;
    }

    /// Writes each friction point's `Q = P diag(stick) E` and, on a contact,
    /// `X = P diag(mu [lambda_n < 0] (w+ - w-)) E` into `jac`.
    pub(super) fn friction_jacobian(&mut self, x: &[f64], jac: &mut super::HbJacobian) {
        let lin = self.state.linear.clone();
        let mut samples = std::mem::take(&mut self.friction);
        let mu = self.smoothing();
        for f in 0..lin.friction.len() {
            let i = lin.normal_rows() + f;
            self.friction_samples(x, f, &mut samples);
            let on_contact = point_jacobian_weights(&mut self.state.aft, &lin, f, &mut samples, mu);
            self.state.write_weighted_contact_block(jac, i);
            if on_contact {
                self.state
                    .aft
                    .samples_mut()
                    .copy_from_slice(samples.cross_weights());
                self.state
                    .aft
                    .samples_multiplication_matrix(&mut jac.cross[f]);
            }
        }
        self.friction = samples;
    }

    /// `dR_t / d mu_s = -P d proj / d mu` of every friction point into `out_l`.
    pub(super) fn friction_smoothing_derivative(&mut self, x: &[f64], out_l: &mut [f64]) {
        self.project_friction_samples(x, out_l, projection_mu_derivative, |_, p| -p);
    }

    /// The largest slip limit under a prescribed normal load (0 without one): a force
    /// scale of the friction law for the smoothing path.
    pub(super) fn largest_prescribed_slip_limit(&self) -> f64 {
        self.state
            .linear
            .friction
            .iter()
            .map(|&(mu, normal)| match normal {
                NormalForce::Prescribed(load) => mu * load,
                NormalForce::Contact(_) => 0.0,
            })
            .fold(0.0, f64::max)
    }
}

/// The samples of friction point `f` on `points` equally spaced times from its
/// coefficients: the law's argument `z = lambda_t - c y_t`, the slip velocity
/// `v_t = w d (g_t . u) / d(w t)` (no mean-slip anchor) and the slip limit `b`.
pub(crate) struct FrictionPeriod {
    pub(crate) argument: Vec<f64>,
    pub(crate) slip_velocity: Vec<f64>,
    pub(crate) slip_limit: Vec<f64>,
}

impl FrictionPeriod {
    /// From friction point `f`'s force coefficients `force(j)` (`None`: the argument is
    /// the slip velocity alone), the displacement coefficients `u`, its contact's normal
    /// force coefficients `normal(j, p)` (used on a contact), `c` and `omega`.
    pub(crate) fn reconstruct(
        lin: &LinearData,
        (u, omega, c): (&[f64], f64, f64),
        f: usize,
        force: Option<&dyn Fn(usize) -> f64>,
        normal: &dyn Fn(usize, usize) -> f64,
        points: usize,
    ) -> Result<Self, HbError> {
        if f >= lin.friction.len() {
            return Err(HbError::IndexOutOfRange {
                what: "friction point",
                index: f,
                count: lin.friction.len(),
            });
        }
        let i = lin.normal_rows() + f;
        let mut aft = Aft::new(FourierBasis::new(lin.basis.harmonics(), points)?);
        let size = lin.size();
        let mut sample = |coefficient: &dyn Fn(usize) -> f64| -> Result<Vec<f64>, HbError> {
            let coeffs: Vec<f64> = (0..size).map(coefficient).collect();
            let mut out = vec![0.0; points];
            aft.to_time(&coeffs, &mut out)?;
            Ok(out)
        };
        // The phase velocity y without the anchor on its constant.
        let phase_velocity = |j: usize| {
            if j == 0 {
                0.0
            } else {
                lin.measured_coefficient(i, u, j)
            }
        };
        let slip_velocity = sample(&|j| omega * phase_velocity(j))?;
        let argument = match force {
            Some(force) => sample(&|j| force(j) - c * lin.measured_coefficient(i, u, j))?,
            None => slip_velocity.clone(),
        };
        let (mu, normal_force) = lin.friction[f];
        let slip_limit = match normal_force {
            NormalForce::Prescribed(load) => vec![mu * load; points],
            NormalForce::Contact(p) => sample(&|j| normal(j, p))?
                .into_iter()
                .map(|l| mu * (-l).max(0.0))
                .collect(),
        };
        Ok(Self {
            argument,
            slip_velocity,
            slip_limit,
        })
    }
}

impl SsnHb {
    /// Friction point `f` over one period on `points` equally spaced times (`points > 2H`):
    /// the law's force `proj_[-b, b](lambda_t - c y_t)` of the truncated series (its
    /// Galerkin projection is `Lambda_t`; the series itself overshoots `b` like a square
    /// wave), the slip velocity, and sticking where `|lambda_t - c y_t| < b`.
    pub fn friction_report(
        &self,
        x: &[f64],
        f: usize,
        points: usize,
    ) -> Result<FrictionReport, HbError> {
        let u = self.displacement_coefficients(x)?;
        let lambda = self.force_coefficients(x)?;
        let lin = &self.state.linear;
        let m = lin.contacts();
        let i = lin.normal_rows() + f;
        let period = FrictionPeriod::reconstruct(
            lin,
            (u, self.state.omega, self.c()),
            f,
            Some(&|j| lambda[j * m + i]),
            &|j, p| lambda[j * m + p],
            points,
        )?;
        let force = period
            .argument
            .iter()
            .zip(&period.slip_limit)
            .map(|(z, b)| z.clamp(-b, *b))
            .collect();
        let stuck = period
            .argument
            .iter()
            .zip(&period.slip_limit)
            .map(|(z, b)| z.abs() < *b);
        Ok(FrictionReport::from_samples(
            f,
            force,
            period.slip_velocity,
            &period.slip_limit,
            stuck,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The projection is the clamp, its slopes the indicators of the two boundaries, and
    /// the smoothed forms converge to them as `mu -> 0` (within `mu`, as `phi_mu` does).
    #[test]
    fn the_projection_is_the_clamp_onto_the_friction_interval() {
        for (z, b) in [
            (0.3f64, 1.0f64),
            (2.0, 1.0),
            (-2.0, 1.0),
            (0.0, 0.0),
            (0.5, 0.0),
        ] {
            let exact = z.clamp(-b, b);
            assert_eq!(projection(z, b, 0.0), exact);
            let (plus, minus) = projection_slopes(z, b, 0.0);
            let slope = if z.abs() < b { 1.0 } else { 0.0 };
            assert_eq!(1.0 - plus - minus, slope, "z = {z}, b = {b}");
            for mu in [1e-2, 1e-4] {
                // |phi_mu - max| <= mu for each of the two terms.
                assert!((projection(z, b, mu) - exact).abs() <= 2.0 * mu);
                let (p, q) = projection_slopes(z, b, mu);
                assert!((0.0..=1.0).contains(&(1.0 - p - q)));
            }
        }
        // The mu-derivative against a central difference.
        let (z, b, mu, d) = (0.9, 1.0, 0.05, 1e-6);
        let fd = (projection(z, b, mu + d) - projection(z, b, mu - d)) / (2.0 * d);
        assert!((projection_mu_derivative(z, b, mu) - fd).abs() < 1e-8);
    }
}
