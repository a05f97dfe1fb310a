//! Dense LU with partial pivoting (faer).

use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{Mat, MatMut};

use super::{check_pivots, LinearSolveError, DEFAULT_PIVOT_THRESHOLD};
use crate::LinearSolve;

/// A Jacobian type that can be written out as a dense `n x n` matrix.
///
/// Structured Jacobians implement this so the dense solvers can check structured ones.
pub trait DenseAssemble {
    /// Number of rows (= columns).
    fn dim(&self) -> usize;
    /// Writes the matrix into `out` (already `dim x dim`, contents arbitrary).
    fn assemble_dense(&self, out: MatMut<'_, f64>);
}

impl DenseAssemble for Mat<f64> {
    fn dim(&self) -> usize {
        self.nrows()
    }
    fn assemble_dense(&self, mut out: MatMut<'_, f64>) {
        out.copy_from(self);
    }
}

impl DenseAssemble for nalgebra::DMatrix<f64> {
    fn dim(&self) -> usize {
        self.nrows()
    }
    fn assemble_dense(&self, mut out: MatMut<'_, f64>) {
        for j in 0..self.ncols() {
            for i in 0..self.nrows() {
                out[(i, j)] = self[(i, j)];
            }
        }
    }
}

/// faer dense LU with partial pivoting, with a relative pivot check
/// (faer itself divides by zero pivots silently).
#[derive(Debug)]
pub struct FaerDenseLu {
    matrix: Mat<f64>,
    lu: Option<PartialPivLu<f64>>,
    pivot_threshold: Option<f64>,
}

impl FaerDenseLu {
    /// A solver with the default pivot threshold [`DEFAULT_PIVOT_THRESHOLD`].
    pub fn new() -> Self {
        Self {
            matrix: Mat::zeros(0, 0),
            lu: None,
            pivot_threshold: None,
        }
    }

    /// A solver that treats `|u_ii| <= threshold * max |u_jj|` as a zero pivot.
    pub fn with_pivot_threshold(threshold: f64) -> Self {
        Self {
            pivot_threshold: Some(threshold),
            ..Self::new()
        }
    }
}

impl Default for FaerDenseLu {
    fn default() -> Self {
        Self::new()
    }
}

impl<J: DenseAssemble + ?Sized> LinearSolve<J> for FaerDenseLu {
    fn factor(&mut self, jac: &J) -> Result<(), LinearSolveError> {
        let n = jac.dim();
        self.lu = None;
        if self.matrix.nrows() != n {
            self.matrix = Mat::zeros(n, n);
        }
        jac.assemble_dense(self.matrix.as_mut());
        for j in 0..n {
            for i in 0..n {
                let value = self.matrix[(i, j)];
                if !value.is_finite() {
                    return Err(LinearSolveError::NonFiniteEntry {
                        row: i,
                        col: j,
                        value,
                    });
                }
            }
        }
        let lu = PartialPivLu::new(self.matrix.as_ref());
        let u = lu.U();
        check_pivots(
            (0..n).map(|i| u[(i, i)]),
            self.pivot_threshold.unwrap_or(DEFAULT_PIVOT_THRESHOLD),
        )?;
        self.lu = Some(lu);
        Ok(())
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        let lu = self.lu.as_ref().ok_or(LinearSolveError::NotFactored)?;
        let n = self.matrix.nrows();
        if rhs.len() != n {
            return Err(LinearSolveError::DimensionMismatch {
                expected: n,
                found: rhs.len(),
            });
        }
        lu.solve_in_place(MatMut::from_column_major_slice_mut(rhs, n, 1));
        Ok(())
    }
}
