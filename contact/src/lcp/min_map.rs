//! The LCP `w = q + A z, w >= 0, z >= 0, w . z = 0` as the nonsmooth equation
//! `F(z) = min(z, q + A z) = 0`, and a linear solver for its generalized Jacobian that
//! factors only the active block.
//!
//! At `z`, row `i` is *active* when `w_i = (q + A z)_i < z_i`: there `F_i = w_i` and the
//! Jacobian row is row `i` of `A`; elsewhere `F_i = z_i` and the row is `e_i` (at a tie the
//! identity row is taken, an element of the B-subdifferential). Ordering the rows as
//! active `I` then inactive `J`, `J d = r` reads `d_J = r_J`,
//! `A_II d_I = r_I - A_IJ r_J`: one `|I| x |I|` LU instead of an `m Nt` one. Newton on this
//! equation is the primal-dual active-set method.
//!
//! The equation offers the core's [`Smoothing`] (the polyalgorithm's smoothing path, through
//! `semismooth::polyalgorithm::solve_smoothing`): `min(z, w) = z - max(0, z - w)` with the
//! max replaced by the
//! Chen–Harker–Kanzow–Smale function, `min_mu(z, w) = z - (s + sqrt(s^2 + 4 mu^2)) / 2`,
//! `s = z - w`; its Jacobian rows are `(1 - t_i) e_i + t_i A_i` with weights
//! `t_i in (0, 1)`, solved by a dense LU (the active-set split needs 0/1 rows).

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor as lu_factor, solve as lu_solve};
use faer::perm::PermRef;
use faer::{MatMut, MatRef, Par};
use semismooth::complementarity::min_function;
use semismooth::linalg::{
    check_finite_dense, check_pivots, DenseAssemble, FaerDenseLu, LinearSolveError,
    DEFAULT_PIVOT_THRESHOLD,
};
use semismooth::InvalidOption;
use semismooth::{
    EvaluationError, Factorize, GeneralizedJacobian, LinearSolve, Residual, Smoothing,
};

use super::LcpError;
use crate::hb::{smoothed_max, smoothed_max_mu_derivative, smoothed_max_slope};

/// `out += a x` for a dense matrix (column by column).
pub(crate) fn add_mat_vec(a: MatRef<'_, f64>, x: &[f64], out: &mut [f64]) {
    for (j, xj) in x.iter().enumerate() {
        if *xj == 0.0 {
            continue;
        }
        let col = a.col(j);
        match col.try_as_col_major() {
            Some(c) => {
                for (o, v) in out.iter_mut().zip(c.as_slice()) {
                    *o += v * xj;
                }
            }
            None => {
                for (i, o) in out.iter_mut().enumerate() {
                    *o += col[i] * xj;
                }
            }
        }
    }
}

/// `F(z) = min(z, q + A z)` for a dense `A` (method `"lcp-ssn"`).
#[derive(Debug, Clone)]
pub struct MinMapLcp<'a> {
    matrix: MatRef<'a, f64>,
    q: &'a [f64],
    w: Vec<f64>,
    /// The smoothing `mu >= 0` set (0: `F` itself).
    mu: f64,
}

impl<'a> MinMapLcp<'a> {
    /// The equation for `w = q + A z`; `A` square of the length of `q`.
    pub fn new(matrix: MatRef<'a, f64>, q: &'a [f64]) -> Result<Self, LcpError> {
        for (what, found) in [
            ("rows of A", matrix.nrows()),
            ("columns of A", matrix.ncols()),
        ] {
            if found != q.len() {
                return Err(LcpError::DimensionMismatch {
                    what,
                    expected: q.len(),
                    found,
                });
            }
        }
        Ok(Self::of_lcp(matrix, q))
    }

    /// The equation of an LCP whose `A` is square of the length of `q` by construction.
    pub(crate) fn of_lcp(matrix: MatRef<'a, f64>, q: &'a [f64]) -> Self {
        Self {
            matrix,
            q,
            w: vec![0.0; q.len()],
            mu: 0.0,
        }
    }

    /// `w = q + A z` into `w`.
    fn gap(&mut self, z: &[f64]) {
        self.w.copy_from_slice(self.q);
        add_mat_vec(self.matrix, z, &mut self.w);
    }
}

impl Residual for MinMapLcp<'_> {
    fn dim(&self) -> usize {
        self.q.len()
    }

    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        self.gap(x);
        let mu = self.mu;
        for ((o, z), w) in out.iter_mut().zip(x).zip(&self.w) {
            *o = if mu == 0.0 {
                min_function(*z, *w).value
            } else {
                z - smoothed_max(z - w, mu)
            };
        }
        Ok(())
    }
}

/// The smoothing `min_mu(z, w) = z - phi_mu(z - w)`, `phi_mu(s) = (s + sqrt(s^2 + 4 mu^2))
/// / 2` (within `mu` of `min`; `mu = 0` is `F` exactly), so that the polyalgorithm can
/// follow the smoothing path from `mu = max |q|`. Its Jacobians at `mu > 0` have fractional
/// rows: solve them with the [`ActiveSetSolver`] (dense LU for those) or a dense solver.
impl Smoothing for MinMapLcp<'_> {
    /// `max |q|`: the spread of the switching quantity `z - w = -q` at `z = 0`.
    fn smoothing_scale(&self) -> f64 {
        self.q
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()))
            .max(f64::MIN_POSITIVE)
    }

    fn set_smoothing(&mut self, mu: f64) {
        self.mu = mu.max(0.0);
    }

    /// `d min_mu(z, w) / d mu = -2 mu / sqrt(s^2 + 4 mu^2)`, `s = z - w`.
    fn residual_smoothing_derivative(
        &mut self,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), EvaluationError> {
        self.gap(x);
        let mu = self.mu;
        for ((o, z), w) in out.iter_mut().zip(x).zip(&self.w) {
            *o = if mu == 0.0 {
                0.0
            } else {
                -smoothed_max_mu_derivative(z - w, mu)
            };
        }
        Ok(())
    }
}

impl<'a> GeneralizedJacobian for MinMapLcp<'a> {
    type Jacobian = MinMapJacobian<'a>;

    fn new_jacobian(&self) -> MinMapJacobian<'a> {
        MinMapJacobian {
            matrix: self.matrix,
            active: vec![false; self.q.len()],
            weights: Vec::new(),
        }
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut MinMapJacobian<'a>) -> Result<(), EvaluationError> {
        self.gap(x);
        let mu = self.mu;
        if mu == 0.0 {
            jac.weights.clear();
            for ((a, z), w) in jac.active.iter_mut().zip(x).zip(&self.w) {
                // min_function's gradient is (0, 1) exactly where w < z (tie: (1, 0)).
                *a = min_function(*z, *w).db == 1.0;
            }
        } else {
            jac.weights.resize(x.len(), 0.0);
            for (((a, t), z), w) in jac
                .active
                .iter_mut()
                .zip(jac.weights.iter_mut())
                .zip(x)
                .zip(&self.w)
            {
                *t = smoothed_max_slope(z - w, mu);
                *a = *t > 0.5;
            }
        }
        Ok(())
    }
}

/// An element of the generalized Jacobian of `min(z, q + A z)`: row `i` of `A` where
/// `active[i]`, the unit row `e_i` elsewhere; of a smoothed equation
/// (at `mu > 0`, [`Smoothing::set_smoothing`]), the rows `(1 - t_i) e_i + t_i A_i`.
#[derive(Debug, Clone)]
pub struct MinMapJacobian<'a> {
    matrix: MatRef<'a, f64>,
    active: Vec<bool>,
    /// The weights `t_i` of a smoothed Jacobian (empty: the 0/1 rows of `active`).
    weights: Vec<f64>,
}

impl<'a> MinMapJacobian<'a> {
    /// A Jacobian with the given active rows (`active.len()` = size of `A`).
    pub fn new(matrix: MatRef<'a, f64>, active: Vec<bool>) -> Result<Self, LcpError> {
        if matrix.nrows() != active.len() || matrix.ncols() != active.len() {
            return Err(LcpError::DimensionMismatch {
                what: "active flags against A",
                expected: matrix.nrows(),
                found: active.len(),
            });
        }
        Ok(Self {
            matrix,
            active,
            weights: Vec::new(),
        })
    }

    /// Whether the rows are weighted (a smoothed equation at `mu > 0`), not 0/1.
    pub fn is_weighted(&self) -> bool {
        !self.weights.is_empty()
    }

    /// Which rows are active (take the row of `A`).
    pub fn active(&self) -> &[bool] {
        &self.active
    }

    /// Number of active rows.
    pub fn active_count(&self) -> usize {
        self.active.iter().filter(|a| **a).count()
    }
}

impl DenseAssemble for MinMapJacobian<'_> {
    fn dim(&self) -> usize {
        self.active.len()
    }

    fn assemble_dense(&self, mut out: MatMut<'_, f64>) {
        let n = self.active.len();
        if self.is_weighted() {
            for j in 0..n {
                for (i, t) in self.weights.iter().enumerate() {
                    let unit = if i == j { 1.0 - t } else { 0.0 };
                    out[(i, j)] = t * self.matrix[(i, j)] + unit;
                }
            }
            return;
        }
        for j in 0..n {
            for i in 0..n {
                out[(i, j)] = if self.active[i] {
                    self.matrix[(i, j)]
                } else if i == j {
                    1.0
                } else {
                    0.0
                };
            }
        }
    }
}

/// Default relative diagonal shift of [`ActiveSetSolver::with_regularization`]: `1e-8`
/// of the largest entry of the active block.
pub const DEFAULT_ACTIVE_SET_REGULARIZATION: f64 = 1e-8;

/// Solves with a [`MinMapJacobian`] by factoring only its active block `A_II`
/// (dense LU with partial pivoting and a relative pivot check).
///
/// A singular active block is [`LinearSolveError::Singular`], as [`Factorize`] promises,
/// unless a regularisation is asked for ([`ActiveSetSolver::with_regularization`]): then
/// the diagonal of a singular block is shifted by `shift` times its largest entry and
/// factored again (a Levenberg–Marquardt-like step, still a descent direction for the
/// merit; e.g. at `z = 0` when every node is in contact and `A` has a null vector).
///
/// Storage (the block, the coupling `A_IJ`, the permutation, the scratch) is kept between
/// factorizations and grows only when a larger active set needs more: a Newton run
/// allocates only while its active sets reach new sizes.
///
/// A weighted Jacobian (of a smoothed equation, [`MinMapJacobian::is_weighted`]) has no
/// unit rows to split off: it is factored whole by a dense LU with the same pivot test.
pub struct ActiveSetSolver {
    n: usize,
    active: Vec<usize>,
    inactive: Vec<usize>,
    /// The factors of `A_II` (`k x k`, column-major, in place).
    block: Vec<f64>,
    /// `A_IJ` (`k x |J|`, column-major).
    coupling: Vec<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    /// `r_I - A_IJ r_J`, then `d_I`.
    rhs: Vec<f64>,
    mem: MemBuffer,
    mem_req: StackReq,
    factored: bool,
    pivot_threshold: f64,
    regularization: Option<f64>,
    /// The whole-matrix LU of weighted Jacobians; `dense_factored` when it holds the last
    /// factorization.
    dense: FaerDenseLu,
    dense_factored: bool,
}

impl std::fmt::Debug for ActiveSetSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ActiveSetSolver")
            .field("n", &self.n)
            .field("active", &self.active.len())
            .field("factored", &self.factored)
            .field("pivot_threshold", &self.pivot_threshold)
            .field("regularization", &self.regularization)
            .finish_non_exhaustive()
    }
}

impl Default for ActiveSetSolver {
    fn default() -> Self {
        Self::new()
    }
}

impl ActiveSetSolver {
    /// A solver with the default relative pivot threshold [`DEFAULT_PIVOT_THRESHOLD`] and
    /// no regularisation.
    pub fn new() -> Self {
        Self::with_pivot_threshold(DEFAULT_PIVOT_THRESHOLD)
    }

    /// A solver treating a pivot `|u_ii| <= threshold * max |u_jj|` of `A_II` as zero.
    pub fn with_pivot_threshold(threshold: f64) -> Self {
        Self {
            n: 0,
            active: Vec::new(),
            inactive: Vec::new(),
            block: Vec::new(),
            coupling: Vec::new(),
            perm: Vec::new(),
            perm_inv: Vec::new(),
            rhs: Vec::new(),
            mem: MemBuffer::new(StackReq::EMPTY),
            mem_req: StackReq::EMPTY,
            factored: false,
            pivot_threshold: threshold,
            regularization: None,
            dense: FaerDenseLu::with_pivot_threshold(threshold),
            dense_factored: false,
        }
    }

    /// Shifts the diagonal of a singular active block by `shift` times its largest entry
    /// (`shift` finite and `> 0`, e.g. [`DEFAULT_ACTIVE_SET_REGULARIZATION`]) instead of
    /// reporting it.
    pub fn with_regularization(mut self, shift: f64) -> Result<Self, LcpError> {
        if !(shift.is_finite() && shift > 0.0) {
            return Err(LcpError::InvalidOption(InvalidOption::new(
                "regularization",
                shift,
                "a finite relative diagonal shift > 0",
            )));
        }
        self.regularization = Some(shift);
        Ok(self)
    }

    /// Reports a singular active block as [`LinearSolveError::Singular`] (the default).
    pub fn without_regularization(mut self) -> Self {
        self.regularization = None;
        self
    }

    /// The relative diagonal shift applied to a singular block, if any.
    pub fn regularization(&self) -> Option<f64> {
        self.regularization
    }

    /// Size of the active block of the last factorization.
    pub fn active_count(&self) -> usize {
        self.active.len()
    }

    /// Factors the Jacobian of `min(z, q + A z)` with the rows `active` of `matrix` (`A`,
    /// square of the length of `active`) and unit rows elsewhere.
    pub(crate) fn factor_rows(
        &mut self,
        matrix: MatRef<'_, f64>,
        active: &[bool],
    ) -> Result<(), LinearSolveError> {
        self.factored = false;
        self.dense_factored = false;
        let n = active.len();
        for found in [matrix.nrows(), matrix.ncols()] {
            if found != n {
                return Err(LinearSolveError::DimensionMismatch { expected: n, found });
            }
        }
        self.n = n;
        self.active.clear();
        self.inactive.clear();
        // Room for any split of the n rows.
        self.active.reserve(n);
        self.inactive.reserve(n);
        for (i, a) in active.iter().enumerate() {
            if *a {
                self.active.push(i);
            } else {
                self.inactive.push(i);
            }
        }
        // The active rows of A (the others are unit rows).
        let active = &self.active;
        check_finite_dense(active.len(), n, |r, j| matrix[(active[r], j)]).map_err(
            |e| match e {
                LinearSolveError::NonFiniteEntry { row, col, value } => {
                    LinearSolveError::NonFiniteEntry {
                        row: active[row],
                        col,
                        value,
                    }
                }
                other => other,
            },
        )?;
        let k = self.active.len();
        self.coupling.resize(k * self.inactive.len(), 0.0);
        for (c, &j) in self.inactive.iter().enumerate() {
            for (r, &i) in self.active.iter().enumerate() {
                self.coupling[c * k + r] = matrix[(i, j)];
            }
        }
        self.rhs.resize(k, 0.0);
        self.perm.resize(k, 0);
        self.perm_inv.resize(k, 0);
        self.block.resize(k * k, 0.0);
        if k > 0 {
            let req = StackReq::any_of(&[
                lu_factor::lu_in_place_scratch::<usize, f64>(k, k, Par::Seq, Default::default()),
                lu_solve::solve_in_place_scratch::<usize, f64>(k, 1, Par::Seq),
            ]);
            if req.size_bytes() > self.mem_req.size_bytes()
                || req.align_bytes() > self.mem_req.align_bytes()
            {
                self.mem_req = self.mem_req.or(req);
                self.mem = MemBuffer::try_new(self.mem_req).map_err(|_| {
                    LinearSolveError::OutOfMemory {
                        during: "allocating the active-block LU workspace",
                    }
                })?;
            }
            match self.factor_block(matrix, 0.0) {
                Ok(()) => {}
                Err(singular) => {
                    let Some(relative) = self.regularization else {
                        return Err(singular);
                    };
                    let largest = self.active.iter().fold(0.0_f64, |m, &i| {
                        self.active
                            .iter()
                            .fold(m, |m, &j| m.max(matrix[(i, j)].abs()))
                    });
                    let shift = relative * largest;
                    if !(shift > 0.0 && self.factor_block(matrix, shift).is_ok()) {
                        return Err(singular);
                    }
                }
            }
        }
        self.factored = true;
        Ok(())
    }

    /// Copies `A_II + shift I` into the block and factors it in place (pivots checked).
    fn factor_block(
        &mut self,
        matrix: MatRef<'_, f64>,
        shift: f64,
    ) -> Result<(), LinearSolveError> {
        let k = self.active.len();
        for (c, &j) in self.active.iter().enumerate() {
            for (r, &i) in self.active.iter().enumerate() {
                self.block[c * k + r] = matrix[(i, j)];
            }
            self.block[c * k + c] += shift;
        }
        lu_factor::lu_in_place(
            MatMut::from_column_major_slice_mut(&mut self.block, k, k),
            &mut self.perm,
            &mut self.perm_inv,
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        let block = &self.block;
        check_pivots((0..k).map(|d| block[d * k + d]), self.pivot_threshold)
    }
}

impl Factorize<MinMapJacobian<'_>> for ActiveSetSolver {
    fn factor(&mut self, jac: &MinMapJacobian<'_>) -> Result<(), LinearSolveError> {
        self.dense_factored = false;
        if jac.is_weighted() {
            self.factored = false;
            self.dense.factor(jac)?;
            self.dense_factored = true;
            return Ok(());
        }
        self.factor_rows(jac.matrix, &jac.active)
    }
}

impl LinearSolve for ActiveSetSolver {
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        if self.dense_factored {
            return self.dense.solve_in_place(rhs);
        }
        if !self.factored {
            return Err(LinearSolveError::NotFactored);
        }
        if rhs.len() != self.n {
            return Err(LinearSolveError::DimensionMismatch {
                expected: self.n,
                found: rhs.len(),
            });
        }
        let k = self.active.len();
        if k == 0 {
            return Ok(()); // J = I
        }
        // d_J = r_J; A_II d_I = r_I - A_IJ r_J.
        for (v, &i) in self.rhs.iter_mut().zip(&self.active) {
            *v = rhs[i];
        }
        for (column, &j) in self.coupling.chunks_exact(k).zip(&self.inactive) {
            let rj = rhs[j];
            for (v, a) in self.rhs.iter_mut().zip(column) {
                *v -= a * rj;
            }
        }
        let factors = MatRef::from_column_major_slice(&self.block, k, k);
        lu_solve::solve_in_place(
            factors,
            factors,
            PermRef::new_checked(&self.perm, &self.perm_inv, k),
            MatMut::from_column_major_slice_mut(&mut self.rhs, k, 1),
            Par::Seq,
            MemStack::new(&mut self.mem),
        );
        for (v, &i) in self.rhs.iter().zip(&self.active) {
            rhs[i] = *v;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;
    use semismooth::linalg::FaerDenseLu;

    /// A deterministic, non-symmetric, diagonally heavy test matrix.
    fn matrix(n: usize) -> Mat<f64> {
        Mat::from_fn(n, n, |i, j| {
            let x = ((i * 7 + j * 13) % 17) as f64 / 17.0 - 0.5;
            if i == j {
                2.0 + x
            } else {
                0.3 * x / (1.0 + (i as f64 - j as f64).abs())
            }
        })
    }

    /// `(A, q)` of 12 unknowns (a diagonally dominant `A`) and a point `z > 0`.
    fn twelve_unknowns() -> (Mat<f64>, Vec<f64>, Vec<f64>) {
        let n = 12;
        let q = (0..n).map(|i| (i as f64 * 1.3).cos()).collect();
        let z = (0..n).map(|i| 0.5 + 0.4 * (i as f64 * 0.9).sin()).collect();
        (matrix(n), q, z)
    }

    #[test]
    fn active_set_solver_matches_dense_lu_on_the_assembled_jacobian() {
        for n in [1usize, 2, 3, 17, 64] {
            let a = matrix(n);
            for pattern in 0..4usize {
                let active: Vec<bool> = (0..n)
                    .map(|i| match pattern {
                        0 => false,
                        1 => true,
                        2 => i % 3 != 0,
                        _ => (i * 5 + 1) % 4 == 0,
                    })
                    .collect();
                let jac = MinMapJacobian::new(a.as_ref(), active).unwrap();
                let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 0.1).collect();
                let mut x1 = rhs.clone();
                let mut x2 = rhs.clone();
                let mut active_solver = ActiveSetSolver::new();
                active_solver.factor(&jac).unwrap();
                active_solver.solve_in_place(&mut x1).unwrap();
                let mut dense = FaerDenseLu::new();
                dense.factor(&jac).unwrap();
                dense.solve_in_place(&mut x2).unwrap();
                // Both are backward-stable solves of a well-conditioned system (condition
                // number O(10)): agreement to a few hundred ulps.
                for (u, v) in x1.iter().zip(&x2) {
                    assert!(
                        (u - v).abs() < 1e-13,
                        "n = {n}, pattern {pattern}: {u} vs {v}"
                    );
                }
            }
        }
    }

    #[test]
    fn singular_active_block_is_a_typed_error() {
        // Rows 0 and 1 of the active block are equal: A_II = [[1, 1], [1, 1]].
        let a = Mat::from_fn(3, 3, |i, j| f64::from(i == j || (i < 2 && j < 2)));
        let jac = MinMapJacobian::new(a.as_ref(), vec![true, true, false]).unwrap();
        // Regularised on request, the solve is finite.
        let mut regularised = ActiveSetSolver::new()
            .with_regularization(DEFAULT_ACTIVE_SET_REGULARIZATION)
            .unwrap();
        regularised.factor(&jac).unwrap();
        let mut x = vec![1.0; 3];
        regularised.solve_in_place(&mut x).unwrap();
        assert!(x.iter().all(|v| v.is_finite()));
        assert!(ActiveSetSolver::new()
            .with_regularization(f64::NAN)
            .is_err());
        // By default (and explicitly without) the singular block is a typed error.
        let mut default = ActiveSetSolver::new();
        assert!(matches!(
            default.factor(&jac),
            Err(LinearSolveError::Singular { .. })
        ));
        let mut solver = ActiveSetSolver::new().without_regularization();
        assert!(matches!(
            solver.factor(&jac),
            Err(LinearSolveError::Singular { .. })
        ));
        let mut rhs = vec![1.0; 3];
        assert_eq!(
            solver.solve_in_place(&mut rhs),
            Err(LinearSolveError::NotFactored)
        );
    }

    #[test]
    fn smoothing_at_mu_zero_is_bitwise_the_min_map_and_its_derivatives_match_differences() {
        let (a, q, z) = twelve_unknowns();
        let n = q.len();
        let mut plain = MinMapLcp::new(a.as_ref(), &q).unwrap();
        let mut smooth = MinMapLcp::new(a.as_ref(), &q).unwrap();
        smooth.set_smoothing(0.0);
        let (mut f0, mut f1) = (vec![0.0; n], vec![0.0; n]);
        plain.residual(&z, &mut f0).unwrap();
        smooth.residual(&z, &mut f1).unwrap();
        assert_eq!(f0, f1);
        let (mut j0, mut j1) = (plain.new_jacobian(), smooth.new_jacobian());
        plain.jacobian(&z, &mut j0).unwrap();
        smooth.jacobian(&z, &mut j1).unwrap();
        assert_eq!(j0.active(), j1.active());
        assert!(!j1.is_weighted());
        // At mu > 0: F_mu within mu of F, its Jacobian and mu-derivative against central
        // differences (smooth, step 1e-6: error O(1e-12 / mu^2) plus round-off 1e-10).
        let mu = 0.3;
        smooth.set_smoothing(mu);
        smooth.residual(&z, &mut f1).unwrap();
        assert!(f0.iter().zip(&f1).all(|(a, b)| a - b > 0.0 && a - b <= mu));
        smooth.jacobian(&z, &mut j1).unwrap();
        assert!(j1.is_weighted());
        let mut dense = Mat::<f64>::zeros(n, n);
        j1.assemble_dense(dense.as_mut());
        let h = 1e-6;
        let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
        for j in 0..n {
            let (mut zp, mut zm) = (z.clone(), z.clone());
            zp[j] += h;
            zm[j] -= h;
            smooth.residual(&zp, &mut fp).unwrap();
            smooth.residual(&zm, &mut fm).unwrap();
            for i in 0..n {
                let fd = (fp[i] - fm[i]) / (2.0 * h);
                assert!((fd - dense[(i, j)]).abs() < 1e-8, "({i}, {j})");
            }
        }
        let mut dmu = vec![0.0; n];
        smooth.residual_smoothing_derivative(&z, &mut dmu).unwrap();
        for (sign, out) in [(1.0, &mut fp), (-1.0, &mut fm)] {
            smooth.set_smoothing(mu + sign * h);
            smooth.residual(&z, out).unwrap();
        }
        // Back at mu = 0: the min map again, bitwise.
        smooth.set_smoothing(0.0);
        smooth.residual(&z, &mut f1).unwrap();
        assert_eq!(f0, f1);
        smooth.set_smoothing(mu);
        for i in 0..n {
            assert!(((fp[i] - fm[i]) / (2.0 * h) - dmu[i]).abs() < 1e-8, "{i}");
        }
        // The weighted Jacobian is solved whole: as the dense LU does.
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 0.1).collect();
        let (mut x1, mut x2) = (rhs.clone(), rhs);
        let mut solver = ActiveSetSolver::new();
        solver.factor(&j1).unwrap();
        solver.solve_in_place(&mut x1).unwrap();
        let mut lu = FaerDenseLu::new();
        lu.factor(&j1).unwrap();
        lu.solve_in_place(&mut x2).unwrap();
        assert_eq!(x1, x2);
    }

    #[test]
    fn jacobian_rows_match_finite_differences_away_from_kinks() {
        let (a, q, z) = twelve_unknowns();
        let n = q.len();
        let mut f = MinMapLcp::new(a.as_ref(), &q).unwrap();
        let mut jac = f.new_jacobian();
        f.jacobian(&z, &mut jac).unwrap();
        let mut dense = Mat::<f64>::zeros(n, n);
        jac.assemble_dense(dense.as_mut());
        let h = 1e-7;
        let mut f0 = vec![0.0; n];
        f.residual(&z, &mut f0).unwrap();
        for j in 0..n {
            let mut zp = z.clone();
            zp[j] += h;
            let mut fp = vec![0.0; n];
            f.residual(&zp, &mut fp).unwrap();
            for i in 0..n {
                // Piecewise linear: the one-sided difference is exact up to round-off
                // (1e-16 / 1e-7) unless a kink is crossed, which these values avoid.
                assert!(
                    ((fp[i] - f0[i]) / h - dense[(i, j)]).abs() < 1e-7,
                    "({i}, {j})"
                );
            }
        }
        assert!(jac.active_count() > 0 && jac.active_count() < n);
    }
}
