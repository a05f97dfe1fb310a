//! The structured harmonic-balance Jacobian: dynamic blocks (shared, fixed at fixed `w`)
//! plus the contact coupling `P diag(h) E` of each contact.

use std::sync::Arc;

use faer::{Mat, MatMut};
use semismooth::linalg::DenseAssemble;

use super::LinearData;

/// How the contact unknowns enter the Jacobian.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactCoupling {
    /// SSN-HB: unknowns `[U; Lambda]`,
    /// `J = [[A(w), -G^T], [c Q G, I - Q]]` with `Q = P diag(h) E` per contact,
    /// `h_n = 1` where `c (G u - g) - lambda > 0` at sample `n`.
    Complementarity {
        /// The complementarity constant `c` (force per length).
        c: f64,
    },
    /// Penalty HB: unknowns `U`, `J = A(w) + k_p G^T Q G` with `h_n = 1` where `G u - g > 0`.
    Penalty {
        /// The penalty stiffness `k_p` (force per length, absolute).
        stiffness: f64,
    },
}

/// One element of the generalized Jacobian of [`SsnHb`](super::SsnHb) or
/// [`PenaltyHb`](super::PenaltyHb).
///
/// The dynamic part `A(w)` is represented by the model matrices (shared with the problem
/// through an `Arc`, never copied per iteration) and `w`; a solver can tell that it has not
/// changed since its last factorization ([`HbJacobian::same_dynamic_part`]). The contact
/// part is the `(2H + 1) x (2H + 1)` matrix `Q_i = P diag(h_i) E` per contact.
#[derive(Debug, Clone)]
pub struct HbJacobian {
    pub(crate) linear: Arc<LinearData>,
    pub(crate) omega: f64,
    pub(crate) coupling: ContactCoupling,
    /// `Q_i` of each contact (`(2H + 1)` square).
    pub(crate) q: Vec<Mat<f64>>,
    pub(crate) active: Vec<usize>,
}

impl HbJacobian {
    pub(crate) fn new(linear: Arc<LinearData>, omega: f64, coupling: ContactCoupling) -> Self {
        let size = linear.size();
        let m = linear.contacts();
        Self {
            q: (0..m).map(|_| Mat::zeros(size, size)).collect(),
            active: vec![0; m],
            linear,
            omega,
            coupling,
        }
    }

    /// Angular frequency `w` of the dynamic blocks.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// Number of harmonics `H`.
    pub fn harmonics(&self) -> usize {
        self.linear.basis.harmonics()
    }

    /// Number of degrees of freedom `N`.
    pub fn dofs(&self) -> usize {
        self.linear.dofs
    }

    /// Number of contacts `m`.
    pub fn contacts(&self) -> usize {
        self.linear.contacts()
    }

    /// How the contact unknowns enter.
    pub fn coupling(&self) -> ContactCoupling {
        self.coupling
    }

    /// True when `other` has the same dynamic part `A(w)` (same model data and same `w`),
    /// so a factorization of it can be reused.
    pub fn same_dynamic_part(&self, other: &HbJacobian) -> bool {
        Arc::ptr_eq(&self.linear, &other.linear) && self.omega.to_bits() == other.omega.to_bits()
    }

    /// Writes `A(w)` into the leading `N (2H + 1)` square of `out` (which must be zeroed).
    fn assemble_dynamic(&self, out: &mut MatMut<'_, f64>) {
        let lin = &self.linear;
        let n = lin.dofs;
        let mut add = |m: &crate::model::SparseMatrix, r0: usize, c0: usize, alpha: f64| {
            let m = m.as_ref();
            let symbolic = m.symbolic();
            let rows = symbolic.row_idx();
            let values = m.val();
            for j in 0..n {
                for p in symbolic.col_range(j) {
                    out[(r0 + rows[p], c0 + j)] += alpha * values[p];
                }
            }
        };
        add(&lin.stiffness, 0, 0, 1.0);
        for k in 1..=lin.basis.harmonics() {
            let kw = k as f64 * self.omega;
            let (c, s) = ((2 * k - 1) * n, 2 * k * n);
            for (r0, c0) in [(c, c), (s, s)] {
                add(&lin.stiffness, r0, c0, 1.0);
                add(&lin.mass, r0, c0, -kw * kw);
            }
            if let Some(d) = &lin.damping {
                add(d, c, s, kw);
                add(d, s, c, -kw);
            }
        }
    }
}

impl DenseAssemble for HbJacobian {
    fn dim(&self) -> usize {
        let size = self.linear.size();
        match self.coupling {
            ContactCoupling::Complementarity { .. } => size * (self.dofs() + self.contacts()),
            ContactCoupling::Penalty { .. } => size * self.dofs(),
        }
    }

    fn assemble_dense(&self, mut out: MatMut<'_, f64>) {
        out.fill(0.0);
        self.assemble_dynamic(&mut out);
        let lin = &self.linear;
        let (n, m, size) = (lin.dofs, lin.contacts(), lin.size());
        let offset = n * size;
        for (i, &dof) in lin.contact_dofs.iter().enumerate() {
            let q = &self.q[i];
            // G's entry of contact i; the penalty block G^T Q G has s^2 = 1.
            let s = lin.contact_signs[i];
            match self.coupling {
                ContactCoupling::Complementarity { c } => {
                    for j in 0..size {
                        // dR_u / dLambda = -G^T.
                        out[(j * n + dof, offset + j * m + i)] -= s;
                        for l in 0..size {
                            // dR_lambda / dU = c Q G, dR_lambda / dLambda = I - Q.
                            out[(offset + j * m + i, l * n + dof)] += c * s * q[(j, l)];
                            out[(offset + j * m + i, offset + l * m + i)] -= q[(j, l)];
                        }
                        out[(offset + j * m + i, offset + j * m + i)] += 1.0;
                    }
                }
                ContactCoupling::Penalty { stiffness } => {
                    for j in 0..size {
                        for l in 0..size {
                            out[(j * n + dof, l * n + dof)] += stiffness * q[(j, l)];
                        }
                    }
                }
            }
        }
    }
}
