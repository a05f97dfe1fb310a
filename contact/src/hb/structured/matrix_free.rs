//! The matrix-free path of [`StructuredHbSolver`]: GMRES on the condensed SSN-HB system
//! with the contact-block preconditioner, and the dense condensed matrix of a recent
//! iterate as the preconditioner when the blocks fail ([`super::super::krylov`]).

use faer::perm::PermRef;
use faer::Mat;
use semismooth::linalg::{GmresOptions, LinearSolveError};

use super::super::jacobian::ContactCoupling;
use super::super::krylov::{CondensedOperator, CondensedPreconditioner};
use super::super::LinearData;
use super::{
    finite_step, gather_contacts, receptance_columns, FactoredCondensed, StructuredHbSolver,
    KRYLOV_RELATIVE_TOLERANCE,
};

/// GMRES restart length and iteration budget of the matrix-free condensed solve. A restart
/// of 60 stalled at a far-off iterate of cycling full steps (100 contacts, H = 5: residual
/// 4.5e-4 after 1,200 iterations) where 200 converges; the basis grows only as far as a
/// solve needs (at most `2 x 201 x 8 m (2H + 1)` bytes).
const KRYLOV_RESTART: usize = 200;
const KRYLOV_MAX_ITERATIONS: usize = 1200;

/// Up to this many condensed unknowns (`8 n^2` bytes: 512 MB, and one dense LU of about
/// `3.4e11` flops) the matrix-free path may fall back on the dense condensed matrix as
/// GMRES's preconditioner, when the contact blocks leave GMRES short of its tolerance after
/// one restart cycle (contacts coupled strongly through the structure: many contacts
/// close together). Above it, GMRES with the contact blocks has the whole budget. At 6000
/// a ring of 100 blades with a 3-D friction contact on every tip at H = 10 (6300 unknowns,
/// most tips sticking: the blocks miss the coupling through the disk) did not converge
/// from zero, the blocks leaving GMRES at `|r| = 5e-8` after 1200 iterations; with the
/// dense preconditioner it converges in 51 iterations.
pub const DENSE_PRECONDITIONER_LIMIT: usize = 8000;

/// GMRES iterations with the dense preconditioner of an earlier iterate above which it is
/// refactored at the next iterate (about the cost of refactoring: one product costs
/// `H + 1` sparse solves and an `n^2` triangular solve, the factorization `n^3 / 1.5`).
const DENSE_REFRESH_ITERATIONS: usize = 30;

/// GMRES iterations with the dense preconditioner of an earlier iterate after which it is
/// refactored at the current one and the solve goes on with it (about the cost of one
/// factorization).
const DENSE_LAGGED_ITERATIONS: usize = 60;

impl StructuredHbSolver {
    /// The contact-block preconditioner of the matrix-free path at the iterate of the
    /// copied `Q_i` ([`super::krylov`]).
    pub(super) fn factor_preconditioner(&mut self) -> Result<(), LinearSolveError> {
        let ContactCoupling::Complementarity { c } = self.coupling else {
            return Err(LinearSolveError::NotFactored);
        };
        let Some((lin, _)) = &self.factored_for else {
            return Err(LinearSolveError::NotFactored);
        };
        self.contact_blocks.factor(
            (&self.coupled_rows, &lin.laws),
            (&self.q, &self.cross),
            &self.unit_receptance,
            c,
        )?;
        self.schur_factorizations += 1;
        self.schur_ready = true;
        Ok(())
    }

    /// The SSN-HB step without the condensed matrix: `w = A^{-1} r_u`,
    /// `(I - Q + c Q R) dLambda = r_lambda - c Q G w` by GMRES, `dU = A^{-1} (r_u + G^T
    /// dLambda)`.
    pub(super) fn solve_matrix_free(
        &mut self,
        lin: &LinearData,
        rhs: &mut [f64],
    ) -> Result<(), LinearSolveError> {
        let ContactCoupling::Complementarity { c } = self.coupling else {
            return Err(LinearSolveError::NotFactored);
        };
        let (n, m, size) = (lin.dofs, lin.contacts(), lin.size());
        let nu = n * size;
        let rhs_norm = rhs.iter().map(|v| v * v).sum::<f64>().sqrt();
        let mut w = std::mem::take(&mut self.work_u);
        w.copy_from_slice(&rhs[..nu]);
        self.apply_dynamic_inverse(&mut w)?;
        gather_contacts(lin, &w[..n * size], &mut self.work_a);
        lin.laws.apply_q(&self.q, m, &self.work_a, &mut self.work_c);
        for (r, b) in self.work_c.iter_mut().enumerate() {
            *b = rhs[nu + r] - c * *b;
        }
        self.work_d.fill(0.0);
        let mut tolerance =
            (KRYLOV_RELATIVE_TOLERANCE * rhs_norm).max(self.krylov_absolute_tolerance);
        if let Some(accuracy) = self.requested_accuracy {
            tolerance = tolerance
                .max(accuracy.relative * rhs_norm)
                .max(accuracy.absolute);
        }
        let nc = m * size;
        let fallback = nc <= DENSE_PRECONDITIONER_LIMIT;
        let mut solved = self.gmres_condensed(lin, c, tolerance, fallback);
        match &solved {
            Ok(iterations) if self.dense_preconditioner => {
                self.refresh_dense = *iterations > DENSE_REFRESH_ITERATIONS;
            }
            Err(LinearSolveError::NotConverged { .. }) if fallback => {
                // The preconditioner no longer captures the coupling at this iterate:
                // factor the dense condensed matrix here and go on from GMRES's last
                // iterate with it.
                if let Err(e) = self.factor_dense_preconditioner() {
                    self.work_u = w;
                    return Err(e);
                }
                solved = self.gmres_condensed(lin, c, tolerance, false);
            }
            _ => {}
        }
        if let Err(e) = solved {
            self.work_u = w;
            return Err(e);
        }
        // dU = A^{-1} (r_u + G^T dLambda).
        w.copy_from_slice(&rhs[..nu]);
        lin.scatter_rows(&self.work_d, 1.0, &mut w);
        self.apply_dynamic_inverse(&mut w)?;
        rhs[..nu].copy_from_slice(&w);
        rhs[nu..].copy_from_slice(&self.work_d);
        self.work_u = w;
        finite_step(rhs)
    }

    /// GMRES on `S dLambda = work_c` into `work_d` (its initial guess) with the current
    /// preconditioner; `short`: the budget of one restart cycle (a dense preconditioner
    /// can take over when it is spent). Returns the iterations.
    fn gmres_condensed(
        &mut self,
        lin: &LinearData,
        c: f64,
        tolerance: f64,
        short: bool,
    ) -> Result<usize, LinearSolveError> {
        let options = GmresOptions {
            relative_tolerance: 0.0,
            absolute_tolerance: tolerance,
            restart: KRYLOV_RESTART,
            max_iterations: if short && self.dense_preconditioner {
                DENSE_LAGGED_ITERATIONS
            } else if short {
                KRYLOV_RESTART
            } else {
                KRYLOV_MAX_ITERATIONS
            },
        };
        let Some((_, dynamic)) = &mut self.dynamic else {
            return Err(LinearSolveError::NotFactored);
        };
        let preconditioner = if self.dense_preconditioner {
            let nc = self.schur.nrows();
            CondensedPreconditioner::Dense(FactoredCondensed {
                lu: self.schur.as_ref(),
                perm: PermRef::new_checked(&self.perm, &self.perm_inv, nc),
                scale: self.scaled.then_some(self.column_scale.as_slice()),
                mem: &mut self.mem,
                rhs: &mut self.work_b,
            })
        } else {
            CondensedPreconditioner::Blocks(&mut self.contact_blocks, &self.coupled_rows)
        };
        let mut operator = CondensedOperator {
            dynamic,
            lin,
            q: &self.q,
            cross: &self.cross,
            c,
            rhs: &mut self.complex_rhs,
            work: &mut self.work_a,
            preconditioner,
        };
        let solved = self
            .gmres
            .solve(&mut operator, &self.work_c, &mut self.work_d, &options);
        self.krylov_iterations += match &solved {
            Ok(report) => report.iterations as u64,
            Err(LinearSolveError::NotConverged { iterations, .. }) => *iterations as u64,
            Err(_) => 0,
        };
        solved.map(|report| report.iterations)
    }

    /// Matrix-free path: forms the dense condensed matrix at the current `Q` (the full
    /// receptance at the factored parameters first, when not yet computed there), factors it and makes it
    /// GMRES's preconditioner until it needs more than [`DENSE_REFRESH_ITERATIONS`].
    pub(super) fn factor_dense_preconditioner(&mut self) -> Result<(), LinearSolveError> {
        let Some((lin, parameters)) = self.factored_for.clone() else {
            return Err(LinearSolveError::NotFactored);
        };
        let (m, size) = (lin.contacts(), lin.size());
        let nc = m * size;
        if self.schur.nrows() != nc {
            self.allocate_condensed_lu(nc, "allocating the dense condensed preconditioner")?;
        }
        if !self
            .receptance_parameters
            .is_some_and(|p| p.same_as(&parameters))
        {
            self.full_receptance(&lin)?;
            self.receptance_parameters = Some(parameters);
        }
        self.factor_condensed_equilibrated_if_needed(lin.dofs * size, m)?;
        self.dense_preconditioner = true;
        self.refresh_dense = false;
        self.dense_preconditioner_factorizations += 1;
        self.schur_factorizations += 1;
        self.schur_ready = true;
        Ok(())
    }

    /// `R_k = G Z_k^{-1} G^T` for every harmonic, a block of contacts' columns at a time
    /// (matrix-free path: the `N x m` responses are not kept).
    fn full_receptance(&mut self, lin: &LinearData) -> Result<(), LinearSolveError> {
        let m = lin.contacts();
        let harmonics = lin.basis.harmonics();
        if self.receptance.len() != harmonics + 1 {
            self.receptance = (0..=harmonics).map(|_| Mat::zeros(m, m)).collect();
        }
        let Some((_, dynamic)) = &mut self.dynamic else {
            return Err(LinearSolveError::NotFactored);
        };
        for k in 0..=harmonics {
            let r = &mut self.receptance[k];
            receptance_columns(dynamic, lin, k, &mut self.block_rhs, |first, z| {
                for i in 0..lin.contacts() {
                    for j in 0..z.ncols() {
                        r[(i, first + j)] = lin.measured(i, k, lin.row_complex(i, k, z, j));
                    }
                }
            })?;
        }
        Ok(())
    }
}
