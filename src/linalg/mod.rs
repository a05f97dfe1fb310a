//! Linear solvers behind the [`Factorize`](crate::Factorize) and
//! [`LinearSolve`](crate::LinearSolve) traits.
//!
//! Every implementation checks its pivots (against a relative threshold unless told
//! otherwise) and returns [`LinearSolveError::Singular`] instead of dividing by a (near) zero
//! pivot: a singular generalized Jacobian is an expected event in semismooth Newton, not a
//! bug.
//!
//! | solver | matrix types | storage between factorizations |
//! |---|---|---|
//! | [`FaerDenseLu`] | any [`DenseAssemble`] (`faer::Mat`, `nalgebra::DMatrix`, structured types) | reused: no allocation after the first call of a size |
//! | [`NalgebraLu`] | any [`DenseAssemble`] | matrix reused; nalgebra allocates its permutation and the U copy for the pivot check |
//! | [`FaerSparseLu`] = [`SparseLu<f64>`] | `faer::sparse::SparseColMat<usize, f64>` | column ordering once per pattern, factor storage reused |
//!
//! [`SparseLu`] also factors complex matrices ([`SparseLu<faer::c64>`]), keeps several
//! factorizations of one pattern (slots) and takes the rule for singular pivots as an
//! option ([`PivotRule`]).
//!
//! For systems too large to factor, [`Gmres`] solves `A x = b` matrix-free from products
//! with `A` and a preconditioner ([`KrylovOperator`]); a problem's structured solver can
//! use it inside its own [`LinearSolve`](crate::LinearSolve).
//!
//! A matrix bordered by a few rows and columns, `[[J, B], [C^T, D]]`, is solved by
//! [`BorderedSolver`] with one factorization of `J` by any of these solvers (block
//! elimination through the Schur complement `D - C^T J^{-1} B`): a problem with a few extra
//! scalar unknowns (a frequency, an amplitude, a phase) keeps its Jacobian's structure.
//!
//! Every solver implements [`Factorize<J>`](crate::Factorize) for the Jacobian types it
//! can factor (the dense ones for every [`DenseAssemble`] type) and the single
//! [`LinearSolve`](crate::LinearSolve) (the solves with the last factorization), so
//! `lu.factor(&a)` and `lu.solve_in_place(&mut x)` need no annotation of the Jacobian type.

mod bordered;
mod dense;
mod krylov;
mod nalgebra_lu;
mod scratch;
mod sparse;

pub use bordered::{
    BorderedCounters, BorderedError, BorderedSolver, DEFAULT_BORDER_PIVOT_THRESHOLD,
};
pub use dense::{check_finite_dense, DenseAssemble, FaerDenseLu};
pub use krylov::{Gmres, GmresOptions, GmresReport, KrylovOperator};
pub use nalgebra_lu::NalgebraLu;
pub use sparse::{diagonal_entry, FaerSparseLu, LuScalar, PivotRule, SparseLu};

/// How accurately an iterative solver must solve `J x = r` (an inexact Newton step):
/// `|J x - r| <= max(relative |r|, absolute)`. Direct solvers solve exactly whatever it asks.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SolveAccuracy {
    /// The share of `|r|` the linear residual may keep (the forcing term).
    pub relative: f64,
    /// A linear residual that is small enough whatever `|r|` is.
    pub absolute: f64,
}

impl SolveAccuracy {
    /// `|J x - r| <= max(relative |r|, absolute)`.
    pub fn new(relative: f64, absolute: f64) -> Self {
        Self { relative, absolute }
    }
}

/// Default relative pivot threshold: a pivot `|u_ii| <= threshold * max_j |u_jj|` is
/// treated as zero.
pub const DEFAULT_PIVOT_THRESHOLD: f64 = 1e-13;

/// Why a factorization or a solve could not be carried out.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
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
    /// The storage of a factorization could not be allocated.
    #[error("out of memory while {during}")]
    OutOfMemory {
        /// What was being allocated.
        during: &'static str,
    },
    /// An iterative solver did not reach its tolerance within its iteration budget.
    #[error(
        "iterative solve not converged: residual {residual:e} after {iterations} iterations, tolerance {tolerance:e}"
    )]
    NotConverged {
        /// Iterations (operator products) done.
        iterations: usize,
        /// Residual norm `|b - A x|` reached.
        residual: f64,
        /// The tolerance it had to meet.
        tolerance: f64,
    },
    /// An index of the sparse backend overflowed (a pattern too large for its index type).
    #[error("index overflow while {during}")]
    IndexOverflow {
        /// What was being built.
        during: &'static str,
    },
}

impl LinearSolveError {
    /// A short name of the kind of failure: `singular-jacobian` (a singular or
    /// non-finite matrix), `out-of-memory`, `index-overflow`, `krylov-not-converged` (an
    /// iterative solve out of iterations), `linear-solve-failed`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::Singular { .. } | Self::NonFiniteEntry { .. } => "singular-jacobian",
            Self::OutOfMemory { .. } => "out-of-memory",
            Self::IndexOverflow { .. } => "index-overflow",
            Self::NotConverged { .. } => "krylov-not-converged",
            Self::DimensionMismatch { .. } | Self::NotFactored => "linear-solve-failed",
        }
    }

    /// The error of a faer sparse operation `during` something.
    pub(crate) fn from_faer(error: faer::sparse::FaerError, during: &'static str) -> Self {
        match error {
            faer::sparse::FaerError::OutOfMemory => Self::OutOfMemory { during },
            _ => Self::IndexOverflow { during },
        }
    }

    /// The error of building a faer sparse matrix `during` something (an entry out of
    /// bounds is a [`LinearSolveError::DimensionMismatch`] on its row).
    pub fn from_creation(error: faer::sparse::CreationError, during: &'static str) -> Self {
        match error {
            faer::sparse::CreationError::Generic(e) => Self::from_faer(e, during),
            faer::sparse::CreationError::OutOfBounds { row, .. } => Self::DimensionMismatch {
                expected: row,
                found: row + 1,
            },
        }
    }
}

/// The preconditions of a solve: a factorization exists (`factored`) of dimension `n`, and
/// the right-hand side has `found` entries.
pub(crate) fn check_solve(factored: bool, n: usize, found: usize) -> Result<(), LinearSolveError> {
    if !factored {
        return Err(LinearSolveError::NotFactored);
    }
    if found != n {
        return Err(LinearSolveError::DimensionMismatch { expected: n, found });
    }
    Ok(())
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

/// `|v|_2`, infinite for any non-finite component; scaled against overflow and underflow.
pub(crate) fn norm2(v: &[f64]) -> f64 {
    // One pass in the common case; the scaled pass only when the squares overflow or
    // underflow (or a component is not finite).
    let squares: f64 = v.iter().map(|x| x * x).sum();
    if squares.is_finite() && squares > f64::MIN_POSITIVE / f64::EPSILON {
        return squares.sqrt();
    }
    let mut scale = 0.0_f64;
    for x in v {
        if !x.is_finite() {
            return f64::INFINITY;
        }
        scale = scale.max(x.abs());
    }
    if scale == 0.0 {
        return 0.0;
    }
    scale * v.iter().map(|x| (x / scale).powi(2)).sum::<f64>().sqrt()
}
