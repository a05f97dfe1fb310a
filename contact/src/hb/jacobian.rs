//! The structured harmonic-balance Jacobian: dynamic blocks (shared, fixed at fixed `w`)
//! plus the contact coupling `P diag(h) E` of each contact.

use std::sync::Arc;

use faer::{Mat, MatMut};
use semismooth::linalg::DenseAssemble;

use super::LinearData;
use crate::operator::HarmonicParameters;

/// How the contact unknowns enter the Jacobian.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
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
/// With friction (SSN-HB), row `i` of a friction point measures the phase velocity
/// `y = D G_i u` (`D` the derivative in `w t`, per harmonic `(a, b) -> (k b, -k a)`):
/// `dR_i/dU = c Q_i D G_i`, `dR_i/dLambda_i = I - Q_i` with `Q_i = P diag(stick) E`, and
/// on its contact's force `dR_i/dLambda_n = X_i`.
///
/// The dynamic part `A(w, p)` is represented by the harmonic operator (shared with the
/// problem through an `Arc`, never copied per iteration) and its parameters; a solver can tell that it has not
/// changed since its last factorization ([`HbJacobian::same_dynamic_part`]). The contact
/// part is block diagonal by row group ([`crate::law`]): the `(2H + 1) x (2H + 1)` matrices
/// `Q_ab = P diag(d proj_a / d z_b) E` between the rows `a`, `b` of one group (one block
/// `Q_i = P diag(h_i) E` for a contact), plus the blocks on the rows a group reads.
#[derive(Debug, Clone)]
pub struct HbJacobian {
    pub(crate) linear: Arc<LinearData>,
    /// `w` and the other parameters of the dynamic part.
    pub(crate) parameters: HarmonicParameters,
    pub(crate) coupling: ContactCoupling,
    /// The blocks `Q_ab = P diag(d proj_a / d z_b) E` of each row group (`(2H + 1)`
    /// square, in the order of the layout's `q_pairs`): `Q` is block diagonal by group.
    pub(crate) q: Vec<Mat<f64>>,
    /// The blocks `X_as = dR_a / dLambda_s` of each group on the rows it reads (the
    /// layout's `x_pairs`): how a friction point's slip limit `mu max(0, -lambda_n)` moves
    /// with its contact's normal force.
    pub(crate) cross: Vec<Mat<f64>>,
    pub(crate) active: Vec<usize>,
}

impl HbJacobian {
    pub(crate) fn new(
        linear: Arc<LinearData>,
        parameters: HarmonicParameters,
        coupling: ContactCoupling,
    ) -> Self {
        let (q, cross) = linear.laws.zero_blocks(linear.size());
        Self {
            q,
            cross,
            active: vec![0; linear.contacts()],
            linear,
            parameters,
            coupling,
        }
    }

    /// Angular frequency `w` of the dynamic blocks.
    pub fn omega(&self) -> f64 {
        self.parameters.omega
    }

    /// The parameters of the dynamic blocks (`w`, the modal damping).
    pub fn parameters(&self) -> HarmonicParameters {
        self.parameters
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

    /// True when `other` has the same dynamic part `A(w, p)` (same model data and the same
    /// bits of every parameter), so a factorization of it can be reused.
    pub fn same_dynamic_part(&self, other: &HbJacobian) -> bool {
        Arc::ptr_eq(&self.linear, &other.linear) && self.parameters.same_as(&other.parameters)
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
        self.linear.operator.add_dense(&self.parameters, &mut out);
        let lin = &self.linear;
        let (n, m, size) = (lin.dofs, lin.contacts(), lin.size());
        let offset = n * size;
        if let ContactCoupling::Complementarity { .. } = self.coupling {
            for i in 0..m {
                for j in 0..size {
                    // dR_u / dLambda = -G^T.
                    lin.row_terms(i, j, |l, dof, a| {
                        out[(l * n + dof, offset + j * m + i)] -= a
                    });
                    out[(offset + j * m + i, offset + j * m + i)] += 1.0;
                }
            }
        }
        for (q, &(a, b)) in self.q.iter().zip(&lin.laws.q_pairs) {
            // Q_ab M_b: the measure of row b (a slip row's is the phase derivative D).
            let measured = measured_block(q, lin.is_velocity_row(b));
            match self.coupling {
                ContactCoupling::Complementarity { c } => {
                    for j in 0..size {
                        for l in 0..size {
                            // dR_a / dU = c Q_ab M_b G_b.
                            let weight = c * measured(j, l);
                            lin.row_terms(b, l, |l2, dof, g| {
                                out[(offset + j * m + a, l2 * n + dof)] += weight * g;
                            });
                        }
                        for l in 0..size {
                            // dR_a / dLambda_b = [a = b] I - Q_ab.
                            out[(offset + j * m + a, offset + l * m + b)] -= q[(j, l)];
                        }
                    }
                }
                ContactCoupling::Penalty { stiffness } => {
                    // k_p G_a^T Q_ab M_b G_b.
                    add_penalty_block(lin, measured, (a, b), stiffness, out.as_mut());
                }
            }
        }
        if let ContactCoupling::Penalty { stiffness } = self.coupling {
            // k_p G_a^T X_as M_s G_s: a penalty law's slope on the rows it reads.
            for (x, &(a, s)) in self.cross.iter().zip(&lin.laws.x_pairs) {
                let measured = measured_block(x, lin.is_velocity_row(s));
                add_penalty_block(lin, measured, (a, s), stiffness, out.as_mut());
            }
        }
        if let ContactCoupling::Complementarity { .. } = self.coupling {
            // dR_a / dLambda_s = X_as of each group on the rows it reads.
            let lambda_block = out.submatrix_mut(offset, offset, m * size, m * size);
            lin.laws.add_x_dense(&self.cross, m, lambda_block);
        }
    }
}

/// `out += k_p G_a^T B M_b G_b` for the block `B` (entries `measured(j, l)` of `B M_b`)
/// between rows `a` and `b`.
fn add_penalty_block(
    lin: &LinearData,
    measured: impl Fn(usize, usize) -> f64,
    (a, b): (usize, usize),
    stiffness: f64,
    mut out: MatMut<'_, f64>,
) {
    let (n, size) = (lin.dofs, lin.size());
    for j in 0..size {
        for l in 0..size {
            let weight = stiffness * measured(j, l);
            lin.row_terms(a, j, |j2, r, ga| {
                lin.row_terms(b, l, |l2, col, gb| {
                    out[(j2 * n + r, l2 * n + col)] += weight * ga * gb;
                });
            });
        }
    }
}

/// Entry `(j, l)` of `Q M`, `M` the measure of `Q`'s column row: the identity, or for a
/// slip row the phase derivative (harmonic `k` of `(a, b)` is `(k b, -k a)`) with the
/// mean-slip anchor on the constant.
fn measured_block(q: &Mat<f64>, velocity: bool) -> impl Fn(usize, usize) -> f64 + '_ {
    move |j: usize, l: usize| {
        if !velocity {
            q[(j, l)]
        } else if l == 0 {
            super::MEAN_SLIP_ANCHOR * q[(j, 0)]
        } else {
            let k = l.div_ceil(2) as f64;
            if l % 2 == 1 {
                -k * q[(j, l + 1)]
            } else {
                k * q[(j, l - 1)]
            }
        }
    }
}
