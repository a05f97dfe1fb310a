//! Dense LU with partial pivoting (faer), factored in place into storage that is reused
//! from one factorization to the next.

use faer::linalg::lu::partial_pivoting::{factor as lu_factor, solve as lu_solve};
use faer::perm::PermRef;
use faer::{Mat, MatMut};

use super::scratch::Scratch;
use super::{check_pivots, check_solve, LinearSolveError, DEFAULT_PIVOT_THRESHOLD};
use crate::{Factorize, LinearSolve};

/// A Jacobian type that can be written out as a dense `n x n` matrix.
///
/// Structured Jacobians implement this so the dense solvers can check structured ones.
///
/// ```
/// use semismooth::faer::MatMut;
/// use semismooth::linalg::{DenseAssemble, FaerDenseLu};
/// use semismooth::{Factorize, LinearSolve};
/// /// A diagonal Jacobian kept as its diagonal.
/// struct Diagonal(Vec<f64>);
/// impl DenseAssemble for Diagonal {
///     fn dim(&self) -> usize { self.0.len() }
///     fn assemble_dense(&self, mut out: MatMut<'_, f64>) {
///         out.fill(0.0);
///         for (i, d) in self.0.iter().enumerate() {
///             out[(i, i)] = *d;
///         }
///     }
/// }
/// // Every dense solver factors it.
/// let mut lu = FaerDenseLu::new();
/// lu.factor(&Diagonal(vec![2.0, 4.0])).unwrap();
/// let mut x = [1.0, 1.0];
/// lu.solve_in_place(&mut x).unwrap();
/// assert_eq!(x, [0.5, 0.25]);
/// ```
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

/// Returns the first non-finite entry of a dense `nrows x ncols` matrix (read through
/// `entry(row, col)`, column by column) as [`LinearSolveError::NonFiniteEntry`].
pub fn check_finite_dense(
    nrows: usize,
    ncols: usize,
    entry: impl Fn(usize, usize) -> f64,
) -> Result<(), LinearSolveError> {
    for col in 0..ncols {
        for row in 0..nrows {
            let value = entry(row, col);
            if !value.is_finite() {
                return Err(LinearSolveError::NonFiniteEntry { row, col, value });
            }
        }
    }
    Ok(())
}

/// faer dense LU with partial pivoting, `P A = L U`, with a relative pivot check
/// (faer itself divides by zero pivots silently).
///
/// The factors overwrite a matrix kept by the solver; the row permutation and the
/// scratch memory are kept as well, so repeated [`factor`](FaerDenseLu::factor) /
/// [`solve_in_place`](FaerDenseLu::solve_in_place) calls of one size allocate nothing.
///
/// It factors every `J: DenseAssemble` ([`Factorize<J>`]).
///
/// ```
/// use faer::Mat;
/// use semismooth::linalg::FaerDenseLu;
/// use semismooth::{Factorize, LinearSolve};
/// let a = Mat::from_fn(2, 2, |i, j| [[4.0, 1.0], [2.0, 3.0]][i][j]);
/// let mut lu = FaerDenseLu::new();
/// lu.factor(&a).unwrap();
/// let mut x = [6.0, 8.0]; // A [1, 2]^T
/// lu.solve_in_place(&mut x).unwrap();
/// assert!((x[0] - 1.0).abs() < 1e-14 && (x[1] - 2.0).abs() < 1e-14);
/// ```
#[derive(Debug)]
pub struct FaerDenseLu {
    /// Packed factors: strictly lower part = L (unit diagonal implied), upper part = U.
    factors: Mat<f64>,
    perm_fwd: Vec<usize>,
    perm_inv: Vec<usize>,
    scratch: Scratch,
    factored: bool,
    pivot_threshold: f64,
}

impl FaerDenseLu {
    /// A solver with the default pivot threshold [`DEFAULT_PIVOT_THRESHOLD`].
    pub fn new() -> Self {
        Self {
            factors: Mat::zeros(0, 0),
            perm_fwd: Vec::new(),
            perm_inv: Vec::new(),
            scratch: Scratch::new(),
            factored: false,
            pivot_threshold: DEFAULT_PIVOT_THRESHOLD,
        }
    }

    /// A solver that treats `|u_ii| <= threshold * max |u_jj|` as a zero pivot.
    pub fn with_pivot_threshold(threshold: f64) -> Self {
        Self {
            pivot_threshold: threshold,
            ..Self::new()
        }
    }
}

impl Default for FaerDenseLu {
    fn default() -> Self {
        Self::new()
    }
}

impl<J: DenseAssemble + ?Sized> Factorize<J> for FaerDenseLu {
    /// Factors `jac` (`P A = L U`, partial pivoting). Errors: a non-finite entry
    /// ([`LinearSolveError::NonFiniteEntry`]) or a pivot `|u_ii| <= threshold * max |u_jj|`
    /// ([`LinearSolveError::Singular`]); after an error the solver is unfactored.
    fn factor(&mut self, jac: &J) -> Result<(), LinearSolveError> {
        let n = jac.dim();
        self.factored = false;
        if self.factors.nrows() != n {
            // n^2 numbers: fallible, so that a matrix too large for memory is an error.
            self.factors = Mat::new();
            let mut factors = Mat::new();
            factors
                .try_reserve(n, n)
                .map_err(|_| LinearSolveError::OutOfMemory {
                    during: "allocating the dense LU factors",
                })?;
            factors.resize_with(n, n, |_, _| 0.0);
            self.factors = factors;
            self.perm_fwd.resize(n, 0);
            self.perm_inv.resize(n, 0);
        }
        jac.assemble_dense(self.factors.as_mut());
        check_finite_dense(n, n, |i, j| self.factors[(i, j)])?;
        let par = faer::get_global_parallelism();
        let req = lu_factor::lu_in_place_scratch::<usize, f64>(n, n, par, Default::default());
        let stack = self.scratch.stack(req)?;
        lu_factor::lu_in_place(
            self.factors.as_mut(),
            &mut self.perm_fwd,
            &mut self.perm_inv,
            par,
            stack,
            Default::default(),
        );
        let factors = &self.factors;
        check_pivots((0..n).map(|i| factors[(i, i)]), self.pivot_threshold)?;
        self.factored = true;
        Ok(())
    }
}

impl LinearSolve for FaerDenseLu {
    /// Overwrites `rhs` with `A^{-1} rhs` using the last successful factorization.
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        self.solve_columns_in_place(rhs, 1)
    }

    /// Overwrites the `ncols` columns of `columns` with `A^{-1} columns` in one blocked
    /// solve (for one column the same arithmetic as [`FaerDenseLu::solve_in_place`]).
    fn solve_columns_in_place(
        &mut self,
        columns: &mut [f64],
        ncols: usize,
    ) -> Result<(), LinearSolveError> {
        let n = self.factors.nrows();
        check_solve(self.factored, n * ncols, columns.len())?;
        if ncols == 0 {
            return Ok(());
        }
        let par = faer::get_global_parallelism();
        let req = lu_solve::solve_in_place_scratch::<usize, f64>(n, ncols, par);
        let stack = self.scratch.stack(req)?;
        let perm = PermRef::new_checked(&self.perm_fwd, &self.perm_inv, n);
        lu_solve::solve_in_place(
            self.factors.as_ref(),
            self.factors.as_ref(),
            perm,
            MatMut::from_column_major_slice_mut(columns, n, ncols),
            par,
            stack,
        );
        Ok(())
    }
}
