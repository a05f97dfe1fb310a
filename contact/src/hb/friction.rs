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
//! contact. Smoothed (`mu_s > 0`), each `max` is `phi_mu`. The law itself is
//! [`crate::law::Coulomb`], sampled like every row group's law (`super::laws`); this module
//! reconstructs a friction point's period for its report.
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

use super::ssn::SsnHb;
use super::{HbError, LinearData};
use crate::contacts::FrictionReport;
use crate::model::NormalForce;

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
        let i = lin.friction_row(f);
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
        let i = lin.friction_row(f);
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
