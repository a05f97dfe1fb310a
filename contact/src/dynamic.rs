//! Linear combinations of the model matrices over their union sparsity pattern, and the
//! complex dynamic stiffness `Z = K + a M + b D` factored for many coefficient pairs.
//!
//! Harmonic balance factors `Z_k = K - (k w)^2 M + i k w D` for each harmonic `k` and the
//! periodic LCP `Z_k = K + s_k^2 M + s_k D` (`s_k` the Tustin frequency of DFT bin `k`);
//! time marching combines `K`, `D` and `M` with real coefficients. All share one pattern:
//!
//! - [`UnionPattern`]: the union of the patterns of the source matrices and of the diagonal
//!   (so that the LU can pivot on it), with the position of every stored entry of every
//!   source in it, computed once; a combination `sum_i c_i A_i` is then a fill of the value
//!   array in source order (`O(nnz)`, no search, no allocation).
//! - [`DynamicStiffness`]: the core's complex sparse LU ([`SparseLu<c64>`]: a fill-reducing
//!   column ordering of that pattern computed once, then a numeric LU with partial pivoting
//!   per coefficient pair into one of a fixed number of slots whose storage is reused, and
//!   solves with scratch memory sized once).
//!
//! **Singularity.** A factorization is rejected ([`LinearSolveError::Singular`], carrying
//! the original column of the pivot, the pivot and the largest pivot, both squared moduli)
//! when faer finds no pivot for a column (structural singularity) or a pivot of `U` is zero
//! or not finite ([`PivotRule::Breakdown`]): the LU broke down and its solves would be
//! infinite or NaN. A merely small pivot (an undamped resonance) is accepted: the callers'
//! condensed systems have their own, relative, pivot checks, and the contact may keep the
//! whole Jacobian regular where the linear part alone is singular.

use std::ops::{AddAssign, Mul};

use faer::sparse::{SparseColMat, SparseColMatRef, SymbolicSparseColMat};
use faer::{c64, MatMut};
use num_traits::Zero;
use semismooth::linalg::{LinearSolveError, PivotRule, SparseLu};

use crate::model::SparseMatrix;

/// The union sparsity pattern of `N x N` source matrices and the diagonal, with the
/// position in it of every stored entry of every source.
#[derive(Debug, Clone)]
pub(crate) struct UnionPattern {
    symbolic: SymbolicSparseColMat<usize>,
    /// `positions[s][p]`: where the entry at storage index `p` of source `s` lies.
    positions: Vec<Vec<usize>>,
}

impl UnionPattern {
    /// The union of the patterns of `sources` (all `n x n`, checked by the caller) and of
    /// the diagonal.
    pub(crate) fn new(n: usize, sources: &[&SparseMatrix]) -> Self {
        let mut col_ptr = Vec::with_capacity(n + 1);
        col_ptr.push(0);
        let mut row_idx = Vec::new();
        let mut positions: Vec<Vec<usize>> =
            sources.iter().map(|a| vec![0; a.val().len()]).collect();
        // Column j: (row, source, storage index) for every source entry, and the diagonal.
        let mut column: Vec<(usize, usize, usize)> = Vec::new();
        for j in 0..n {
            column.clear();
            column.push((j, usize::MAX, 0));
            for (s, a) in sources.iter().enumerate() {
                let symbolic = a.symbolic();
                for p in symbolic.col_range(j) {
                    column.push((symbolic.row_idx()[p], s, p));
                }
            }
            column.sort_unstable();
            for &(i, s, p) in &column {
                if row_idx.len() == *col_ptr.last().unwrap_or(&0) || row_idx.last() != Some(&i) {
                    row_idx.push(i);
                }
                if let Some(source) = positions.get_mut(s) {
                    source[p] = row_idx.len() - 1;
                }
            }
            col_ptr.push(row_idx.len());
        }
        Self {
            symbolic: SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx),
            positions,
        }
    }

    /// Number of stored entries of the union.
    pub(crate) fn nnz(&self) -> usize {
        self.symbolic.row_idx().len()
    }

    /// `values <- sum_s c_s A_s` in the union's storage order for the pairs `(A_s, c_s)`, the
    /// sources in the order given to [`UnionPattern::new`] (`values` of length
    /// [`UnionPattern::nnz`]; the terms are added source by source).
    pub(crate) fn combine<'a, T>(
        &self,
        terms: impl IntoIterator<Item = (&'a SparseMatrix, T)>,
        values: &mut [T],
    ) where
        T: Copy + Zero + AddAssign + Mul<f64, Output = T>,
    {
        values.fill(T::zero());
        // `positions` follows each source's storage order (its columns one after the other).
        for ((a, c), positions) in terms.into_iter().zip(&self.positions) {
            for (&p, &v) in positions.iter().zip(a.val()) {
                values[p] += c * v;
            }
        }
    }

    /// The matrix of the union pattern with the given values (length [`UnionPattern::nnz`]).
    pub(crate) fn matrix<'a, T>(&'a self, values: &'a [T]) -> SparseColMatRef<'a, usize, T> {
        SparseColMatRef::new(self.symbolic.as_ref(), values)
    }

    /// `sum_s coefficients[s] sources[s]` as a new real matrix (the union pattern).
    pub(crate) fn linear_combination(
        n: usize,
        sources: &[&SparseMatrix],
        coefficients: &[f64],
    ) -> SparseMatrix {
        let pattern = Self::new(n, sources);
        let mut values = vec![0.0; pattern.nnz()];
        let terms = sources.iter().copied().zip(coefficients.iter().copied());
        pattern.combine(terms, &mut values);
        SparseColMat::new(pattern.symbolic, values)
    }
}

/// `Z = K + a M + b D` (complex `a`, `b`) over the union pattern of `K`, `M`, `D`: column
/// ordering once, numeric LU per coefficient pair into one of `slots` reusable slots
/// (module documentation).
pub(crate) struct DynamicStiffness {
    pattern: UnionPattern,
    /// `[K, M, D]` (`D` absent without damping).
    sources: Vec<SparseMatrix>,
    values: Vec<c64>,
    lu: SparseLu<c64>,
}

impl std::fmt::Debug for DynamicStiffness {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DynamicStiffness")
            .field("n", &self.lu.dim())
            .field("nnz", &self.pattern.nnz())
            .field("slots", &self.lu.slots())
            .finish_non_exhaustive()
    }
}

impl DynamicStiffness {
    /// The pattern of `K`, `M`, `D` (all `N x N`, checked by the caller), its column
    /// ordering, `slots` empty factorizations and scratch for solves of up to `max_columns`
    /// right-hand sides at once.
    pub(crate) fn new(
        stiffness: &SparseMatrix,
        mass: &SparseMatrix,
        damping: Option<&SparseMatrix>,
        slots: usize,
        max_columns: usize,
    ) -> Result<Self, LinearSolveError> {
        let mut sources = vec![stiffness.clone(), mass.clone()];
        sources.extend(damping.cloned());
        Self::with_sources(sources, slots, max_columns)
    }

    /// `Z = sum_s c_s A_s` over any `N x N` sources (the first one `K`; all checked by the
    /// caller), factored per coefficient list with [`DynamicStiffness::factor_combination`].
    pub(crate) fn with_sources(
        sources: Vec<SparseMatrix>,
        slots: usize,
        max_columns: usize,
    ) -> Result<Self, LinearSolveError> {
        let n = sources[0].nrows();
        let refs: Vec<&SparseMatrix> = sources.iter().collect();
        let pattern = UnionPattern::new(n, &refs);
        let mut lu = SparseLu::new()
            .with_pivot_rule(PivotRule::Breakdown)
            .with_slots(slots)
            .with_solve_columns(max_columns);
        lu.analyze_pattern(pattern.symbolic.as_ref())?;
        Ok(Self {
            values: vec![c64::new(0.0, 0.0); pattern.nnz()],
            pattern,
            sources,
            lu,
        })
    }

    /// Factors `K + mass M + damping D` into `slot` (`< slots`). A breakdown (module
    /// documentation) is [`LinearSolveError::Singular`] with the original column of the
    /// failing pivot as its index; the slot is then unfactored.
    pub(crate) fn factor(
        &mut self,
        slot: usize,
        mass: c64,
        damping: c64,
    ) -> Result<(), LinearSolveError> {
        self.factor_combination(slot, &[c64::new(1.0, 0.0), mass, damping])
    }

    /// Factors `sum_s coefficients[s] A_s` (the sources in their order) into `slot`, with
    /// the breakdown of [`DynamicStiffness::factor`].
    pub(crate) fn factor_combination(
        &mut self,
        slot: usize,
        coefficients: &[c64],
    ) -> Result<(), LinearSolveError> {
        self.pattern.combine(
            self.sources.iter().zip(coefficients.iter().copied()),
            &mut self.values,
        );
        match self.lu.factor_slot(slot, self.pattern.matrix(&self.values)) {
            // The pivot's position in the factorization is a column of the ordering.
            Err(LinearSolveError::Singular {
                index,
                pivot,
                max_pivot,
            }) => Err(LinearSolveError::Singular {
                index: self.lu.pivot_column(index),
                pivot,
                max_pivot,
            }),
            other => other,
        }
    }

    /// `rhs <- Z^{-1} rhs` with the factorization in `slot` (`rhs` has `N` rows).
    pub(crate) fn solve_in_place(
        &mut self,
        slot: usize,
        rhs: MatMut<'_, c64>,
    ) -> Result<(), LinearSolveError> {
        self.lu.solve_slot_in_place(slot, rhs)
    }

    /// `y += (a K + b M + c D) x` for complex vectors (`x`, `y` of length `N`), the values
    /// assembled into `values` (resized to the pattern; no allocation once it has been).
    pub(crate) fn mul_add(
        &self,
        coefficients: [c64; 3],
        values: &mut Vec<c64>,
        x: &[c64],
        y: &mut [c64],
    ) {
        values.resize(self.pattern.nnz(), c64::new(0.0, 0.0));
        self.pattern
            .combine(self.sources.iter().zip(coefficients), values);
        crate::model::sparse_mul_add(self.pattern.matrix(values), c64::new(1.0, 0.0), x, y);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;
    use faer::Mat;

    fn sparse(n: usize, entries: &[(usize, usize, f64)]) -> SparseMatrix {
        let t: Vec<_> = entries
            .iter()
            .map(|&(i, j, v)| Triplet::new(i, j, v))
            .collect();
        SparseMatrix::try_new_from_triplets(n, n, &t).unwrap()
    }

    #[test]
    fn union_pattern_combines_in_place() {
        // K has no (2, 2) entry: the union adds the diagonal.
        let k = sparse(3, &[(0, 0, 2.0), (1, 0, -1.0), (0, 1, -1.0), (1, 1, 2.0)]);
        let m = sparse(3, &[(0, 0, 1.0), (2, 2, 3.0), (2, 0, 0.5)]);
        let sum = UnionPattern::linear_combination(3, &[&k, &m], &[2.0, -1.0]);
        let dense = |a: &SparseMatrix| {
            let mut d = Mat::<f64>::zeros(3, 3);
            let r = a.as_ref();
            for j in 0..3 {
                for (i, v) in r.row_idx_of_col(j).zip(r.val_of_col(j)) {
                    d[(i, j)] += v;
                }
            }
            d
        };
        let expected = dense(&k) * 2.0 - dense(&m);
        assert_eq!(dense(&sum), expected);
        assert_eq!(sum.compute_nnz(), 6);
    }

    #[test]
    fn dynamic_stiffness_solves_and_reports_breakdown() {
        // K = tridiag(-1, 2, -1), M = I, D = 0.1 K on 4 dofs.
        let mut t = Vec::new();
        for i in 0..4 {
            t.push((i, i, 2.0));
            if i + 1 < 4 {
                t.push((i, i + 1, -1.0));
                t.push((i + 1, i, -1.0));
            }
        }
        let k = sparse(4, &t);
        let m = sparse(4, &(0..4).map(|i| (i, i, 1.0)).collect::<Vec<_>>());
        let d = sparse(
            4,
            &t.iter()
                .map(|&(i, j, v)| (i, j, 0.1 * v))
                .collect::<Vec<_>>(),
        );
        let mut z = DynamicStiffness::new(&k, &m, Some(&d), 2, 1).unwrap();
        let (a, b) = (c64::new(-0.7, 0.0), c64::new(0.0, 0.3));
        z.factor(1, a, b).unwrap();
        let x: Vec<c64> = (0..4).map(|i| c64::new(i as f64, 1.0 - i as f64)).collect();
        let mut y = vec![c64::new(0.0, 0.0); 4];
        let mut values = Vec::new();
        z.mul_add([c64::new(1.0, 0.0), a, b], &mut values, &x, &mut y);
        // Two columns through a one-column scratch: solved in two blocks.
        let mut rhs = Mat::<c64>::from_fn(4, 2, |i, _| y[i]);
        z.solve_in_place(1, rhs.as_mut()).unwrap();
        for c in 0..2 {
            for i in 0..4 {
                assert!((rhs[(i, c)] - x[i]).norm() < 1e-14, "{:?}", rhs[(i, c)]);
            }
        }
        assert_eq!(
            z.solve_in_place(0, rhs.as_mut()),
            Err(LinearSolveError::NotFactored)
        );
        // K - M with K = diag(1, 3), M = I has the exact zero pivot of dof 0.
        let k2 = sparse(2, &[(0, 0, 1.0), (1, 1, 3.0)]);
        let m2 = sparse(2, &[(0, 0, 1.0), (1, 1, 1.0)]);
        let mut z2 = DynamicStiffness::new(&k2, &m2, None, 1, 1).unwrap();
        match z2.factor(0, c64::new(-1.0, 0.0), c64::new(0.0, 0.0)) {
            Err(LinearSolveError::Singular { index, .. }) => assert_eq!(index, 0),
            other => panic!("{other:?}"),
        }
        let mut r = Mat::<c64>::zeros(2, 1);
        assert_eq!(
            z2.solve_in_place(0, r.as_mut()),
            Err(LinearSolveError::NotFactored)
        );
        z2.factor(0, c64::new(-2.0, 0.0), c64::new(0.0, 0.0))
            .unwrap();
    }
}
