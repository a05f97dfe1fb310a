//! Linear solvers behind the [`LinearSolve`](crate::LinearSolve) trait.
//!
//! Every implementation checks its pivots against a relative threshold and returns
//! [`LinearSolveError::Singular`] instead of dividing by a (near) zero pivot: a singular
//! generalized Jacobian is an expected event in semismooth Newton, not a bug.
//!
//! | solver | matrix types | storage between factorizations |
//! |---|---|---|
//! | [`FaerDenseLu`] | any [`DenseAssemble`] (`faer::Mat`, `nalgebra::DMatrix`, structured types) | reused: no allocation after the first call of a size |
//! | [`NalgebraLu`] | any [`DenseAssemble`] | matrix reused; nalgebra allocates its permutation and the U copy for the pivot check |
//! | [`FaerSparseLu`] | `faer::sparse::SparseColMat<usize, f64>` | column ordering once per pattern, factor storage reused |
//!
//! Each solver has inherent `factor` and `solve_in_place` methods with the same meaning
//! as the [`LinearSolve`](crate::LinearSolve) trait methods, so direct use needs neither
//! the trait in scope nor an annotation of the Jacobian type (the dense solvers implement
//! `LinearSolve<J>` for every `J: DenseAssemble`, which would otherwise make
//! `lu.solve_in_place(..)` ambiguous). Generic code (the Newton driver) uses the trait.

mod dense;
mod nalgebra_lu;
mod scratch;
mod sparse;

pub use dense::{DenseAssemble, FaerDenseLu};
pub use nalgebra_lu::NalgebraLu;
pub use sparse::FaerSparseLu;

/// Default relative pivot threshold: a pivot `|u_ii| <= threshold * max_j |u_jj|` is
/// treated as zero.
pub const DEFAULT_PIVOT_THRESHOLD: f64 = 1e-13;

/// Why a factorization or a solve could not be carried out.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LinearSolveError {
    /// A pivot is zero or negligible relative to the largest pivot.
    #[error(
        "singular matrix: pivot {pivot:e} at index {index} is negligible against the largest pivot {max_pivot:e}"
    )]
    Singular {
        /// Position of the offending pivot in the factorization.
        index: usize,
        /// Its absolute value.
        pivot: f64,
        /// Largest absolute pivot.
        max_pivot: f64,
    },
    /// The matrix holds a NaN or infinite entry.
    #[error("matrix entry ({row}, {col}) is not finite ({value})")]
    NonFiniteEntry {
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// The value found.
        value: f64,
    },
    /// The matrix is not square, or a right-hand side has the wrong length.
    #[error("dimension mismatch: expected {expected}, found {found}")]
    DimensionMismatch {
        /// Expected dimension.
        expected: usize,
        /// Dimension received.
        found: usize,
    },
    /// `solve_in_place` was called without a successful factorization.
    #[error("solve requested before a successful factorization")]
    NotFactored,
    /// The sparse factorization failed for a reason other than a small pivot.
    #[error("sparse factorization failed: {reason}")]
    Sparse {
        /// Description from the sparse backend.
        reason: String,
    },
}

/// Scans the diagonal of an upper-triangular factor: `Err(Singular)` if some
/// `|u_ii| <= threshold * max |u_jj|` (or is zero / not finite).
pub fn check_pivots(
    diagonal: impl Iterator<Item = f64> + Clone,
    threshold: f64,
) -> Result<(), LinearSolveError> {
    let max_pivot = diagonal.clone().map(f64::abs).fold(0.0, f64::max);
    for (index, u) in diagonal.enumerate() {
        let pivot = u.abs();
        if !pivot.is_finite() || pivot == 0.0 || pivot <= threshold * max_pivot {
            return Err(LinearSolveError::Singular {
                index,
                pivot,
                max_pivot,
            });
        }
    }
    Ok(())
}
