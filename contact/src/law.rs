//! Contact laws as typed groups of rows of `G`.
//!
//! A contact is a group of `k` rows of `G` with its law. Every law is written as a
//! Lipschitz projection per time sample (Alart–Curnier's augmented Lagrangian): with the
//! rows' forces `lambda_a` and what they measure `y_a` (a displacement `g_a . u`, or a slip
//! velocity per radian `d (g_a . u) / d(w t)`), the argument
//!
//! `z_a = lambda_a - c (y_a - o_a)` (`o_a` the row's offset: a contact's gap, 0 for a slip),
//!
//! and the law's equation `lambda - proj(z; r) = 0`, where `r` are the force samples of the
//! rows of other groups the law reads (the normal force of a Coulomb point). A law gives,
//! per sample, the value of `proj`, an element of its generalized Jacobian (a `k x k`
//! block on `z` and a `k x |r|` block on `r`) and the derivative of its smoothed form with
//! respect to the smoothing `mu` (`mu = 0`: the law itself). Harmonic balance samples the
//! arguments through the AFT, applies the law and projects back; the contact Jacobian is
//! then block diagonal by group (`Q_ab = P diag(d proj_a / d z_b) E`), plus the blocks on
//! the rows read.
//!
//! - [`Unilateral`]: `proj(z) = min(0, z)` (`lambda <= 0`, `y - o <= 0`, complementary);
//!   smoothed `-phi_mu(-z)` with `phi_mu(s) = (s + sqrt(s^2 + 4 mu^2)) / 2`.
//! - [`Coulomb`]: `proj(z) = clamp(z, -b, b)`, `b = mu_c N` with `N` prescribed or
//!   `N = max(0, -lambda_n)` of the contact read; smoothed by `phi_mu` in each of its two
//!   `max` terms.
//!
//! - [`FrictionDisk`]: Coulomb friction on two tangential rows, the radial projection onto
//!   the disk of radius `mu_c N` (a 3-D frictional contact's tangent plane).
//!
//! A law coupling several rows is one more type implementing [`ContactLaw`], attached to a
//! model's rows by a [`LawGroup`].
//!
//! Reference: P. Alart, A. Curnier, CMAME 92 (1991) 353–375.

use std::sync::Arc;

use crate::model::{ContactRow, NormalForce};

mod disk;

pub use disk::FrictionDisk;

/// What the rows of a group measure (the `y` of the law's argument).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Measure {
    /// The displacement `g . u` of the row (a gap closure).
    Displacement,
    /// The slip velocity per radian of the forcing, `d (g . u) / d(w t)`.
    Velocity,
}

/// The samples a law is evaluated at: `samples` times per row, row-major.
#[derive(Debug, Clone, Copy)]
pub struct LawSamples<'a> {
    /// The arguments `z_a(t_n)` of the group's own rows, at `a * samples + n`.
    pub z: &'a [f64],
    /// The forces `r_s(t_n)` of the rows it reads, at `s * samples + n`.
    pub read: &'a [f64],
    /// Samples per row.
    pub samples: usize,
    /// The smoothing `mu >= 0` (0: the law itself).
    pub smoothing: f64,
}

/// The law of a group of rows of `G`, evaluated per time sample (module documentation).
///
/// Every method writes `samples` values per row, row-major: `out[a * samples + n]`;
/// [`ContactLaw::jacobian`] writes the block on the own rows at `(a k + b) samples + n`
/// and the block on the read rows at `(a |r| + s) samples + n`.
///
/// ```
/// use semismooth_contact::law::{ContactLaw, LawSamples, Measure, Unilateral};
///
/// let law = Unilateral;
/// let at = LawSamples { z: &[-2.0, 3.0], read: &[], samples: 2, smoothing: 0.0 };
/// let (mut value, mut dz) = ([0.0; 2], [0.0; 2]);
/// law.project(&at, &mut value);
/// law.jacobian(&at, &mut dz, &mut []);
/// assert_eq!((value, dz), ([-2.0, 0.0], [1.0, 0.0]));
/// assert_eq!(law.measure(), Measure::Displacement);
/// ```
pub trait ContactLaw: std::fmt::Debug + Send + Sync {
    /// Number `k >= 1` of rows of `G` the law owns.
    fn rows(&self) -> usize;

    /// What its rows measure.
    fn measure(&self) -> Measure;

    /// The rows of `G` (indices in the model's order) whose force samples it reads.
    fn reads(&self) -> &[usize] {
        &[]
    }

    /// `out = proj(z; r)`, smoothed by `at.smoothing`.
    fn project(&self, at: &LawSamples<'_>, out: &mut [f64]);

    /// An element of the generalized Jacobian of the (smoothed) projection: `dz` on the
    /// own rows' arguments, `dread` on the forces read.
    fn jacobian(&self, at: &LawSamples<'_>, dz: &mut [f64], dread: &mut [f64]);

    /// `d proj / d mu` of the smoothed projection.
    fn smoothing_derivative(&self, at: &LawSamples<'_>, out: &mut [f64]);

    /// A force scale at which the law switches independently of the motion (a prescribed
    /// slip limit; 0 when none): a scale of the polyalgorithm's smoothing path.
    fn force_scale(&self) -> f64 {
        0.0
    }

    /// The regularised form penalty formulations use: the force as a function of the
    /// measured samples alone, `force(y)` with `at.z` holding `(y - o) / w` in the units of
    /// the formulation's width `w` (the force is then per unit of its stiffness for a
    /// gap, absolute for a slip), and its slope `d force / d at.z`. False when the law has
    /// none (the default).
    fn regularised(&self, at: &LawSamples<'_>, force: &mut [f64], slope: &mut [f64]) -> bool {
        let _ = (at, force, slope);
        false
    }
}

/// A group of rows of `G` added to a model with its law: the rows (each over any dofs),
/// their offsets `o_a` (a gap for a displacement, 0 for a slip) and the law owning them.
/// Its rows follow the model's contacts' and friction points' rows.
#[derive(Debug, Clone)]
pub struct LawGroup {
    /// The rows the law owns (as many as [`ContactLaw::rows`]).
    pub rows: Vec<ContactRow>,
    /// The offset of each row in the law's argument `z = lambda - c (y - o)`.
    pub offsets: Vec<f64>,
    /// The law.
    pub law: Arc<dyn ContactLaw>,
}

/// `phi_mu(s) = (s + sqrt(s^2 + 4 mu^2)) / 2`, the Chen–Harker–Kanzow–Smale smoothing of
/// `max(0, s)` (`phi_0 = max(0, .)`, `0 < phi_mu(s) - max(0, s) <= mu`).
pub(crate) fn smoothed_max(s: f64, mu: f64) -> f64 {
    if mu == 0.0 {
        s.max(0.0)
    } else {
        0.5 * (s + s.hypot(2.0 * mu))
    }
}

/// `phi_mu'(s) = (1 + s / sqrt(s^2 + 4 mu^2)) / 2`, in `(0, 1)` for `mu > 0`.
pub(crate) fn smoothed_max_slope(s: f64, mu: f64) -> f64 {
    0.5 * (1.0 + s / s.hypot(2.0 * mu))
}

/// `d phi_mu(s) / d mu = 2 mu / sqrt(s^2 + 4 mu^2)`.
pub(crate) fn smoothed_max_mu_derivative(s: f64, mu: f64) -> f64 {
    2.0 * mu / s.hypot(2.0 * mu)
}

/// Unilateral contact on one row: `proj(z) = min(0, z) = -max(0, -z)`, the force
/// `lambda <= 0` where the gap closes (`y = o`) and zero where it is open.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Unilateral;

impl ContactLaw for Unilateral {
    fn rows(&self) -> usize {
        1
    }

    fn measure(&self) -> Measure {
        Measure::Displacement
    }

    fn project(&self, at: &LawSamples<'_>, out: &mut [f64]) {
        let mu = at.smoothing;
        for (o, z) in out.iter_mut().zip(at.z) {
            *o = -smoothed_max(-z, mu);
        }
    }

    /// `d proj / dz = [z < 0]` (`phi_mu'(-z)` when smoothed).
    fn jacobian(&self, at: &LawSamples<'_>, dz: &mut [f64], _dread: &mut [f64]) {
        let mu = at.smoothing;
        for (d, z) in dz.iter_mut().zip(at.z) {
            let s = -z;
            *d = if mu > 0.0 {
                smoothed_max_slope(s, mu)
            } else if s > 0.0 {
                1.0
            } else {
                0.0
            };
        }
    }

    fn smoothing_derivative(&self, at: &LawSamples<'_>, out: &mut [f64]) {
        let mu = at.smoothing;
        for (o, z) in out.iter_mut().zip(at.z) {
            *o = -smoothed_max_mu_derivative(-z, mu);
        }
    }

    /// The penalty spring: `force = -max(0, y)`, slope `-[y > 0]`.
    fn regularised(&self, at: &LawSamples<'_>, force: &mut [f64], slope: &mut [f64]) -> bool {
        for ((f, d), y) in force.iter_mut().zip(slope.iter_mut()).zip(at.z) {
            *f = -y.max(0.0);
            *d = if *y > 0.0 { -1.0 } else { 0.0 };
        }
        true
    }
}

/// Coulomb friction on one tangential row: `proj(z) = clamp(z, -b, b)` with the slip limit
/// `b = mu_c N` (velocity form: stick `|z| < b` gives `y = 0`, slip `lambda = b sign(z)`).
#[derive(Debug, Clone, PartialEq)]
pub struct Coulomb {
    coefficient: f64,
    normal: NormalForce,
    reads: Vec<usize>,
}

impl Coulomb {
    /// Coulomb's law with coefficient `mu_c` under `normal`: a prescribed load, or the
    /// force of the contact on row `p` (read: `N = max(0, -lambda_p)`).
    pub fn new(coefficient: f64, normal: NormalForce) -> Self {
        let reads = match normal {
            NormalForce::Contact(p) => vec![p],
            NormalForce::Prescribed(_) => Vec::new(),
        };
        Self {
            coefficient,
            normal,
            reads,
        }
    }

    /// The slip limit `b_n` of sample `n` from the forces read.
    #[inline]
    fn bound(&self, read: &[f64], n: usize) -> f64 {
        match self.normal {
            NormalForce::Prescribed(load) => self.coefficient * load,
            NormalForce::Contact(_) => self.coefficient * (-read[n]).max(0.0),
        }
    }
}

impl ContactLaw for Coulomb {
    fn rows(&self) -> usize {
        1
    }

    fn measure(&self) -> Measure {
        Measure::Velocity
    }

    fn reads(&self) -> &[usize] {
        &self.reads
    }

    fn project(&self, at: &LawSamples<'_>, out: &mut [f64]) {
        for (n, (o, z)) in out.iter_mut().zip(at.z).enumerate() {
            *o = coulomb_projection(*z, self.bound(at.read, n), at.smoothing);
        }
    }

    /// `d proj / dz = 1 - w+ - w-` and, on a contact's force `lambda_n`,
    /// `d proj / d lambda_n = -mu_c [lambda_n < 0] (w+ - w-)` ([`coulomb_slopes`]).
    fn jacobian(&self, at: &LawSamples<'_>, dz: &mut [f64], dread: &mut [f64]) {
        let on_contact = matches!(self.normal, NormalForce::Contact(_));
        for (n, (d, z)) in dz.iter_mut().zip(at.z).enumerate() {
            let (plus, minus) = coulomb_slopes(*z, self.bound(at.read, n), at.smoothing);
            *d = 1.0 - plus - minus;
            if on_contact {
                dread[n] = if at.read[n] < 0.0 {
                    -(self.coefficient * (plus - minus))
                } else {
                    0.0
                };
            }
        }
    }

    fn smoothing_derivative(&self, at: &LawSamples<'_>, out: &mut [f64]) {
        let mu = at.smoothing;
        for (n, (o, z)) in out.iter_mut().zip(at.z).enumerate() {
            let b = self.bound(at.read, n);
            *o = -smoothed_max_mu_derivative(z - b, mu) + smoothed_max_mu_derivative(-z - b, mu);
        }
    }

    fn force_scale(&self) -> f64 {
        match self.normal {
            NormalForce::Prescribed(load) => self.coefficient * load,
            NormalForce::Contact(_) => 0.0,
        }
    }

    /// NLvib's regularised Coulomb law under a prescribed load: `force = -b tanh(y)`,
    /// slope `-b sech^2(y)` (none on a contact's normal force).
    fn regularised(&self, at: &LawSamples<'_>, force: &mut [f64], slope: &mut [f64]) -> bool {
        let NormalForce::Prescribed(_) = self.normal else {
            return false;
        };
        let b = self.force_scale();
        for ((f, d), y) in force.iter_mut().zip(slope.iter_mut()).zip(at.z) {
            let sech = 1.0 / y.cosh();
            *f = -(b * y.tanh());
            *d = -(b * sech * sech);
        }
        true
    }
}

/// Coulomb's projection `proj_[-b, b](z)` as `z - phi_mu(z - b) + phi_mu(-z - b)` (the
/// exact clamp at `mu = 0`).
pub fn coulomb_projection(z: f64, b: f64, mu: f64) -> f64 {
    z - smoothed_max(z - b, mu) + smoothed_max(-z - b, mu)
}

/// The slopes `(w+, w-)` of the two `max` terms of [`coulomb_projection`] (at `mu = 0`
/// the indicators of `z >= b` and `z <= -b` outside the open interval `|z| < b`):
/// `d proj / dz = 1 - w+ - w-`, `d proj / db = w+ - w-`.
pub fn coulomb_slopes(z: f64, b: f64, mu: f64) -> (f64, f64) {
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
            assert_eq!(coulomb_projection(z, b, 0.0), exact);
            let (plus, minus) = coulomb_slopes(z, b, 0.0);
            let slope = if z.abs() < b { 1.0 } else { 0.0 };
            assert_eq!(1.0 - plus - minus, slope, "z = {z}, b = {b}");
            for mu in [1e-2, 1e-4] {
                // |phi_mu - max| <= mu for each of the two terms.
                assert!((coulomb_projection(z, b, mu) - exact).abs() <= 2.0 * mu);
                let (p, q) = coulomb_slopes(z, b, mu);
                assert!((0.0..=1.0).contains(&(1.0 - p - q)));
            }
        }
        // The mu-derivative against a central difference.
        let law = Coulomb::new(1.0, NormalForce::Prescribed(1.0));
        let (z, mu, d) = ([0.9], 0.05, 1e-6);
        let at = |mu| LawSamples {
            z: &z,
            read: &[],
            samples: 1,
            smoothing: mu,
        };
        let value = |mu| {
            let mut out = [0.0];
            law.project(&at(mu), &mut out);
            out[0]
        };
        let mut derivative = [0.0];
        law.smoothing_derivative(&at(mu), &mut derivative);
        let fd = (value(mu + d) - value(mu - d)) / (2.0 * d);
        assert!((derivative[0] - fd).abs() < 1e-8);
    }

    /// The unilateral law's smoothed value, slope and mu-derivative against central
    /// differences (the smoothed form is smooth: differences agree to 1e-8).
    #[test]
    fn the_smoothed_unilateral_law_has_the_derivatives_it_reports() {
        let law = Unilateral;
        let (mu, d) = (0.1, 1e-6);
        for z in [-0.7, -0.05, 0.0, 0.2, 1.5] {
            let value = |z: f64, mu: f64| {
                let mut out = [0.0];
                let at = LawSamples {
                    z: &[z],
                    read: &[],
                    samples: 1,
                    smoothing: mu,
                };
                law.project(&at, &mut out);
                out[0]
            };
            let at = LawSamples {
                z: &[z],
                read: &[],
                samples: 1,
                smoothing: mu,
            };
            let (mut dz, mut dmu) = ([0.0], [0.0]);
            law.jacobian(&at, &mut dz, &mut []);
            law.smoothing_derivative(&at, &mut dmu);
            let fd_z = (value(z + d, mu) - value(z - d, mu)) / (2.0 * d);
            let fd_mu = (value(z, mu + d) - value(z, mu - d)) / (2.0 * d);
            assert!((dz[0] - fd_z).abs() < 1e-8, "z = {z}");
            assert!((dmu[0] - fd_mu).abs() < 1e-8, "z = {z}");
            assert_eq!(value(z, 0.0), z.min(0.0));
        }
    }
}
