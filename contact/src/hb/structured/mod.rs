//! Structured solver for [`HbJacobian`]: per-harmonic sparse LU of the dynamic blocks,
//! condensation onto the `m (2H + 1)` contact unknowns (receptance / Schur complement).
//!
//! For harmonic `k >= 1` the real `2N x 2N` block on `(u_ck, u_sk)` is equivalent to the
//! complex `N x N` block `Z_k(w, p)` of the harmonic operator ([`crate::operator`]) acting
//! on `z = u_c - i u_s` (`k = 0`: `K` on `u_0`). Each `Z_k` is factored once per change of
//! the operator's parameters by its factors (sparse LU; column ordering once per model,
//! numeric factorization into reused storage, rejected only on a zero pivot), so the cost
//! is linear in `N` for banded models. The receptance `R_k = G Z_k^{-1} G^T` (`m x m` complex) maps contact-force
//! coefficients to contact-displacement coefficients.
//!
//! SSN-HB, `J = [[A, -G^T], [c Q G, I - Q]]`: with `w = A^{-1} r_u` and `y = G w`,
//! `(I - Q + c Q R) dLambda = r_lambda - c Q y`, then `dU = w + A^{-1} G^T dLambda`.
//! Penalty HB, `J = A + k_p G^T Q G`: `(I + k_p R Q) y = G A^{-1} r`, then
//! `dU = A^{-1} (r - k_p G^T Q y)`. The dense Schur matrix (`m (2H + 1)` square) is
//! refactored each Newton iteration; the sparse factors only when `w` or the model change.
//!
//! Large SSN-HB systems (more than [`KRYLOV_THRESHOLD`] condensed unknowns, or on request,
//! [`CondensedSolve`]) are not formed: `(I - Q + c Q R) dLambda = b` is solved by
//! restarted GMRES with the operator and preconditioner of [`super::krylov`], and
//! `dU = A^{-1} (r_u + G^T dLambda)`. The step then satisfies `|J d - r| <= max(1e-10 |r|,
//! tau)` with the absolute `tau` of [`StructuredHbSolver::with_krylov_tolerance`] (the
//! `U` rows are solved exactly, so the full residual is the condensed one), or at the
//! looser accuracy a Newton run asks of its step (the inexact-Newton forcing term of
//! [`LinearSolve::solve_in_place_to`]); a solve that does not reach it is
//! [`LinearSolveError::NotConverged`].

use std::sync::Arc;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor as dense_lu, solve as dense_solve};
use faer::perm::PermRef;
use faer::{c64, Conj, Mat, MatMut, Par};
use semismooth::linalg::{
    check_pivots, Gmres, LinearSolveError, SolveAccuracy, DEFAULT_PIVOT_THRESHOLD,
};
use semismooth::{Factorize, LinearSolve};

use super::coupled_rows::CoupledRows;
use super::jacobian::{ContactCoupling, HbJacobian};
use super::krylov::{ContactBlocks, KRYLOV_THRESHOLD, RECEPTANCE_BLOCK};
use super::laws::{copy_blocks, LawLayout};
use super::LinearData;
use crate::operator::{HarmonicFactors, HarmonicParameters};

mod matrix_free;

pub use matrix_free::DENSE_PRECONDITIONER_LIMIT;

/// Relative residual `|J x - b| / |b|` below which iterative refinement stops.
const REFINEMENT_TARGET: f64 = 1e-14;

/// Relative tolerance `|J d - r| <= KRYLOV_RELATIVE_TOLERANCE |r|` of a matrix-free solve
/// (an inexact Newton forcing term small enough to keep the iteration counts of exact
/// solves).
pub const KRYLOV_RELATIVE_TOLERANCE: f64 = 1e-10;

/// How [`StructuredHbSolver`] solves the condensed SSN-HB system on the contact unknowns.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum CondensedSolve {
    /// Dense LU up to [`KRYLOV_THRESHOLD`] condensed unknowns, GMRES above.
    #[default]
    Auto,
    /// Always form and factor the dense condensed matrix.
    Dense,
    /// Always matrix-free GMRES (SSN-HB only; penalty HB stays dense).
    Krylov,
}

impl CondensedSolve {
    /// True when the system of `contacts` contacts and `harmonics` harmonics is solved
    /// matrix-free (`complementarity`: SSN-HB, the only formulation with the Krylov path).
    pub fn uses_krylov(self, contacts: usize, harmonics: usize, complementarity: bool) -> bool {
        complementarity
            && contacts > 0
            && match self {
                Self::Auto => {
                    contacts.saturating_mul(harmonics.saturating_mul(2).saturating_add(1))
                        > KRYLOV_THRESHOLD
                }
                Self::Dense => false,
                Self::Krylov => true,
            }
    }
}

/// Structured [`LinearSolve`] for [`HbJacobian`] (SSN-HB and penalty HB): see the module
/// documentation of this file for the algebra.
///
/// Work per Newton iteration at fixed `w`: one dense LU of size `m (2H + 1)`, `H + 1`
/// sparse complex solves per right-hand side. Workspaces are allocated once per model:
/// neither a Newton iteration nor a change of `w` (refactoring the dynamic blocks)
/// allocates.
/// The per-harmonic sparse factorizations are redone only when the Jacobian's dynamic part
/// changes ([`HbJacobian::same_dynamic_part`]), which
/// [`StructuredHbSolver::dynamic_factorizations`] counts.
pub struct StructuredHbSolver {
    /// The model the workspaces are sized for, and its dynamic stiffness with one
    /// factorization slot per harmonic `k = 0..=H`.
    dynamic: Option<(Arc<LinearData>, HarmonicFactors)>,
    /// Jacobian whose dynamic part is currently factored (only its `linear` and
    /// `parameters` matter).
    factored_for: Option<(Arc<LinearData>, HarmonicParameters)>,
    /// `Z_k^{-1} G^T` (N x m) per harmonic `k = 0..=H`.
    response: Vec<Mat<c64>>,
    /// `R_k = G Z_k^{-1} G^T` (m x m) per harmonic.
    receptance: Vec<Mat<c64>>,
    coupling: ContactCoupling,
    /// The row groups' blocks `Q_ab`, copied from the Jacobian.
    q: Vec<Mat<f64>>,
    /// The row groups' blocks `X` on the rows they read, copied from the Jacobian.
    cross: Vec<Mat<f64>>,
    schur: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    /// Column scaling `s_j = 1 / max_i |S_ij|` of the condensed matrix, factored as
    /// `S diag(s)` when `scaled` (only after the unscaled factorization failed its pivot test).
    column_scale: Vec<f64>,
    scaled: bool,
    schur_ready: bool,
    complex_rhs: Mat<c64>,
    work_u: Vec<f64>,
    work_a: Vec<f64>,
    work_b: Mat<f64>,
    work_c: Vec<f64>,
    work_d: Vec<f64>,
    work_rhs: Vec<f64>,
    work_res: Vec<f64>,
    refinement_steps: usize,
    mem: MemBuffer,
    pivot_threshold: f64,
    dynamic_factorizations: u64,
    schur_factorizations: u64,
    condensed: CondensedSolve,
    /// The matrix-free path was chosen for the prepared model.
    krylov: bool,
    gmres: Gmres,
    krylov_absolute_tolerance: f64,
    /// The accuracy the current solve was asked for (an inexact Newton step), beside the
    /// tolerance of the matrix-free path.
    requested_accuracy: Option<SolveAccuracy>,
    krylov_iterations: u64,
    /// The units of rows coupled by their laws (matrix-free path).
    coupled_rows: CoupledRows,
    /// `R_k[a, b]` between the rows of each unit at index `k E + entry(a, b)` of
    /// `coupled_rows` (matrix-free path).
    unit_receptance: Vec<c64>,
    contact_blocks: ContactBlocks,
    block_rhs: Mat<c64>,
    /// Matrix-free path: `schur` holds the LU of the dense condensed matrix of a recent
    /// iterate, used as GMRES's preconditioner instead of the contact blocks.
    dense_preconditioner: bool,
    /// The dense preconditioner is refactored at the next iterate (it needed more than
    /// [`DENSE_REFRESH_ITERATIONS`] GMRES iterations).
    refresh_dense: bool,
    /// Parameters of the full receptance `receptance` on the matrix-free path.
    receptance_parameters: Option<HarmonicParameters>,
    dense_preconditioner_factorizations: u64,
    /// Hold one harmonic's sparse factorization at a time
    /// ([`StructuredHbSolver::with_one_factorization_at_a_time`]).
    one_factorization: bool,
}

impl std::fmt::Debug for StructuredHbSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StructuredHbSolver")
            .field("dynamic_factorizations", &self.dynamic_factorizations)
            .field("schur_factorizations", &self.schur_factorizations)
            .finish_non_exhaustive()
    }
}

impl Default for StructuredHbSolver {
    fn default() -> Self {
        Self::new()
    }
}

impl StructuredHbSolver {
    /// A solver with the default relative pivot threshold for the condensed system.
    pub fn new() -> Self {
        Self {
            dynamic: None,
            factored_for: None,
            response: Vec::new(),
            receptance: Vec::new(),
            coupling: ContactCoupling::Complementarity { c: 1.0 },
            q: Vec::new(),
            cross: Vec::new(),
            schur: Mat::zeros(0, 0),
            perm: Vec::new(),
            perm_inv: Vec::new(),
            column_scale: Vec::new(),
            scaled: false,
            schur_ready: false,
            complex_rhs: Mat::zeros(0, 0),
            work_u: Vec::new(),
            work_a: Vec::new(),
            work_b: Mat::zeros(0, 0),
            work_c: Vec::new(),
            work_d: Vec::new(),
            work_rhs: Vec::new(),
            work_res: Vec::new(),
            refinement_steps: 1,
            mem: MemBuffer::new(StackReq::EMPTY),
            pivot_threshold: DEFAULT_PIVOT_THRESHOLD,
            dynamic_factorizations: 0,
            schur_factorizations: 0,
            condensed: CondensedSolve::Auto,
            krylov: false,
            gmres: Gmres::new(),
            krylov_absolute_tolerance: 0.0,
            requested_accuracy: None,
            krylov_iterations: 0,
            coupled_rows: CoupledRows::default(),
            unit_receptance: Vec::new(),
            contact_blocks: ContactBlocks::default(),
            block_rhs: Mat::zeros(0, 0),
            dense_preconditioner: false,
            refresh_dense: false,
            receptance_parameters: None,
            dense_preconditioner_factorizations: 0,
            one_factorization: false,
        }
    }

    /// Holds one harmonic's sparse factorization at a time: a solve with another harmonic
    /// refactors it, so memory is one factor (plus the responses `Z_k^{-1} G^T`) while a
    /// full Newton solve refactors every harmonic per step. Meant for
    /// [`super::CondensedSsnHb::one_factorization_at_a_time`], which needs of each harmonic
    /// only its responses, solved once per frequency.
    pub fn with_one_factorization_at_a_time(mut self) -> Self {
        self.one_factorization = true;
        self.dynamic = None;
        self
    }

    /// Chooses how the condensed system is solved (default [`CondensedSolve::Auto`]).
    pub fn with_condensed_solve(mut self, condensed: CondensedSolve) -> Self {
        self.condensed = condensed;
        self.dynamic = None;
        self
    }

    /// Absolute tolerance `tau` of the matrix-free solve: it stops when
    /// `|J d - r| <= max(KRYLOV_RELATIVE_TOLERANCE |r|, tau)` (default 0). A Newton run
    /// with absolute tolerance `t` on `|F|` passes `t / 100`: a full step on the right
    /// piece then leaves `|F| <= t / 100`.
    pub fn with_krylov_tolerance(mut self, tau: f64) -> Self {
        self.krylov_absolute_tolerance = tau.max(0.0);
        self
    }

    /// True when the prepared model's condensed system is solved matrix-free.
    pub fn is_matrix_free(&self) -> bool {
        self.krylov
    }

    /// GMRES iterations (operator products) of all matrix-free solves so far.
    pub fn krylov_iterations(&self) -> u64 {
        self.krylov_iterations
    }

    /// Dense factorizations of the condensed matrix made on the matrix-free path as GMRES's
    /// preconditioner (after the contact blocks failed; module documentation).
    pub fn dense_preconditioner_factorizations(&self) -> u64 {
        self.dense_preconditioner_factorizations
    }

    /// Number of times the per-harmonic dynamic blocks were factored (once per frequency).
    pub fn dynamic_factorizations(&self) -> u64 {
        self.dynamic_factorizations
    }

    /// Number of condensed (Schur) factorizations (once per Newton iteration).
    pub fn schur_factorizations(&self) -> u64 {
        self.schur_factorizations
    }

    /// Receptance `R_k = G Z_k(w, p)^{-1} G^T` of harmonic `k` (m x m, complex; `Z_k` the
    /// harmonic operator's block) at the last factored parameters.
    pub fn receptance(&self, k: usize) -> Option<&Mat<c64>> {
        self.receptance.get(k)
    }

    /// Sizes every workspace for the model of `lin` (once per model: nothing here depends
    /// on the frequency).
    fn prepare(
        &mut self,
        lin: &Arc<LinearData>,
        coupling: ContactCoupling,
    ) -> Result<(), LinearSolveError> {
        if matches!(&self.dynamic, Some((l, _)) if Arc::ptr_eq(l, lin)) {
            return Ok(());
        }
        self.dynamic = None;
        let (n, m, h) = (lin.dofs, lin.contacts(), lin.basis.harmonics());
        let complementarity = matches!(coupling, ContactCoupling::Complementarity { .. });
        self.krylov = self.condensed.uses_krylov(m, h, complementarity);
        let size = 2 * h + 1;
        let nc = m * size;
        // Right-hand sides solved at once: a block of contacts for the receptance diagonal
        // (matrix-free) or every contact's column of the response (dense).
        let columns = if self.krylov {
            RECEPTANCE_BLOCK
        } else {
            m.max(1)
        };
        let dynamic = lin.operator.factors(columns, self.one_factorization)?;
        self.complex_rhs = Mat::zeros(n, 1);
        self.work_u = vec![0.0; n * size];
        self.work_a = vec![0.0; nc];
        self.work_c = vec![0.0; nc];
        self.work_d = vec![0.0; nc];
        self.work_rhs = Vec::with_capacity(n * size + nc);
        self.work_res = Vec::with_capacity(n * size + nc);
        (self.q, self.cross) = lin.laws.zero_blocks(size);
        if self.krylov {
            self.coupled_rows = CoupledRows::new(&lin.laws, m);
            self.unit_receptance = vec![c64::new(0.0, 0.0); (h + 1) * self.coupled_rows.entries()];
            self.block_rhs = Mat::zeros(n, RECEPTANCE_BLOCK.min(m));
            self.response.clear();
            self.receptance.clear();
            self.schur = Mat::zeros(0, 0);
            self.dense_preconditioner = false;
            self.refresh_dense = false;
            self.receptance_parameters = None;
        } else {
            self.allocate_condensed_lu(nc, "allocating the condensed LU workspace")?;
            self.response = (0..=h).map(|_| Mat::zeros(n, m)).collect();
            self.receptance = (0..=h).map(|_| Mat::zeros(m, m)).collect();
        }
        self.dynamic = Some((lin.clone(), dynamic));
        Ok(())
    }

    /// Factors every harmonic's `Z_k(w, p)` and sets `u <- A(w, p)^{-1} u` with the same
    /// factors harmonic by harmonic (one factorization per harmonic also one at a time),
    /// forming the responses and receptances of [`Factorize::factor`] but not its condensed
    /// matrix; only the solves with `A` ([`StructuredHbSolver::add_response`],
    /// [`StructuredHbSolver::apply_dynamic_inverse`]) are ready after it.
    pub(crate) fn factor_and_apply_dynamic_inverse(
        &mut self,
        jac: &HbJacobian,
        u: &mut [f64],
    ) -> Result<(), LinearSolveError> {
        self.schur_ready = false;
        let reuse = matches!(&self.factored_for,
            Some((lin, p)) if Arc::ptr_eq(lin, &jac.linear) && p.same_as(&jac.parameters));
        if reuse {
            return self.apply_dynamic_inverse(u);
        }
        self.factored_for = None;
        self.factor_dynamic(jac, Some(u))
    }

    /// Factors every harmonic's `Z_k(w, p)` (unless factored there) and forms the responses
    /// `Z_k^{-1} G^T` and receptances `G Z_k^{-1} G^T` (no allocation once prepared); with
    /// `also`, `also <- A^{-1} also` harmonic by harmonic with the same factors.
    fn factor_dynamic(
        &mut self,
        jac: &HbJacobian,
        mut also: Option<&mut [f64]>,
    ) -> Result<(), LinearSolveError> {
        let lin = jac.linear.clone();
        self.prepare(&lin, jac.coupling)?;
        let Some((_, dynamic)) = &mut self.dynamic else {
            return Err(LinearSolveError::NotFactored);
        };
        dynamic.factor(&jac.parameters)?;
        for k in 0..=lin.basis.harmonics() {
            if let Some(u) = also.as_deref_mut() {
                dynamic.solve_real_harmonic(k, u)?;
            }
            if self.krylov {
                // R_k[a, i] between the rows of each unit only.
                let (rows, store) = (&self.coupled_rows, &mut self.unit_receptance);
                let entries = rows.entries();
                receptance_columns(dynamic, &lin, k, &mut self.block_rhs, |first, z| {
                    for j in 0..z.ncols() {
                        let i = first + j;
                        for &a in &rows.units[rows.place[i].0] {
                            store[k * entries + rows.entry(a, i)] =
                                lin.measured(a, k, lin.row_complex(a, k, z, j));
                        }
                    }
                })?;
                continue;
            }
            let z = &mut self.response[k];
            z.fill(c64::new(0.0, 0.0));
            // Columns of G^T (two rows may share a dof).
            for i in 0..lin.contacts() {
                lin.add_row_column(i, k, c64::new(1.0, 0.0), z.as_mut(), i);
            }
            dynamic.solve_in_place(k, z.as_mut())?;
            let r = &mut self.receptance[k];
            for i in 0..lin.contacts() {
                for ip in 0..lin.contacts() {
                    r[(i, ip)] = lin.measured(i, k, lin.row_complex(i, k, z.as_ref(), ip));
                }
            }
        }
        self.factored_for = Some((lin, jac.parameters));
        self.dynamic_factorizations += 1;
        Ok(())
    }

    /// `u <- A(w, p)^{-1} u` harmonic by harmonic (complex form).
    pub(crate) fn apply_dynamic_inverse(&mut self, u: &mut [f64]) -> Result<(), LinearSolveError> {
        let (Some((_, dynamic)), Some(_)) = (&mut self.dynamic, &self.factored_for) else {
            return Err(LinearSolveError::NotFactored);
        };
        dynamic.solve_real(u)
    }

    /// `u += alpha A^{-1} G^T p` for contact coefficients `p` (index `j m + i`).
    pub(crate) fn add_response(&self, p: &[f64], alpha: f64, u: &mut [f64]) {
        let Some((lin, _)) = &self.factored_for else {
            return;
        };
        let (n, m) = (lin.dofs, lin.contacts());
        for k in 0..=lin.basis.harmonics() {
            let z = &self.response[k];
            for i in 0..m {
                if k == 0 {
                    let pi = alpha * p[i];
                    for r in 0..n {
                        u[r] += z[(r, i)].re * pi;
                    }
                } else {
                    // Load pc cos + ps sin -> complex pc - i ps.
                    let q = c64::new(p[(2 * k - 1) * m + i], -p[2 * k * m + i]) * alpha;
                    let (c, s) = ((2 * k - 1) * n, 2 * k * n);
                    for r in 0..n {
                        let v = z[(r, i)] * q;
                        u[c + r] += v.re;
                        u[s + r] -= v.im;
                    }
                }
            }
        }
    }
}

/// `Z_k^{-1} G^T`, a block of contacts' columns at a time (as many as `block` has): calls
/// `visit(first, z)` with the columns of contacts `first..first + z.ncols()`.
fn receptance_columns(
    dynamic: &mut HarmonicFactors,
    lin: &LinearData,
    k: usize,
    block: &mut Mat<c64>,
    mut visit: impl FnMut(usize, faer::MatRef<'_, c64>),
) -> Result<(), LinearSolveError> {
    let width = block.ncols().max(1);
    for first in (0..lin.contacts()).step_by(width) {
        let count = width.min(lin.contacts() - first);
        let mut z = block.as_mut().subcols_mut(0, count);
        z.fill(c64::new(0.0, 0.0));
        for j in 0..count {
            lin.add_row_column(first + j, k, c64::new(1.0, 0.0), z.as_mut(), j);
        }
        dynamic.solve_in_place(k, z.as_mut())?;
        visit(first, z.as_ref());
    }
    Ok(())
}

/// `out = G u`: the rows' measured coefficients (index `j m + i`; a friction point's
/// phase velocity, [`LinearData::gather_measured`]) of the full coefficients `u` (index
/// `j N + dof`).
fn gather_contacts(lin: &LinearData, u: &[f64], out: &mut [f64]) {
    lin.gather_measured(u, out);
}

/// `Ok` unless the solved step holds a non-finite entry.
fn finite_step(step: &[f64]) -> Result<(), LinearSolveError> {
    match step.iter().find(|v| !v.is_finite()) {
        Some(&value) => Err(LinearSolveError::NonFiniteEntry {
            row: 0,
            col: 0,
            value,
        }),
        None => Ok(()),
    }
}

impl Factorize<HbJacobian> for StructuredHbSolver {
    fn factor(&mut self, jac: &HbJacobian) -> Result<(), LinearSolveError> {
        self.schur_ready = false;
        let reuse = matches!(&self.factored_for,
            Some((lin, p)) if Arc::ptr_eq(lin, &jac.linear) && p.same_as(&jac.parameters));
        if !reuse {
            self.factored_for = None;
            self.factor_dynamic(jac, None)?;
        }
        let lin = jac.linear.clone();
        let (m, size) = (lin.contacts(), lin.size());
        let nc = m * size;
        self.coupling = jac.coupling;
        copy_blocks(&mut self.cross, &jac.cross)?;
        copy_blocks(&mut self.q, &jac.q)?;
        if self.krylov {
            if self.dense_preconditioner && !self.refresh_dense {
                // The dense factorization of a recent iterate stays the preconditioner.
                self.schur_ready = true;
                return Ok(());
            }
            if self.dense_preconditioner {
                return self.factor_dense_preconditioner();
            }
            return self.factor_preconditioner();
        }
        self.scaled = false;
        if nc > 0 {
            self.factor_condensed_equilibrated_if_needed(lin.dofs * size, m)?;
        }
        self.schur_factorizations += 1;
        self.schur_ready = true;
        Ok(())
    }
}

impl LinearSolve for StructuredHbSolver {
    fn krylov_iterations(&self) -> u64 {
        self.krylov_iterations
    }

    /// The matrix-free path stops at the looser of `accuracy` and its own tolerance; the
    /// dense path solves exactly.
    fn solve_in_place_to(
        &mut self,
        rhs: &mut [f64],
        accuracy: SolveAccuracy,
    ) -> Result<(), LinearSolveError> {
        self.requested_accuracy = Some(accuracy);
        let solved = self.solve_in_place(rhs);
        self.requested_accuracy = None;
        solved
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        self.work_rhs.clear();
        self.work_rhs.extend_from_slice(rhs);
        self.solve_once(rhs)?;
        if self.krylov {
            // The matrix-free solve meets its own residual tolerance.
            return Ok(());
        }
        // Iterative refinement with the exact structured operator: the condensation
        // subtracts large terms when A(w) is ill-conditioned (near resonance, stiff
        // penalties); a correction step restores dense-LU accuracy.
        for _ in 0..self.refinement_steps {
            let mut correction = std::mem::take(&mut self.work_res);
            correction.resize(rhs.len(), 0.0);
            self.apply_jacobian(rhs, &mut correction);
            let mut residual_sq = 0.0;
            let mut rhs_sq = 0.0;
            for (c, o) in correction.iter_mut().zip(&self.work_rhs) {
                *c = *o - *c;
                residual_sq += *c * *c;
                rhs_sq += o * o;
            }
            // Already at rounding level: a correction would not change the answer.
            if residual_sq <= REFINEMENT_TARGET * REFINEMENT_TARGET * rhs_sq {
                self.work_res = correction;
                break;
            }
            let solved = self.solve_once(&mut correction);
            if solved.is_ok() {
                for (x, c) in rhs.iter_mut().zip(&correction) {
                    *x += c;
                }
            }
            self.work_res = correction;
            solved?;
        }
        Ok(())
    }
}

impl StructuredHbSolver {
    fn solve_once(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        if !self.schur_ready {
            return Err(LinearSolveError::NotFactored);
        }
        let Some((lin, _)) = self.factored_for.clone() else {
            return Err(LinearSolveError::NotFactored);
        };
        let (n, m, size) = (lin.dofs, lin.contacts(), lin.size());
        let nu = n * size;
        let nc = m * size;
        let expected = match self.coupling {
            ContactCoupling::Complementarity { .. } => nu + nc,
            ContactCoupling::Penalty { .. } => nu,
        };
        if rhs.len() != expected {
            return Err(LinearSolveError::DimensionMismatch {
                expected,
                found: rhs.len(),
            });
        }
        if self.krylov {
            return self.solve_matrix_free(&lin, rhs);
        }
        let mut w = std::mem::take(&mut self.work_u);
        w.copy_from_slice(&rhs[..nu]);
        self.apply_dynamic_inverse(&mut w)?;
        // y = G w.
        gather_contacts(&lin, &w[..n * size], &mut self.work_a);
        match self.coupling {
            ContactCoupling::Complementarity { c } => {
                // b = r_lambda - c Q y.
                lin.laws.apply_q(&self.q, m, &self.work_a, &mut self.work_c);
                for r in 0..nc {
                    self.work_b[(r, 0)] = rhs[nu + r] - c * self.work_c[r];
                }
                self.solve_schur();
                for r in 0..nc {
                    self.work_a[r] = self.work_b[(r, 0)];
                }
                // dU = w + A^{-1} G^T dLambda.
                self.add_response(&self.work_a, 1.0, &mut w);
                rhs[..nu].copy_from_slice(&w);
                rhs[nu..].copy_from_slice(&self.work_a);
            }
            ContactCoupling::Penalty { stiffness } => {
                for r in 0..nc {
                    self.work_b[(r, 0)] = self.work_a[r];
                }
                self.solve_schur();
                for r in 0..nc {
                    self.work_a[r] = self.work_b[(r, 0)];
                }
                // dU = w - k_p A^{-1} G^T (Q + X) y.
                lin.laws.apply_q(&self.q, m, &self.work_a, &mut self.work_c);
                lin.laws
                    .apply_x_add(&self.cross, m, &self.work_a, &mut self.work_c);
                self.add_response(&self.work_c, -stiffness, &mut w);
                rhs.copy_from_slice(&w);
            }
        }
        self.work_u = w;
        finite_step(rhs)
    }
}

impl StructuredHbSolver {
    /// `out = J x` with the Jacobian last factored (structured product, no assembly).
    fn apply_jacobian(&mut self, x: &[f64], out: &mut [f64]) {
        let Some((lin, parameters)) = self.factored_for.clone() else {
            return;
        };
        let (n, m, size) = (lin.dofs, lin.contacts(), lin.size());
        let nu = n * size;
        lin.apply_dynamic(&parameters, &x[..nu], &mut out[..nu]);
        gather_contacts(&lin, &x[..n * size], &mut self.work_a);
        lin.laws.apply_q(&self.q, m, &self.work_a, &mut self.work_c);
        match self.coupling {
            ContactCoupling::Complementarity { c } => {
                let (out_u, out_l) = out.split_at_mut(nu);
                let x_l = &x[nu..];
                lin.laws.apply_q(&self.q, m, x_l, &mut self.work_d);
                lin.scatter_rows(x_l, -1.0, out_u);
                for r in 0..m * size {
                    out_l[r] = c * self.work_c[r] + x_l[r] - self.work_d[r];
                }
                lin.laws.apply_x_add(&self.cross, m, x_l, out_l);
            }
            ContactCoupling::Penalty { stiffness } => {
                lin.laws
                    .apply_x_add(&self.cross, m, &self.work_a, &mut self.work_c);
                lin.scatter_rows(&self.work_c, stiffness, out);
            }
        }
    }

    /// The dense condensed LU's storage and workspace for `nc` unknowns.
    fn allocate_condensed_lu(
        &mut self,
        nc: usize,
        during: &'static str,
    ) -> Result<(), LinearSolveError> {
        let req = StackReq::any_of(&[
            dense_lu::lu_in_place_scratch::<usize, f64>(nc, nc, Par::Seq, Default::default()),
            dense_solve::solve_in_place_scratch::<usize, f64>(nc, 1, Par::Seq),
        ]);
        self.mem = MemBuffer::try_new(req).map_err(|_| LinearSolveError::OutOfMemory { during })?;
        self.work_b = Mat::zeros(nc, 1);
        self.schur = Mat::zeros(nc, nc);
        self.perm = vec![0; nc];
        self.perm_inv = vec![0; nc];
        self.column_scale = vec![1.0; nc];
        Ok(())
    }

    /// Factors the condensed matrix; when its unscaled factorization fails the pivot test,
    /// factors it again with equilibrated columns. Near an undamped resonance the
    /// receptance of one harmonic dwarfs the others: the pivot test must compare pivots of
    /// columns of one scale (the solve undoes the scaling).
    fn factor_condensed_equilibrated_if_needed(
        &mut self,
        offset: usize,
        m: usize,
    ) -> Result<(), LinearSolveError> {
        self.scaled = false;
        let unscaled = self.factor_condensed(offset, m, false);
        if matches!(unscaled, Err(LinearSolveError::Singular { .. })) {
            self.scaled = true;
            self.factor_condensed(offset, m, true)
        } else {
            unscaled
        }
    }

    /// Forms the condensed matrix `S` (with its columns scaled to unit largest entry when
    /// `equilibrate`), factors it and checks its pivots (`offset`: the index of its first
    /// unknown in the full system, for the error).
    fn factor_condensed(
        &mut self,
        offset: usize,
        m: usize,
        equilibrate: bool,
    ) -> Result<(), LinearSolveError> {
        let Some((lin, _)) = &self.factored_for else {
            return Err(LinearSolveError::NotFactored);
        };
        condensed_matrix(
            &self.receptance,
            (&lin.laws, &self.q, &self.cross),
            self.coupling,
            m,
            self.schur.as_mut(),
        );
        if equilibrate {
            for (j, scale) in self.column_scale.iter_mut().enumerate() {
                let largest = self
                    .schur
                    .col_as_slice(j)
                    .iter()
                    .fold(0.0_f64, |a, v| a.max(v.abs()));
                *scale = if largest > 0.0 && largest.is_finite() {
                    1.0 / largest
                } else {
                    1.0
                };
                for v in self.schur.col_as_slice_mut(j) {
                    *v *= *scale;
                }
            }
        }
        let nc = self.schur.nrows();
        let stack = MemStack::new(&mut self.mem);
        dense_lu::lu_in_place(
            self.schur.as_mut(),
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            stack,
            Default::default(),
        );
        check_pivots((0..nc).map(|i| self.schur[(i, i)]), self.pivot_threshold).map_err(|e| match e
        {
            LinearSolveError::Singular {
                index,
                pivot,
                max_pivot,
            } => LinearSolveError::Singular {
                index: offset + index,
                pivot,
                max_pivot,
            },
            other => other,
        })
    }

    /// `work_b <- S^{-1} work_b` with the factored condensed matrix.
    fn solve_schur(&mut self) {
        let nc = self.schur.nrows();
        if nc == 0 {
            return;
        }
        FactoredCondensed {
            lu: self.schur.as_ref(),
            perm: PermRef::new_checked(&self.perm, &self.perm_inv, nc),
            scale: self.scaled.then_some(self.column_scale.as_slice()),
            mem: &mut self.mem,
            rhs: &mut self.work_b,
        }
        .solve_rhs();
    }
}

/// The LU of the condensed matrix `S diag(scale) = P^T L U` (`scale`: the column
/// equilibration, when it was needed) with its solve workspace.
pub(crate) struct FactoredCondensed<'a> {
    lu: faer::MatRef<'a, f64>,
    perm: PermRef<'a, usize>,
    scale: Option<&'a [f64]>,
    mem: &'a mut MemBuffer,
    /// `nc x 1` right-hand side, overwritten by the solution.
    rhs: &'a mut Mat<f64>,
}

impl FactoredCondensed<'_> {
    /// `rhs <- S^{-1} rhs`.
    fn solve_rhs(&mut self) {
        dense_solve::solve_in_place_with_conj(
            self.lu,
            self.lu,
            self.perm,
            Conj::No,
            self.rhs.as_mut(),
            Par::Seq,
            MemStack::new(self.mem),
        );
        if let Some(scale) = self.scale {
            for (r, s) in scale.iter().enumerate() {
                self.rhs[(r, 0)] *= s;
            }
        }
    }

    /// `out = S^{-1} b`.
    pub(crate) fn solve(&mut self, b: &[f64], out: &mut [f64]) {
        for (r, v) in b.iter().enumerate() {
            self.rhs[(r, 0)] = *v;
        }
        self.solve_rhs();
        for (r, o) in out.iter_mut().enumerate() {
            *o = self.rhs[(r, 0)];
        }
    }
}

/// Receptance entries of column `(l, i')`: `R e_(l, i')` is nonzero only on the basis
/// functions of harmonic `k(l)`; returns `(rho_cos_or_const, rho_sin)` for row contact `i`
/// (`rho_sin` is 0 for `k = 0`).
#[inline]
fn receptance_column(receptance: &[Mat<c64>], l: usize, i: usize, ip: usize) -> (f64, f64) {
    real_receptance(receptance[l.div_ceil(2)][(i, ip)], l)
}

/// The real form of the receptance entry `r = R_k[i, i']` on basis function `l` of harmonic
/// `k = ceil(l / 2)`: the response's coefficients `(rho_cos_or_const, rho_sin)` on harmonic
/// `k` to a unit load on `l` (`rho_sin` 0 for `k = 0`).
#[inline]
pub(crate) fn real_receptance(r: c64, l: usize) -> (f64, f64) {
    let k = l.div_ceil(2);
    if k == 0 {
        (r.re, 0.0)
    } else if l % 2 == 1 {
        // Unit cosine load: a = Cr, b = -Ci.
        (r.re, -r.im)
    } else {
        // Unit sine load: a = Ci, b = Cr.
        (r.im, r.re)
    }
}

/// Writes the condensed matrix on the `m (2H + 1)` contact unknowns: `I - Q + c Q R + X`
/// (SSN-HB; `X` the row groups' blocks on the rows they read) or `I + k_p R Q` (penalty),
/// using that `R` only couples the two basis functions of one harmonic (cost
/// `O(m^2 (2H + 1)^2)` for groups of one row). `blocks` holds the layout of the groups and
/// their blocks `Q_ab` and `X_as`.
pub(crate) fn condensed_matrix(
    receptance: &[Mat<c64>],
    (layout, q, cross): (&LawLayout, &[Mat<f64>], &[Mat<f64>]),
    coupling: ContactCoupling,
    m: usize,
    mut out: MatMut<'_, f64>,
) {
    let size = (2 * receptance.len()).saturating_sub(1);
    out.fill(0.0);
    for (qab, &(a, b)) in q.iter().zip(&layout.q_pairs) {
        match coupling {
            ContactCoupling::Complementarity { c } => {
                complementarity_columns(receptance, qab, (a, b), (c, m), out.as_mut());
            }
            ContactCoupling::Penalty { stiffness } => {
                penalty_columns(receptance, qab, (a, b), (stiffness, m), out.as_mut());
            }
        }
    }
    match coupling {
        ContactCoupling::Complementarity { .. } => {
            for col in 0..m * size {
                out[(col, col)] += 1.0;
            }
            layout.add_x_dense(cross, m, out);
        }
        ContactCoupling::Penalty { stiffness } => {
            // A penalty law's slope on the rows it reads enters as Q does.
            for (xas, &(a, s)) in cross.iter().zip(&layout.x_pairs) {
                penalty_columns(receptance, xas, (a, s), (stiffness, m), out.as_mut());
            }
            for col in 0..m * size {
                out[(col, col)] += 1.0;
            }
        }
    }
}

/// Adds the columns `l m + b` of `k_p R B` for the block `B` between rows `a` and `b`
/// (column `(l, b)` of `B` is `B[:, l]` on row `a`: `S e += k_p R_{:, a} B[:, l]`).
fn penalty_columns(
    receptance: &[Mat<c64>],
    block: &Mat<f64>,
    (a, b): (usize, usize),
    (stiffness, m): (f64, usize),
    mut out: MatMut<'_, f64>,
) {
    for l in 0..block.ncols() {
        let col = l * m + b;
        for i in 0..m {
            let r0 = receptance[0][(i, a)].re;
            out[(i, col)] += stiffness * r0 * block[(0, l)];
            for (kk, rk) in receptance.iter().enumerate().skip(1) {
                let (jc, js) = (2 * kk - 1, 2 * kk);
                let r = rk[(i, a)];
                let (pc, ps) = (block[(jc, l)], block[(js, l)]);
                out[(jc * m + i, col)] += stiffness * (r.re * pc + r.im * ps);
                out[(js * m + i, col)] += stiffness * (-r.im * pc + r.re * ps);
            }
        }
    }
}

/// Adds the rows `j m + a` of `c Q_ab R_b - Q_ab` (the block `(a, b)` of `Q` times the
/// receptance rows of `b`, and minus itself on the columns of `b`) to `out`.
fn complementarity_columns(
    receptance: &[Mat<c64>],
    qab: &Mat<f64>,
    (a, b): (usize, usize),
    (c, m): (f64, usize),
    mut out: MatMut<'_, f64>,
) {
    for l in 0..qab.ncols() {
        for ip in 0..m {
            let col = l * m + ip;
            let rho = receptance_column(receptance, l, b, ip);
            law_receptance_column(qab, (l, b == ip), rho, c, |j, value| {
                out[(j * m + a, col)] += value;
            });
        }
    }
}

/// Column `l` of `c Q_ab R~ - [own] Q_ab` (`R~` the real form of one receptance entry on
/// harmonic `k = ceil(l / 2)`, `rho` from [`real_receptance`]: it couples only harmonic
/// `k`'s basis functions; `own` when the entry is `b`'s own, `R_k[b, b]`):
/// `visit(j, c (rho_0 Q[j, first] + rho_1 Q[j, first + 1]) - [own] Q[j, l])` for every row
/// `j`, `first` harmonic `k`'s first basis function.
#[inline]
pub(crate) fn law_receptance_column(
    qab: &Mat<f64>,
    (l, own): (usize, bool),
    (rho0, rho1): (f64, f64),
    c: f64,
    mut visit: impl FnMut(usize, f64),
) {
    let k = l.div_ceil(2);
    let (first, count) = if k == 0 { (0, 1) } else { (2 * k - 1, 2) };
    let (q0, q1) = (qab.col_as_slice(first), qab.col_as_slice(first + count - 1));
    let ql = qab.col_as_slice(l);
    for (j, ((x, y), d)) in q0.iter().zip(q1).zip(ql).enumerate() {
        let mut value = c * rho0 * x;
        if count == 2 {
            value += c * rho1 * y;
        }
        if own {
            value -= d;
        }
        visit(j, value);
    }
}
