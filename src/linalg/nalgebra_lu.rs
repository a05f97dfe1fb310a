//! Dense LU with partial pivoting from nalgebra: an independent implementation used to
//! cross-check the faer solvers, and a convenience for nalgebra users.

use nalgebra::{DMatrix, DVectorViewMut, Dyn, LU};

use super::dense::{check_finite_dense, DenseAssemble};
use super::{check_pivots, check_solve, LinearSolveError, DEFAULT_PIVOT_THRESHOLD};
use crate::{Factorize, LinearSolve};

/// nalgebra's `LU` (partial pivoting, `P A = L U`) behind [`LinearSolve`], with the same
/// relative pivot check as [`FaerDenseLu`](super::FaerDenseLu) (nalgebra itself only
/// notices exactly zero pivots).
///
/// The matrix storage is reused between factorizations; nalgebra allocates its
/// permutation sequence (n integers) per factorization and the pivot check reads the
/// U factor through `LU::u()` (an n x n copy), so this solver is not allocation-free:
/// use [`FaerDenseLu`](super::FaerDenseLu) in hot loops.
///
/// ```
/// use nalgebra::DMatrix;
/// use semismooth::linalg::NalgebraLu;
/// use semismooth::{Factorize, LinearSolve};
/// let a = DMatrix::from_row_slice(2, 2, &[4.0, 1.0, 2.0, 3.0]);
/// let mut lu = NalgebraLu::new();
/// lu.factor(&a).unwrap();
/// let mut x = [6.0, 8.0]; // A [1, 2]^T
/// lu.solve_in_place(&mut x).unwrap();
/// assert!((x[0] - 1.0).abs() < 1e-14 && (x[1] - 2.0).abs() < 1e-14);
/// ```
pub struct NalgebraLu {
    /// The factorization, or the bare storage to assemble the next matrix into.
    state: State,
    dim: usize,
    pivot_threshold: f64,
}

enum State {
    Empty(DMatrix<f64>),
    Factored(LU<f64, Dyn, Dyn>),
}

impl std::fmt::Debug for NalgebraLu {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NalgebraLu")
            .field("dim", &self.dim)
            .field("factored", &matches!(self.state, State::Factored(_)))
            .field("pivot_threshold", &self.pivot_threshold)
            .finish()
    }
}

impl NalgebraLu {
    /// A solver with the default pivot threshold [`DEFAULT_PIVOT_THRESHOLD`].
    pub fn new() -> Self {
        Self::with_pivot_threshold(DEFAULT_PIVOT_THRESHOLD)
    }

    /// A solver that treats `|u_ii| <= threshold * max |u_jj|` as a zero pivot.
    pub fn with_pivot_threshold(pivot_threshold: f64) -> Self {
        Self {
            state: State::Empty(DMatrix::zeros(0, 0)),
            dim: 0,
            pivot_threshold,
        }
    }
}

impl Default for NalgebraLu {
    fn default() -> Self {
        Self::new()
    }
}

impl<J: DenseAssemble + ?Sized> Factorize<J> for NalgebraLu {
    /// Factors `jac`. Errors: a non-finite entry or a negligible pivot (as for
    /// [`FaerDenseLu`](super::FaerDenseLu)); after an error the solver is unfactored.
    fn factor(&mut self, jac: &J) -> Result<(), LinearSolveError> {
        let n = jac.dim();
        let state = std::mem::replace(&mut self.state, State::Empty(DMatrix::zeros(0, 0)));
        let mut storage = match state {
            State::Empty(m) => m,
            // `l_unpack` hands back the factor storage itself (no copy).
            State::Factored(lu) => lu.l_unpack(),
        };
        if storage.nrows() != n || storage.ncols() != n {
            storage = DMatrix::zeros(n, n);
        }
        self.dim = n;
        {
            let view = faer::MatMut::from_column_major_slice_mut(storage.as_mut_slice(), n, n);
            jac.assemble_dense(view);
        }
        if let Err(e) = check_finite_dense(n, n, |i, j| storage[(i, j)]) {
            self.state = State::Empty(storage);
            return Err(e);
        }
        let lu = LU::new(storage);
        let u = lu.u();
        let pivots = check_pivots((0..n).map(|i| u[(i, i)]), self.pivot_threshold);
        drop(u);
        match pivots {
            Ok(()) => {
                self.state = State::Factored(lu);
                Ok(())
            }
            Err(e) => {
                self.state = State::Empty(lu.l_unpack());
                Err(e)
            }
        }
    }
}

impl LinearSolve for NalgebraLu {
    /// Overwrites `rhs` with `A^{-1} rhs` using the last successful factorization.
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        let n = self.dim;
        check_solve(matches!(self.state, State::Factored(_)), n, rhs.len())?;
        let State::Factored(lu) = &self.state else {
            return Err(LinearSolveError::NotFactored);
        };
        if n == 0 {
            // nalgebra's triangular solves index out of bounds on 0 x 0 factors.
            return Ok(());
        }
        let mut b = DVectorViewMut::from_slice(rhs, n);
        if lu.solve_mut(&mut b) {
            Ok(())
        } else {
            // Unreachable after the pivot check (nalgebra fails only on exact zeros),
            // reported rather than asserted.
            Err(LinearSolveError::Singular {
                index: 0,
                pivot: 0.0,
                max_pivot: 0.0,
            })
        }
    }
}
