//! The tangent of one step of the massless-contact trapezoidal scheme, for the discrete
//! monodromy of a periodic orbit (module `stability`).
//!
//! With the active contacts `A` of a step fixed, the step map `(u_n, v_n) -> (u_{n+1},
//! v_{n+1})` of [`super::TimeMarcher`] is affine, and its linear part is, with `S` the
//! massless rows and `P_S` / `P_R` the restrictions to them / to the others,
//!
//! ```text
//! du_free = K_eff^{-1} ( M (4/h^2 du + 4/h dv) + (2/h) D du + P_S D dv - P_R K du )
//! du'     = du_free - Y_A W_AA^{-1} G_A du_free        (contacts of A stay closed)
//! dv'     = (2/h) (du' - du) - dv    (0 on the dofs of closed contacts with the reset)
//! ```
//!
//! (the inertial force `r_n = P_R (f_n - D v_n - K u_n)` is a function of the state, and
//! its `-D v_n` cancels the `D v_n` of the right-hand side on the rows with mass). The
//! forcing does not enter: the tangent depends on the active set only.
//!
//! # The velocity of a closed massless contact dof
//!
//! The trapezoidal relation `v' = (2/h)(u' - u) - v` makes the velocity of a massless dof
//! held at the gap ring with a factor `-1` per step: it starts at `-(2/h) du` from the
//! position perturbation `du` on the closing step and, through a damping entry on the
//! massless row, re-enters the dynamics at the opening step with the sign `(-1)^k` of the
//! contact phase's length `k`. In the orbit that is an `O(h)` effect, in the tangent an
//! `O(1)` one: the multipliers then depend on the parity of `k` (measured on the strongly
//! forced rod: 0.80 / 0.95 / 1.08 / 1.13 / 1.16 at 500 / 1000 / 2000 / 4000 / 8000 steps per
//! period for an orbit that marching shows to decay at 0.82). In the semi-discrete model a
//! massless dof held at the gap has velocity 0 and no memory of how it arrived. With
//! [`TimeMarcher::set_closed_contact_velocity_reset`] the marcher sets that velocity to 0
//! after every step on which the contact is closed, and the tangent does the same; the
//! scheme stays convergent (tip minimum of the canonical rod -0.5231568 / -0.5231520 /
//! -0.5231509 at 1000 / 2000 / 4000 steps per period) but its mean contact force converges
//! at first order instead of second, so the reference march keeps the plain trapezoidal
//! velocity and the reset is used for the stability analysis only.

use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::Mat;
use semismooth::InvalidOption;
use semismooth::LinearSolve;

use super::{MarchError, MarchState, Scheme, TimeMarcher};
use crate::model::{sparse_mul_add, StructuralModel};

impl TimeMarcher<'_> {
    /// Puts the marcher at step `phase` of a period (`0..steps_per_period`) in `state`,
    /// as if it had marched there (the inertial force is recomputed from the state).
    pub fn restart_at(&mut self, phase: usize, state: &MarchState) -> Result<(), MarchError> {
        let (n, m) = (self.u.len(), self.lambda.len());
        state.check(n, m)?;
        if phase >= self.steps_per_period {
            return Err(MarchError::InvalidOption(InvalidOption::new(
                "phase",
                phase as f64,
                "a step index below steps_per_period",
            )));
        }
        self.u.copy_from_slice(&state.displacement);
        self.v.copy_from_slice(&state.velocity);
        self.lambda.copy_from_slice(&state.contact_force);
        self.phase = phase;
        if self.scheme == Scheme::Trapezoidal {
            self.equilibrium_inertia(phase);
        }
        Ok(())
    }

    /// The model marched.
    pub fn model(&self) -> &StructuralModel {
        self.model
    }

    /// Whether the velocity of a closed contact's (massless) dof is set to 0 after each
    /// trapezoidal step (module documentation); off by default.
    pub fn set_closed_contact_velocity_reset(&mut self, on: bool) {
        self.reset_closed_velocity = on;
    }

    /// Steps per period.
    pub fn steps_per_period(&self) -> usize {
        self.steps_per_period
    }

    /// Whether dof `j` has a zero mass row.
    pub fn is_massless(&self, j: usize) -> bool {
        self.massless[j]
    }

    /// The linear part of one trapezoidal step with the contacts `active` closed (indices
    /// into the model's contacts), as a dense `2N x 2N` matrix on `(u, v)` (module
    /// documentation). Moreau–Jean is refused: its tangent needs the impact law's
    /// saltation.
    pub fn step_tangent(&mut self, active: &[usize]) -> Result<Mat<f64>, MarchError> {
        let model = self.model;
        if let Some(dof) = super::massive_contact_dof(model, &self.massless) {
            return Err(MarchError::MassiveContactDof {
                dof,
                mass: super::column_max_abs(&model.mass, dof),
            });
        }
        let n = self.u.len();
        let h = self.h;
        let a = active.len();
        // P = Y_A W_AA^{-1} (N x a), from W_AA P^T = Y_A^T (W symmetric).
        let mut projection = Mat::<f64>::zeros(n, a);
        if a > 0 {
            let w_aa = Mat::from_fn(a, a, |i, j| self.w[(active[i], active[j])]);
            let mut rhs = Mat::from_fn(a, n, |i, r| self.y[active[i] * n + r]);
            PartialPivLu::new(w_aa.as_ref()).solve_in_place(rhs.as_mut());
            for i in 0..a {
                for r in 0..n {
                    projection[(r, i)] = rhs[(i, r)];
                }
            }
        }
        let rows: Vec<&crate::model::ContactRow> =
            active.iter().map(|&k| &model.contacts[k].row).collect();
        let mut tangent = Mat::<f64>::zeros(2 * n, 2 * n);
        let mut col = vec![0.0; n];
        let mut unit = vec![0.0; n];
        for c in 0..2 * n {
            let j = c % n;
            col.fill(0.0);
            unit.fill(0.0);
            unit[j] = 1.0;
            if c < n {
                sparse_mul_add(model.mass.as_ref(), 4.0 / (h * h), &unit, &mut col);
                if let Some(d) = &model.damping {
                    sparse_mul_add(d.as_ref(), 2.0 / h, &unit, &mut col);
                }
                self.tmp.fill(0.0);
                sparse_mul_add(model.stiffness.as_ref(), -1.0, &unit, &mut self.tmp);
                for ((ci, ti), ml) in col.iter_mut().zip(&self.tmp).zip(&self.massless) {
                    if !ml {
                        *ci += ti;
                    }
                }
            } else {
                sparse_mul_add(model.mass.as_ref(), 4.0 / h, &unit, &mut col);
                if let Some(d) = &model.damping {
                    self.tmp.fill(0.0);
                    sparse_mul_add(d.as_ref(), 1.0, &unit, &mut self.tmp);
                    for ((ci, ti), ml) in col.iter_mut().zip(&self.tmp).zip(&self.massless) {
                        if *ml {
                            *ci += ti;
                        }
                    }
                }
            }
            self.lu
                .solve_in_place(&mut col)
                .map_err(|source| MarchError::Factorization {
                    matrix: self.scheme.matrix(),
                    source,
                })?;
            self.counters.linear_solves += 1;
            if a > 0 {
                let closed: Vec<f64> = rows.iter().map(|row| row.dot(&col)).collect();
                for r in 0..n {
                    let mut s = 0.0;
                    for (i, g) in closed.iter().enumerate() {
                        s += projection[(r, i)] * g;
                    }
                    col[r] -= s;
                }
            }
            for r in 0..n {
                tangent[(r, c)] = col[r];
                let du = if c < n && r == j { 1.0 } else { 0.0 };
                let dv = if c >= n && r == j { 1.0 } else { 0.0 };
                tangent[(n + r, c)] = 2.0 / h * (col[r] - du) - dv;
            }
            if self.reset_closed_velocity {
                for row in &rows {
                    super::remove_row_component(row, &mut tangent, |t, d| &mut t[(n + d, c)]);
                }
            }
        }
        Ok(tangent)
    }
}
