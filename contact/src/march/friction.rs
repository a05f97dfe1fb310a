//! The Moreau–Jean step with Coulomb friction: the impact law on the closed contacts and
//! Coulomb's law on every friction point, at velocity level, as one semismooth equation
//! solved by the core's Newton.
//!
//! With `Y = M_hat^{-1} G^T` over every row of `G` (contacts, then friction points),
//! `W = G Y` and the impulses `r = (-z, p)` (`z >= 0` the contacts' compressive impulses,
//! `p` the friction impulses), the rows' velocities after the step are
//! `s = G v_free + W r`. The unknowns `x = (z, p)` solve
//!
//! - closed contact `k`: `z_k - max(0, z_k - c w_k) = 0`, `w_k = -(s_k + e g_k . v_n)`
//!   (Newton's impact law: `w >= 0`, `z >= 0`, `w z = 0`); open contact: `z_k = 0`;
//! - friction point `f` on row `i`: `p_f - proj_[-b, b](p_f - c s_i) = 0` with the slip
//!   limit `b = mu h N` under a prescribed load `N`, or `b = mu max(0, z_p)` on contact
//!   `p` (Alart–Curnier's projection: stick `s_i = 0` with `|p_f| <= b`, or slip with
//!   `p_f = -b sign(s_i)`),
//!
//! - 3-D frictional contact with the normal row `n` (when unilateral: as a closed or open
//!   contact above) and the tangent rows `t = (t_1, t_2)`: `p_t - proj_D(p_t - c s_t) = 0`,
//!   `D` the disk of radius `b = mu max(0, z_n)` (or `mu h N` under a prescribed load), the
//!   projection of [`crate::law::FrictionDisk`] (stick `s_t = 0` inside the disk, or slip
//!   with `p_t = -b s_t / |s_t|` on its boundary): the normal Signorini law and Coulomb's
//!   disk solved together, exactly, per step;
//!
//! with `c = 1 / mean diag(W)` (an impulse per velocity, so both terms have one scale).
//! The clamp is Coulomb's projection of [`crate::law`] (the same law harmonic balance
//! samples); the generalized Jacobian is that of the max and the clamp; the step is solved from the
//! previous step's impulses, so a stick or slip phase that goes on costs one iteration.

use faer::Mat;
use semismooth::linalg::FaerDenseLu;
use semismooth::newton::{NewtonOptions, Tolerances};
use semismooth::{EvaluationError, GeneralizedJacobian, Residual};

use crate::law::{coulomb_projection, coulomb_slopes, ContactLaw, FrictionDisk, LawSamples};
use crate::model::{NormalForce, NormalLaw, StructuralModel};

/// Newton iterations allowed for one step's problem.
const STEP_MAX_ITERATIONS: usize = 100;
/// Tolerance on the step residual relative to the impulse scale.
const STEP_RELATIVE_TOLERANCE: f64 = 1e-12;

/// A 3-D frictional contact's rows in the step problem and its disk law (with the normal
/// force read from its normal row's impulse `-z_n`, or the prescribed impulse `h N`).
#[derive(Debug)]
struct DiskRows {
    /// The normal row, when unilateral.
    normal: Option<usize>,
    /// The first tangent row (the second follows it).
    tangent: usize,
    /// The friction coefficient `mu`.
    coefficient: f64,
    /// `h N` under a prescribed load `N` (0 on a unilateral contact).
    prescribed_impulse: f64,
    law: FrictionDisk,
}

/// One step's contact and friction problem (module documentation).
#[derive(Debug)]
pub(super) struct CoulombStep {
    /// `W = G M_hat^{-1} G^T` over every row (contacts, friction points, then the 3-D
    /// frictional contacts' rows).
    w: Mat<f64>,
    contacts: usize,
    /// `(mu, normal)` of each friction point.
    friction: Vec<(f64, NormalForce)>,
    /// Each 3-D frictional contact's rows and law.
    disks: Vec<DiskRows>,
    /// Whether each row is unilateral (a contact or a disk's normal row: `r = -z`).
    unilateral: Vec<bool>,
    h: f64,
    c: f64,
    /// `G v_free` of every row (relative to a moving obstacle).
    free: Vec<f64>,
    /// `e (g_k . v_n)` of every unilateral row (relative to a moving obstacle).
    restitution: Vec<f64>,
    /// Unilateral rows predicted closed.
    closed: Vec<bool>,
    /// Row velocities `s` at the last evaluated `x`.
    velocity: Vec<f64>,
    /// The impulses `x = (z, p)` of the last step (the next step's initial guess).
    pub(super) x: Vec<f64>,
    lu: FaerDenseLu,
}

/// Why a step's contact and friction problem was not solved: the Newton residual reached.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct UnsolvedStep {
    /// `|F|_2` at the end.
    pub residual: f64,
    /// The tolerance asked.
    pub tolerance: f64,
}

impl CoulombStep {
    /// The problem for `model` with `W` over its rows and step `h`.
    pub(super) fn new(model: &StructuralModel, w: Mat<f64>, h: f64) -> Self {
        let m = w.nrows();
        let mean_diagonal = (0..m).map(|i| w[(i, i)]).sum::<f64>() / m.max(1) as f64;
        let mut unilateral = vec![false; m];
        unilateral[..model.contact_count()].fill(true);
        let mut row = model.contact_count() + model.friction_count();
        let mut disks = Vec::new();
        for point in &model.frictional_contacts {
            let mu = point.coefficient;
            let (normal, prescribed_impulse) = match point.normal {
                NormalLaw::Unilateral { .. } => {
                    unilateral[row] = true;
                    row += 1;
                    (Some(row - 1), 0.0)
                }
                NormalLaw::Prescribed(load) => (None, h * load),
            };
            let law = match normal {
                Some(_) => FrictionDisk::new(mu, NormalForce::Contact(0)),
                None => FrictionDisk::new(mu, NormalForce::Prescribed(prescribed_impulse)),
            };
            disks.push(DiskRows {
                normal,
                tangent: row,
                coefficient: mu,
                prescribed_impulse,
                law,
            });
            row += 2;
        }
        Self {
            w,
            contacts: model.contact_count(),
            friction: model
                .friction
                .iter()
                .map(|f| (f.coefficient, f.normal))
                .collect(),
            disks,
            unilateral,
            h,
            c: 1.0 / mean_diagonal,
            free: vec![0.0; m],
            restitution: vec![0.0; m],
            closed: vec![false; m],
            velocity: vec![0.0; m],
            x: vec![0.0; m],
            lu: FaerDenseLu::new(),
        }
    }

    /// Row velocities `s = free + W r(x)`.
    fn row_velocities(&mut self, x: &[f64]) {
        let m = self.free.len();
        self.velocity.copy_from_slice(&self.free);
        for (j, xj) in x.iter().enumerate() {
            let r = if self.unilateral[j] { -xj } else { *xj };
            if r != 0.0 {
                for i in 0..m {
                    self.velocity[i] += self.w[(i, j)] * r;
                }
            }
        }
    }

    /// The slip limit `b` of friction point `f` at `x`, and `db / dz_p` with its contact.
    fn slip_limit(&self, f: usize, x: &[f64]) -> (f64, Option<(usize, f64)>) {
        let (mu, normal) = self.friction[f];
        match normal {
            NormalForce::Prescribed(load) => (mu * self.h * load, None),
            NormalForce::Contact(p) => {
                let slope = if x[p] > 0.0 { mu } else { 0.0 };
                (mu * x[p].max(0.0), Some((p, slope)))
            }
        }
    }

    /// The disk law's samples for contact `d` at `x`: the argument `p_t - c s_t` and the
    /// normal force read, `-z_n` (one sample).
    fn disk_argument(&self, d: usize, x: &[f64]) -> ([f64; 2], [f64; 1]) {
        let disk = &self.disks[d];
        let t = disk.tangent;
        let z = [
            x[t] - self.c * self.velocity[t],
            x[t + 1] - self.c * self.velocity[t + 1],
        ];
        (z, [disk.normal.map_or(0.0, |n| -x[n])])
    }

    /// The largest slip limit at `x`: `mu z_n` or `mu h N` over the friction points and the
    /// disks.
    fn largest_slip_limit(&self, x: &[f64]) -> f64 {
        let points = (0..self.friction.len()).map(|f| self.slip_limit(f, x).0);
        let disks = self.disks.iter().map(|disk| match disk.normal {
            Some(n) => disk.coefficient * x[n].max(0.0),
            None => disk.coefficient * disk.prescribed_impulse,
        });
        points.chain(disks).fold(0.0, f64::max)
    }

    /// Solves the step from the free velocities `free` (`G v_free`), the restitution terms
    /// and the closed unilateral rows (each indexed by row); the impulses are in
    /// [`CoulombStep::x`].
    pub(super) fn solve(
        &mut self,
        free: &[f64],
        restitution: &[f64],
        closed: &[bool],
    ) -> Result<(), UnsolvedStep> {
        self.free.copy_from_slice(free);
        self.restitution.copy_from_slice(restitution);
        self.closed.copy_from_slice(closed);
        // The impulse scale: the slip limits and what stops the free motion in one step.
        let stopping = free
            .iter()
            .enumerate()
            .map(|(i, s)| s.abs() / self.w[(i, i)])
            .fold(0.0, f64::max);
        let limits = self.largest_slip_limit(&self.x);
        let tolerance = STEP_RELATIVE_TOLERANCE * stopping.max(limits).max(f64::MIN_POSITIVE);
        let mut x = std::mem::take(&mut self.x);
        for (k, xk) in x.iter_mut().enumerate() {
            if self.unilateral[k] && !closed[k] {
                *xk = 0.0;
            }
        }
        let options = NewtonOptions {
            tolerances: Tolerances::absolute(tolerance),
            max_iterations: STEP_MAX_ITERATIONS,
            ..NewtonOptions::default()
        };
        let mut lu = std::mem::take(&mut self.lu);
        let report = semismooth::newton::solve(self, &mut lu, &mut x, &options);
        self.lu = lu;
        self.x = x;
        match report {
            Ok(report) if report.converged() => Ok(()),
            Ok(report) => Err(UnsolvedStep {
                residual: report.residual_norms.last().copied().unwrap_or(f64::NAN),
                tolerance,
            }),
            Err(_) => Err(UnsolvedStep {
                residual: f64::NAN,
                tolerance,
            }),
        }
    }

    /// The row impulses `r = (-z, p)` of the solution (`-z` on the unilateral rows).
    pub(super) fn impulses(&self) -> impl Iterator<Item = f64> + '_ {
        self.x
            .iter()
            .zip(&self.unilateral)
            .map(|(x, unilateral)| if *unilateral { -x } else { *x })
    }
}

impl Residual for CoulombStep {
    fn dim(&self) -> usize {
        self.free.len()
    }

    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        self.row_velocities(x);
        for k in (0..x.len()).filter(|k| self.unilateral[*k]) {
            out[k] = if self.closed[k] {
                let w = -(self.velocity[k] + self.restitution[k]);
                x[k] - (x[k] - self.c * w).max(0.0)
            } else {
                x[k]
            };
        }
        for f in 0..self.friction.len() {
            let i = self.contacts + f;
            let (b, _) = self.slip_limit(f, x);
            out[i] = x[i] - coulomb_projection(x[i] - self.c * self.velocity[i], b, 0.0);
        }
        for d in 0..self.disks.len() {
            let (z, read) = self.disk_argument(d, x);
            let mut projected = [0.0; 2];
            self.disks[d]
                .law
                .project(&one_sample(&z, &read), &mut projected);
            let t = self.disks[d].tangent;
            out[t] = x[t] - projected[0];
            out[t + 1] = x[t + 1] - projected[1];
        }
        Ok(())
    }
}

/// The law's argument at one sample.
fn one_sample<'a>(z: &'a [f64; 2], read: &'a [f64; 1]) -> LawSamples<'a> {
    LawSamples {
        z,
        read,
        samples: 1,
        smoothing: 0.0,
    }
}

impl GeneralizedJacobian for CoulombStep {
    type Jacobian = Mat<f64>;

    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(self.dim(), self.dim())
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        self.row_velocities(x);
        let m = self.dim();
        let sign = |j: usize| if self.unilateral[j] { -1.0 } else { 1.0 };
        jac.fill(0.0);
        for k in (0..m).filter(|k| self.unilateral[*k]) {
            let w = -(self.velocity[k] + self.restitution[k]);
            if self.closed[k] && x[k] - self.c * w > 0.0 {
                // F = c w: dF/dx_j = -c W_kj sign_j.
                for j in 0..m {
                    jac[(k, j)] = -self.c * self.w[(k, j)] * sign(j);
                }
            } else {
                jac[(k, k)] = 1.0;
            }
        }
        for f in 0..self.friction.len() {
            let i = self.contacts + f;
            let (b, normal) = self.slip_limit(f, x);
            let y = x[i] - self.c * self.velocity[i];
            let (plus, minus) = coulomb_slopes(y, b, 0.0);
            if plus + minus == 0.0 {
                // Stick: F = c s.
                for j in 0..m {
                    jac[(i, j)] = self.c * self.w[(i, j)] * sign(j);
                }
            } else {
                // Slip: F = p -+ b.
                jac[(i, i)] = 1.0;
                if let Some((p, slope)) = normal {
                    // d proj / db = w+ - w- (the side of the interval reached).
                    jac[(i, p)] -= (plus - minus) * slope;
                }
            }
        }
        for d in 0..self.disks.len() {
            self.disk_jacobian(d, x, jac);
        }
        Ok(())
    }
}

impl CoulombStep {
    /// The rows of disk `d` in the Jacobian: with `F_t = p_t - P(y, -z_n)`,
    /// `y = p_t - c s_t`, `dF_a / dx_j = delta_aj - sum_b dP_ab / dy_b (delta_bj - c W_bj
    /// sign_j) + dP_a / d read delta_nj` (the law's block and column, rows at
    /// `row_velocities(x)`).
    fn disk_jacobian(&self, d: usize, x: &[f64], jac: &mut Mat<f64>) {
        let (z, read) = self.disk_argument(d, x);
        let (mut dz, mut dread) = ([0.0; 4], [0.0; 2]);
        let disk = &self.disks[d];
        disk.law
            .jacobian(&one_sample(&z, &read), &mut dz, &mut dread);
        let t = disk.tangent;
        for a in 0..2 {
            for j in 0..x.len() {
                let sign = if self.unilateral[j] { -1.0 } else { 1.0 };
                let mut value = if j == t + a { 1.0 } else { 0.0 };
                for b in 0..2 {
                    let dy =
                        if j == t + b { 1.0 } else { 0.0 } - self.c * self.w[(t + b, j)] * sign;
                    value -= dz[2 * a + b] * dy;
                }
                if disk.normal == Some(j) {
                    value += dread[a];
                }
                jac[(t + a, j)] = value;
            }
        }
    }
}
