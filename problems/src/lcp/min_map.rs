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

use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{Mat, MatMut, MatRef};
use semismooth::complementarity::min_function;
use semismooth::linalg::{check_pivots, DenseAssemble, LinearSolveError, DEFAULT_PIVOT_THRESHOLD};
use semismooth::{EvaluationError, Factorize, GeneralizedJacobian, LinearSolve, Residual};

use super::LcpError;

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
        Ok(Self {
            matrix,
            q,
            w: vec![0.0; q.len()],
        })
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
        for ((o, z), w) in out.iter_mut().zip(x).zip(&self.w) {
            *o = min_function(*z, *w).value;
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
        }
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut MinMapJacobian<'a>) -> Result<(), EvaluationError> {
        self.gap(x);
        for ((a, z), w) in jac.active.iter_mut().zip(x).zip(&self.w) {
            // min_function's gradient is (0, 1) exactly where w < z (tie: (1, 0)).
            *a = min_function(*z, *w).db == 1.0;
        }
        Ok(())
    }
}

/// An element of the generalized Jacobian of `min(z, q + A z)`: row `i` of `A` where
/// `active[i]`, the unit row `e_i` elsewhere.
#[derive(Debug, Clone)]
pub struct MinMapJacobian<'a> {
    matrix: MatRef<'a, f64>,
    active: Vec<bool>,
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
        Ok(Self { matrix, active })
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

/// Solves with a [`MinMapJacobian`] by factoring only its active block `A_II`
/// (dense LU with partial pivoting and a relative pivot check).
#[derive(Debug)]
pub struct ActiveSetSolver {
    n: usize,
    active: Vec<usize>,
    inactive: Vec<usize>,
    /// `A_IJ`, `|I| x |J|`.
    coupling: Mat<f64>,
    lu: Option<PartialPivLu<f64>>,
    rhs: Mat<f64>,
    pivot_threshold: f64,
    regularize: bool,
}

impl Default for ActiveSetSolver {
    fn default() -> Self {
        Self::new()
    }
}

impl ActiveSetSolver {
    /// A solver with the default relative pivot threshold [`DEFAULT_PIVOT_THRESHOLD`].
    pub fn new() -> Self {
        Self::with_pivot_threshold(DEFAULT_PIVOT_THRESHOLD)
    }

    /// A solver treating a pivot `|u_ii| <= threshold * max |u_jj|` of `A_II` as zero.
    pub fn with_pivot_threshold(threshold: f64) -> Self {
        Self {
            n: 0,
            active: Vec::new(),
            inactive: Vec::new(),
            coupling: Mat::zeros(0, 0),
            lu: None,
            rhs: Mat::zeros(0, 1),
            pivot_threshold: threshold,
            regularize: true,
        }
    }

    /// Reports a singular active block as [`LinearSolveError::Singular`] instead of
    /// shifting its diagonal (the default regularises it, see `factor`).
    pub fn without_regularization(mut self) -> Self {
        self.regularize = false;
        self
    }

    /// Size of the active block of the last factorization.
    pub fn active_count(&self) -> usize {
        self.active.len()
    }
}

/// Relative diagonal shift applied to a singular active block (see `factor`).
const REGULARIZATION: f64 = 1e-8;

impl Factorize<MinMapJacobian<'_>> for ActiveSetSolver {
    fn factor(&mut self, jac: &MinMapJacobian<'_>) -> Result<(), LinearSolveError> {
        self.lu = None;
        let n = jac.active.len();
        self.n = n;
        self.active.clear();
        self.inactive.clear();
        for (i, a) in jac.active.iter().enumerate() {
            if *a {
                self.active.push(i);
            } else {
                self.inactive.push(i);
            }
        }
        let k = self.active.len();
        let a = jac.matrix;
        let mut block = Mat::<f64>::zeros(k, k);
        self.coupling = Mat::zeros(k, self.inactive.len());
        for (r, &i) in self.active.iter().enumerate() {
            for (c, &j) in self.active.iter().enumerate() {
                block[(r, c)] = a[(i, j)];
            }
            for (c, &j) in self.inactive.iter().enumerate() {
                self.coupling[(r, c)] = a[(i, j)];
            }
        }
        for &i in &self.active {
            for j in 0..n {
                let value = a[(i, j)];
                if !value.is_finite() {
                    return Err(LinearSolveError::NonFiniteEntry {
                        row: i,
                        col: j,
                        value,
                    });
                }
            }
        }
        if k > 0 {
            let lu = PartialPivLu::new(block.as_ref());
            let u = lu.U();
            match check_pivots((0..k).map(|i| u[(i, i)]), self.pivot_threshold) {
                Ok(()) => self.lu = Some(lu),
                Err(singular) if !self.regularize => return Err(singular),
                Err(singular) => {
                    // A singular active block (e.g. at z = 0 when every time node is in
                    // contact and A has a null vector): shift the diagonal by 1e-8 of the
                    // largest entry (a Levenberg–Marquardt-like regularised Newton step,
                    // still a descent direction for the merit), or report the singularity.
                    let largest = (0..k)
                        .flat_map(|r| (0..k).map(move |c| (r, c)))
                        .fold(0.0_f64, |m, (r, c)| m.max(block[(r, c)].abs()));
                    let shift = REGULARIZATION * largest;
                    for d in 0..k {
                        block[(d, d)] += shift;
                    }
                    let lu = PartialPivLu::new(block.as_ref());
                    let u = lu.U();
                    if shift > 0.0
                        && check_pivots((0..k).map(|i| u[(i, i)]), self.pivot_threshold).is_ok()
                    {
                        self.lu = Some(lu);
                    } else {
                        return Err(singular);
                    }
                }
            }
        }
        self.rhs = Mat::zeros(k, 1);
        Ok(())
    }
}

impl LinearSolve for ActiveSetSolver {
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
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
        let lu = self.lu.as_ref().ok_or(LinearSolveError::NotFactored)?;
        // d_J = r_J; A_II d_I = r_I - A_IJ r_J.
        for (r, &i) in self.active.iter().enumerate() {
            let mut v = rhs[i];
            for (c, &j) in self.inactive.iter().enumerate() {
                v -= self.coupling[(r, c)] * rhs[j];
            }
            self.rhs[(r, 0)] = v;
        }
        lu.solve_in_place(self.rhs.as_mut());
        for (r, &i) in self.active.iter().enumerate() {
            rhs[i] = self.rhs[(r, 0)];
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
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
        // By default the block is regularised and the solve is finite.
        let mut regularised = ActiveSetSolver::new();
        regularised.factor(&jac).unwrap();
        let mut x = vec![1.0; 3];
        regularised.solve_in_place(&mut x).unwrap();
        assert!(x.iter().all(|v| v.is_finite()));
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
    fn jacobian_rows_match_finite_differences_away_from_kinks() {
        let n = 12;
        let a = matrix(n);
        let q: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).cos()).collect();
        let z: Vec<f64> = (0..n).map(|i| 0.5 + 0.4 * (i as f64 * 0.9).sin()).collect();
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
