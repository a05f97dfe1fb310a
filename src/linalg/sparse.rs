//! Sparse LU (faer), real or complex: a fill-reducing column ordering computed once per
//! sparsity pattern, then a left-looking (Gilbert–Peierls) numeric LU with partial pivoting
//! per factorization, into storage that is reused.

use faer::dyn_stack::StackReq;
use faer::perm::Perm;
use faer::sparse::linalg::colamd;
use faer::sparse::linalg::lu::simplicial::{self, SimplicialLu};
use faer::sparse::linalg::LuError;
use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMatRef};
use faer::traits::ComplexField;
use faer::{c64, Conj, MatMut, Par};

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

mod sealed {
    pub trait Sealed {}
    impl Sealed for f64 {}
    impl Sealed for faer::c64 {}
}

/// The scalars [`SparseLu`] factors: `f64` and [`faer::c64`].
pub trait LuScalar: ComplexField + Copy + std::fmt::Debug + sealed::Sealed {
    /// `|x|`.
    fn modulus(self) -> f64;
    /// `|x|^2` (no square root).
    fn modulus_squared(self) -> f64;
    /// The number an error reports for an entry: `x` itself when real, `|x|` when complex.
    fn reported(self) -> f64;
}

impl LuScalar for f64 {
    fn modulus(self) -> f64 {
        self.abs()
    }

    fn modulus_squared(self) -> f64 {
        self * self
    }

    fn reported(self) -> f64 {
        self
    }
}

impl LuScalar for c64 {
    fn modulus(self) -> f64 {
        self.norm()
    }

    fn modulus_squared(self) -> f64 {
        self.norm_sqr()
    }

    fn reported(self) -> f64 {
        self.norm()
    }
}

/// When [`SparseLu`] reports a factorization as singular ([`LinearSolveError::Singular`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum PivotRule {
    /// The rule of the other solvers of this module: the entries of the matrix are checked
    /// first ([`LinearSolveError::NonFiniteEntry`]), then a pivot with
    /// `|u_ii| <= threshold * max_j |u_jj|` (zero or not finite included) is singular.
    /// A structurally singular matrix reports the largest absolute entry as `max_pivot`.
    Relative(f64),
    /// Only a breakdown of the LU: a pivot whose squared modulus is zero or not finite (no
    /// square root per pivot); the entries are not scanned and a merely small pivot is
    /// accepted. For matrices whose closeness to singularity the caller judges itself
    /// (e.g. a dynamic stiffness near an undamped resonance, whose condensed systems have
    /// their own relative checks). `pivot` and `max_pivot` of the error are squared moduli;
    /// a structurally singular matrix has `max_pivot` NaN.
    Breakdown,
}

impl Default for PivotRule {
    /// [`PivotRule::Relative`] with [`DEFAULT_PIVOT_THRESHOLD`].
    fn default() -> Self {
        Self::Relative(DEFAULT_PIVOT_THRESHOLD)
    }
}

/// The row permutation of a slot: validated once per factorization (so that solves need not
/// check it again), or its storage while unfactored.
#[derive(Debug)]
enum RowPerm {
    Factored(Perm<usize>),
    Unfactored(Box<[usize]>, Box<[usize]>),
}

impl RowPerm {
    /// The permutation's storage, resized to `n` (allocates only when the size changes).
    fn storage(self, n: usize) -> (Box<[usize]>, Box<[usize]>) {
        let (fwd, inv) = match self {
            RowPerm::Factored(perm) => perm.into_arrays(),
            RowPerm::Unfactored(fwd, inv) => (fwd, inv),
        };
        if fwd.len() == n && inv.len() == n {
            return (fwd, inv);
        }
        (vec![0; n].into_boxed_slice(), vec![0; n].into_boxed_slice())
    }
}

/// One numeric LU: row permutation and factors.
#[derive(Debug)]
struct Slot<T: LuScalar> {
    row_perm: RowPerm,
    lu: SimplicialLu<usize, T>,
}

impl<T: LuScalar> Slot<T> {
    fn new() -> Self {
        Self {
            row_perm: RowPerm::Unfactored(Box::default(), Box::default()),
            lu: SimplicialLu::new(),
        }
    }

    /// Unfactored, with row-permutation storage of size `n`.
    fn reset(&mut self, n: usize) {
        let empty = RowPerm::Unfactored(Box::default(), Box::default());
        let (fwd, inv) = std::mem::replace(&mut self.row_perm, empty).storage(n);
        self.row_perm = RowPerm::Unfactored(fwd, inv);
    }
}

/// faer sparse LU of a [`SparseColMat<usize, T>`] (`T` = `f64` or [`faer::c64`]):
/// `P A Q = L U` with a COLAMD column ordering `Q` and partial row pivoting `P`.
///
/// - **Symbolic analysis explicit and cached.** The column ordering is computed by
///   [`SparseLu::analyze`] (or [`SparseLu::analyze_pattern`]), or by the first
///   factorization of a new dimension, and reused by every later factorization: a
///   factorization does not compare patterns. An ordering computed for another pattern is
///   still a valid column permutation (the row pivoting keeps the factorization correct),
///   only possibly a worse one for fill: analyse again when the pattern changes for good.
///   [`SparseLu::symbolic_analyses`] counts the orderings computed.
/// - **Numeric refactorization per factorization** into the factor storage of the previous
///   one (it grows only if the fill grows), so repeated factorizations of one pattern
///   allocate nothing once the storage has settled; nor do solves, the scratch memory
///   being sized when the pattern is analysed.
/// - **Singularity is detected**: faer's sparse LU reports only structural singularity;
///   the diagonal of `U` is scanned by the [`PivotRule`] (by default the same relative
///   threshold as the dense solvers). The `index` of [`LinearSolveError::Singular`] is the
///   pivot's position in the factorization ([`SparseLu::pivot_column`] gives its column).
/// - **Slots**: [`SparseLu::with_slots`] keeps several numeric factorizations of matrices
///   of one pattern (e.g. one per frequency of a dynamic stiffness), sharing the column
///   ordering and the scratch memory ([`SparseLu::factor_slot`],
///   [`SparseLu::solve_slot_in_place`]); [`Factorize`] and [`LinearSolve`] use slot 0.
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
///
/// Complex matrices, two factorizations of one pattern:
///
/// ```
/// use faer::sparse::{SparseColMat, Triplet};
/// use faer::{c64, Mat};
/// use semismooth::linalg::SparseLu;
/// let z = |d: c64| {
///     let t = [(0, 0, d), (1, 0, c64::new(-1.0, 0.0)), (0, 1, c64::new(-1.0, 0.0)), (1, 1, d)];
///     let t: Vec<_> = t.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
///     SparseColMat::<usize, c64>::try_new_from_triplets(2, 2, &t).unwrap()
/// };
/// let mut lu = SparseLu::<c64>::new().with_slots(2);
/// lu.factor_slot(0, z(c64::new(2.0, 1.0)).as_ref()).unwrap();
/// lu.factor_slot(1, z(c64::new(3.0, 0.0)).as_ref()).unwrap();
/// assert_eq!(lu.symbolic_analyses(), 1);
/// // [3 -1; -1 3] [1, 1] = [2, 2].
/// let mut x = Mat::<c64>::from_fn(2, 1, |_, _| c64::new(2.0, 0.0));
/// lu.solve_slot_in_place(1, x.as_mut()).unwrap();
/// assert!((x[(0, 0)] - c64::new(1.0, 0.0)).norm() < 1e-15);
/// ```
#[derive(Debug)]
pub struct SparseLu<T: LuScalar = f64> {
    dim: usize,
    /// The column ordering, `None` until a pattern is analysed.
    col_perm: Option<Perm<usize>>,
    slots: Vec<Slot<T>>,
    scratch: Scratch,
    rule: PivotRule,
    /// Right-hand sides solved at once (wider blocks are split).
    solve_columns: usize,
    symbolic_analyses: u64,
}

/// The real sparse LU, [`SparseLu<f64>`]: a [`Factorize`] and [`LinearSolve`] for
/// [`SparseColMat<usize, f64>`] Jacobians.
pub type FaerSparseLu = SparseLu<f64>;

impl<T: LuScalar> SparseLu<T> {
    /// A solver with one slot, the default pivot rule ([`PivotRule::Relative`] with
    /// [`DEFAULT_PIVOT_THRESHOLD`]) and solves of one right-hand side at a time.
    pub fn new() -> Self {
        Self {
            dim: 0,
            col_perm: None,
            slots: vec![Slot::new()],
            scratch: Scratch::new(),
            rule: PivotRule::default(),
            solve_columns: 1,
            symbolic_analyses: 0,
        }
    }

    /// A solver that treats `|u_ii| <= threshold * max |u_jj|` as a zero pivot.
    pub fn with_pivot_threshold(threshold: f64) -> Self {
        Self::new().with_pivot_rule(PivotRule::Relative(threshold))
    }

    /// The same solver with the pivot rule `rule`.
    pub fn with_pivot_rule(mut self, rule: PivotRule) -> Self {
        self.rule = rule;
        self
    }

    /// The same solver with `slots` numeric factorizations (at least 1), unfactored.
    pub fn with_slots(mut self, slots: usize) -> Self {
        let n = self.dim;
        self.slots = (0..slots.max(1))
            .map(|_| {
                let mut slot = Slot::new();
                slot.reset(n);
                slot
            })
            .collect();
        self
    }

    /// The same solver with scratch memory for solves of `columns` right-hand sides at once
    /// (at least 1; wider blocks are solved `columns` at a time).
    pub fn with_solve_columns(mut self, columns: usize) -> Self {
        self.solve_columns = columns.max(1);
        self
    }

    /// Dimension of the last analysed matrix.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// Number of slots (numeric factorizations kept).
    pub fn slots(&self) -> usize {
        self.slots.len()
    }

    /// How many symbolic analyses (column orderings) have been computed: 1 for any
    /// number of factorizations of matrices sharing one sparsity pattern.
    pub fn symbolic_analyses(&self) -> u64 {
        self.symbolic_analyses
    }

    /// The column of the factored matrix whose pivot is at position `index` of the
    /// factorization (the `index` of [`LinearSolveError::Singular`]); `index` itself before
    /// any analysis or out of range.
    pub fn pivot_column(&self, index: usize) -> usize {
        self.col_perm
            .as_ref()
            .and_then(|p| p.arrays().0.get(index).copied())
            .unwrap_or(index)
    }

    /// Computes the fill-reducing column ordering of `a`'s sparsity pattern, used by the
    /// following factorizations (square matrices only). Every slot is then unfactored.
    pub fn analyze(&mut self, a: &SparseColMat<usize, T>) -> Result<(), LinearSolveError> {
        self.analyze_pattern(a.symbolic())
    }

    /// [`SparseLu::analyze`] of a sparsity pattern.
    pub fn analyze_pattern(
        &mut self,
        pattern: SymbolicSparseColMatRef<'_, usize>,
    ) -> Result<(), LinearSolveError> {
        let (n, ncols) = (pattern.nrows(), pattern.ncols());
        if n != ncols {
            return Err(LinearSolveError::DimensionMismatch {
                expected: n,
                found: ncols,
            });
        }
        for slot in &mut self.slots {
            slot.reset(n);
        }
        let (mut fwd, mut inv) = match self.col_perm.take() {
            Some(perm) => {
                let (fwd, inv) = perm.into_arrays();
                (Vec::from(fwd), Vec::from(inv))
            }
            None => (Vec::new(), Vec::new()),
        };
        fwd.resize(n, 0);
        inv.resize(n, 0);
        let req = colamd::order_scratch::<usize>(n, n, pattern.compute_nnz());
        let stack = self.scratch.stack(req)?;
        colamd::order(
            &mut fwd,
            &mut inv,
            pattern,
            colamd::Control::default(),
            stack,
        )
        .map_err(|e| LinearSolveError::from_faer(e, "ordering the columns"))?;
        self.col_perm = Some(Perm::new_checked(
            fwd.into_boxed_slice(),
            inv.into_boxed_slice(),
            n,
        ));
        self.dim = n;
        self.symbolic_analyses += 1;
        // Sized now, so that neither factorizations nor solves allocate scratch later.
        self.scratch.stack(StackReq::or(
            simplicial::factorize_simplicial_numeric_lu_scratch::<usize, T>(n, n),
            simplicial::solve_in_place_scratch::<usize, T>(n, self.solve_columns, Par::Seq),
        ))?;
        Ok(())
    }

    /// Factors `a` (square) into `slot`, analysing its pattern first when no analysis of
    /// this dimension is cached. Errors: [`LinearSolveError::NotFactored`] for a slot out of
    /// range, [`LinearSolveError::DimensionMismatch`] for a non-square matrix,
    /// [`LinearSolveError::NonFiniteEntry`] (with [`PivotRule::Relative`]; a complex entry
    /// reports its modulus), [`LinearSolveError::Singular`] for a structurally singular matrix
    /// (then `pivot` is 0) or a pivot the [`PivotRule`] rejects,
    /// [`LinearSolveError::OutOfMemory`]. After an error the slot is unfactored.
    pub fn factor_slot(
        &mut self,
        slot: usize,
        a: SparseColMatRef<'_, usize, T>,
    ) -> Result<(), LinearSolveError> {
        if slot >= self.slots.len() {
            return Err(LinearSolveError::NotFactored);
        }
        let (nrows, ncols) = (a.nrows(), a.ncols());
        if nrows != ncols {
            self.slots[slot].reset(self.dim);
            return Err(LinearSolveError::DimensionMismatch {
                expected: nrows,
                found: ncols,
            });
        }
        // The largest absolute entry (the `max_pivot` of a structurally singular matrix).
        let max_entry = match self.rule {
            PivotRule::Relative(_) => match max_finite_entry(a) {
                Ok(max) => max,
                Err(e) => {
                    self.slots[slot].reset(self.dim);
                    return Err(e);
                }
            },
            PivotRule::Breakdown => f64::NAN,
        };
        if self.col_perm.is_none() || self.dim != nrows {
            self.analyze_pattern(a.symbolic())?;
        }
        let n = self.dim;
        let Some(col_perm) = self.col_perm.as_ref() else {
            return Err(LinearSolveError::NotFactored);
        };
        let s = &mut self.slots[slot];
        let empty = RowPerm::Unfactored(Box::default(), Box::default());
        let (mut fwd, mut inv) = std::mem::replace(&mut s.row_perm, empty).storage(n);
        let req = simplicial::factorize_simplicial_numeric_lu_scratch::<usize, T>(n, n);
        let result = match self.scratch.stack(req) {
            Ok(stack) => simplicial::factorize_simplicial_numeric_lu(
                &mut fwd,
                &mut inv,
                &mut s.lu,
                a,
                col_perm.as_ref(),
                stack,
            ),
            Err(e) => {
                s.row_perm = RowPerm::Unfactored(fwd, inv);
                return Err(e);
            }
        };
        let checked = match result {
            Ok(()) => {
                let u = s.lu.u_factor_unsorted();
                let diagonal = |j| diagonal_entry(u, j);
                match self.rule {
                    PivotRule::Relative(threshold) => check_pivots(
                        (0..n).map(|j| diagonal(j).map_or(0.0, T::modulus)),
                        threshold,
                    ),
                    PivotRule::Breakdown => check_pivots(
                        (0..n).map(|j| diagonal(j).map_or(0.0, T::modulus_squared)),
                        0.0,
                    ),
                }
            }
            Err(LuError::SymbolicSingular { index }) => Err(LinearSolveError::Singular {
                index,
                pivot: 0.0,
                max_pivot: max_entry,
            }),
            Err(LuError::Generic(e)) => {
                Err(LinearSolveError::from_faer(e, "factoring a sparse matrix"))
            }
        };
        s.row_perm = match checked {
            Ok(()) => RowPerm::Factored(Perm::new_checked(fwd, inv, n)),
            Err(_) => RowPerm::Unfactored(fwd, inv),
        };
        checked
    }

    /// `rhs <- A^{-1} rhs` with the factorization in `slot` (`rhs` has `N` rows and any
    /// number of columns).
    pub fn solve_slot_in_place(
        &mut self,
        slot: usize,
        mut rhs: MatMut<'_, T>,
    ) -> Result<(), LinearSolveError> {
        let n = self.dim;
        let (
            Some(col_perm),
            Some(Slot {
                row_perm: RowPerm::Factored(row_perm),
                lu,
            }),
        ) = (self.col_perm.as_ref(), self.slots.get(slot))
        else {
            return Err(LinearSolveError::NotFactored);
        };
        check_solve(true, n, rhs.nrows())?;
        let mut start = 0;
        while start < rhs.ncols() {
            let width = self.solve_columns.min(rhs.ncols() - start);
            let req = simplicial::solve_in_place_scratch::<usize, T>(n, width, Par::Seq);
            lu.solve_in_place_with_conj(
                row_perm.as_ref(),
                col_perm.as_ref(),
                Conj::No,
                rhs.as_mut().subcols_mut(start, width),
                Par::Seq,
                self.scratch.stack(req)?,
            );
            start += width;
        }
        Ok(())
    }
}

/// The largest absolute entry of `a`, or `Err(NonFiniteEntry)` with the first entry (column
/// by column) that is not finite.
fn max_finite_entry<T: LuScalar>(
    a: SparseColMatRef<'_, usize, T>,
) -> Result<f64, LinearSolveError> {
    let mut max_entry = 0.0_f64;
    for col in 0..a.ncols() {
        for (&row, &value) in a.row_idx_of_col_raw(col).iter().zip(a.val_of_col(col)) {
            let modulus = value.modulus();
            if !modulus.is_finite() {
                return Err(LinearSolveError::NonFiniteEntry {
                    row,
                    col,
                    value: value.reported(),
                });
            }
            max_entry = max_entry.max(modulus);
        }
    }
    Ok(max_entry)
}

impl<T: LuScalar> Default for SparseLu<T> {
    fn default() -> Self {
        Self::new()
    }
}

impl Factorize<SparseColMat<usize, f64>> for SparseLu<f64> {
    /// Factors `a` (square) into slot 0 ([`SparseLu::factor_slot`]).
    fn factor(&mut self, a: &SparseColMat<usize, f64>) -> Result<(), LinearSolveError> {
        self.factor_slot(0, a.as_ref())
    }
}

impl LinearSolve for SparseLu<f64> {
    /// Overwrites `rhs` with `A^{-1} rhs` using the factorization in slot 0.
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        let factored = matches!(
            self.slots.first(),
            Some(Slot {
                row_perm: RowPerm::Factored(_),
                ..
            })
        );
        check_solve(factored, self.dim, rhs.len())?;
        let n = self.dim;
        self.solve_slot_in_place(0, MatMut::from_column_major_slice_mut(rhs, n, 1))
    }
}
