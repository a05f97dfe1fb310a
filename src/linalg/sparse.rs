//! Sparse LU (faer): a fill-reducing column ordering computed once per sparsity
//! pattern, then a left-looking (Gilbert–Peierls) numeric LU with partial pivoting per
//! factorization, into storage that is reused.

use faer::dyn_stack::StackReq;
use faer::perm::PermRef;
use faer::sparse::linalg::colamd;
use faer::sparse::linalg::lu::simplicial::{self, SimplicialLu};
use faer::sparse::linalg::LuError;
use faer::sparse::{SparseColMat, SparseColMatRef};
use faer::{Conj, MatMut, Par};

use super::scratch::Scratch;
use super::{check_pivots, check_solve, LinearSolveError, DEFAULT_PIVOT_THRESHOLD};
use crate::{Factorize, LinearSolve};

/// Entry `(j, j)` of a column-compressed matrix (rows of a column unsorted allowed), `None`
/// when it is not stored.
pub fn diagonal_entry<T: Copy>(m: SparseColMatRef<'_, usize, T>, j: usize) -> Option<T> {
    m.row_idx_of_col_raw(j)
        .iter()
        .zip(m.val_of_col(j))
        .find(|(&i, _)| i == j)
        .map(|(_, &v)| v)
}

/// faer sparse LU for [`SparseColMat<usize, f64>`]: `P A Q = L U` with a COLAMD column
/// ordering `Q` and partial row pivoting `P`.
///
/// - **Symbolic analysis explicit and cached.** The column ordering is computed by
///   [`FaerSparseLu::analyze`], or by the first [`factor`](Factorize::factor) of a new
///   dimension, and reused by every later factorization: `factor` does not compare
///   patterns. An ordering computed for another pattern is still a valid column
///   permutation (the row pivoting keeps the factorization correct), only possibly a
///   worse one for fill: call `analyze` when the pattern changes for good.
///   [`FaerSparseLu::symbolic_analyses`] counts the orderings computed.
/// - **Numeric refactorization per `factor`** into the factor storage of the previous
///   call (it grows only if the fill grows), so repeated factorizations of one pattern
///   allocate nothing once the storage has settled.
/// - **Singularity is detected**: faer's sparse LU reports only structural
///   singularity; the diagonal of `U` is scanned against the same relative threshold as
///   the dense solvers ([`LinearSolveError::Singular`]).
///
/// The simplicial (column-by-column) variant of faer's sparse LU is used because its
/// factors are accessible for the pivot check; it is the efficient variant for the
/// banded and block-structured matrices of this crate, less so for 2-D/3-D meshes.
///
/// ```
/// use faer::sparse::{SparseColMat, Triplet};
/// use semismooth::linalg::FaerSparseLu;
/// use semismooth::{Factorize, LinearSolve};
/// // Tridiagonal [2 -1 0; -1 2 -1; 0 -1 2] times [1, 1, 1] = [1, 0, 1].
/// let t = [(0, 0, 2.0), (1, 0, -1.0), (0, 1, -1.0), (1, 1, 2.0), (2, 1, -1.0), (1, 2, -1.0), (2, 2, 2.0)];
/// let triplets: Vec<_> = t.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
/// let a = SparseColMat::<usize, f64>::try_new_from_triplets(3, 3, &triplets).unwrap();
/// let mut lu = FaerSparseLu::new();
/// lu.factor(&a).unwrap();
/// let mut x = [1.0, 0.0, 1.0];
/// lu.solve_in_place(&mut x).unwrap();
/// assert!(x.iter().all(|xi| (xi - 1.0).abs() < 1e-14));
/// ```
#[derive(Debug)]
pub struct FaerSparseLu {
    dim: usize,
    col_perm_fwd: Vec<usize>,
    col_perm_inv: Vec<usize>,
    row_perm_fwd: Vec<usize>,
    row_perm_inv: Vec<usize>,
    lu: SimplicialLu<usize, f64>,
    scratch: Scratch,
    analyzed: bool,
    factored: bool,
    pivot_threshold: f64,
    symbolic_analyses: u64,
}

impl FaerSparseLu {
    /// A solver with the default pivot threshold [`DEFAULT_PIVOT_THRESHOLD`].
    pub fn new() -> Self {
        Self {
            dim: 0,
            col_perm_fwd: Vec::new(),
            col_perm_inv: Vec::new(),
            row_perm_fwd: Vec::new(),
            row_perm_inv: Vec::new(),
            lu: SimplicialLu::new(),
            scratch: Scratch::new(),
            analyzed: false,
            factored: false,
            pivot_threshold: DEFAULT_PIVOT_THRESHOLD,
            symbolic_analyses: 0,
        }
    }

    /// A solver that treats `|u_ii| <= threshold * max |u_jj|` as a zero pivot.
    pub fn with_pivot_threshold(threshold: f64) -> Self {
        Self {
            pivot_threshold: threshold,
            ..Self::new()
        }
    }

    /// How many symbolic analyses (column orderings) have been computed: 1 for any
    /// number of factorizations of matrices sharing one sparsity pattern.
    pub fn symbolic_analyses(&self) -> u64 {
        self.symbolic_analyses
    }

    /// Computes the fill-reducing column ordering of `a`'s sparsity pattern, used by the
    /// following factorizations (square matrices only).
    pub fn analyze(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), LinearSolveError> {
        let s = a.symbolic();
        let (n, ncols) = (s.nrows(), s.ncols());
        if n != ncols {
            return Err(LinearSolveError::DimensionMismatch {
                expected: n,
                found: ncols,
            });
        }
        self.analyzed = false;
        self.factored = false;
        self.col_perm_fwd.resize(n, 0);
        self.col_perm_inv.resize(n, 0);
        self.row_perm_fwd.resize(n, 0);
        self.row_perm_inv.resize(n, 0);
        let req = colamd::order_scratch::<usize>(n, n, s.compute_nnz());
        let stack = self.scratch.stack(req)?;
        colamd::order(
            &mut self.col_perm_fwd,
            &mut self.col_perm_inv,
            s,
            colamd::Control::default(),
            stack,
        )
        .map_err(|e| LinearSolveError::from_faer(e, "ordering the columns"))?;
        self.dim = n;
        self.analyzed = true;
        self.symbolic_analyses += 1;
        Ok(())
    }
}

impl Default for FaerSparseLu {
    fn default() -> Self {
        Self::new()
    }
}

impl Factorize<SparseColMat<usize, f64>> for FaerSparseLu {
    /// Factors `a` (square), analysing its pattern first when no analysis of this
    /// dimension is cached. Errors: [`LinearSolveError::DimensionMismatch`] for a
    /// non-square matrix, [`LinearSolveError::NonFiniteEntry`],
    /// [`LinearSolveError::Singular`] for a structurally singular matrix (then `pivot`
    /// is 0 and `max_pivot` is the largest absolute entry of `a`, the pivots not being
    /// available) or a negligible pivot, [`LinearSolveError::OutOfMemory`]. After an
    /// error the solver is unfactored.
    fn factor(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), LinearSolveError> {
        self.factored = false;
        let (nrows, ncols) = (a.nrows(), a.ncols());
        if nrows != ncols {
            return Err(LinearSolveError::DimensionMismatch {
                expected: nrows,
                found: ncols,
            });
        }
        let mut max_entry = 0.0_f64;
        for col in 0..ncols {
            for (&row, &value) in a.row_idx_of_col_raw(col).iter().zip(a.val_of_col(col)) {
                if !value.is_finite() {
                    return Err(LinearSolveError::NonFiniteEntry { row, col, value });
                }
                max_entry = max_entry.max(value.abs());
            }
        }
        if !self.analyzed || self.dim != nrows {
            self.analyze(a)?;
        }
        let n = self.dim;
        let req = StackReq::or(
            simplicial::factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n),
            simplicial::solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq),
        );
        let stack = self.scratch.stack(req)?;
        let col_perm = PermRef::new_checked(&self.col_perm_fwd, &self.col_perm_inv, n);
        let result = simplicial::factorize_simplicial_numeric_lu(
            &mut self.row_perm_fwd,
            &mut self.row_perm_inv,
            &mut self.lu,
            a.as_ref(),
            col_perm,
            stack,
        );
        match result {
            Ok(()) => {}
            Err(LuError::SymbolicSingular { index }) => {
                return Err(LinearSolveError::Singular {
                    index,
                    pivot: 0.0,
                    max_pivot: max_entry,
                })
            }
            Err(LuError::Generic(e)) => {
                return Err(LinearSolveError::from_faer(e, "factoring a sparse matrix"))
            }
        }
        let u = self.lu.u_factor_unsorted();
        let diagonal = (0..n).map(|j| diagonal_entry(u, j).unwrap_or(0.0));
        check_pivots(diagonal, self.pivot_threshold)?;
        self.factored = true;
        Ok(())
    }
}

impl LinearSolve for FaerSparseLu {
    /// Overwrites `rhs` with `A^{-1} rhs` using the last successful factorization.
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        let n = self.dim;
        check_solve(self.factored, n, rhs.len())?;
        let req = simplicial::solve_in_place_scratch::<usize, f64>(n, 1, Par::Seq);
        let stack = self.scratch.stack(req)?;
        let row_perm = PermRef::new_checked(&self.row_perm_fwd, &self.row_perm_inv, n);
        let col_perm = PermRef::new_checked(&self.col_perm_fwd, &self.col_perm_inv, n);
        self.lu.solve_in_place_with_conj(
            row_perm,
            col_perm,
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            stack,
        );
        Ok(())
    }
}
