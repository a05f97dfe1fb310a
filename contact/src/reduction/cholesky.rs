//! The factorization of a symmetric stiffness `K` that the eigensolver and the constraint
//! modes solve with: faer's sparse Cholesky `P K P^T = L L^T` (approximate minimum degree
//! ordering, supernodal on 3-D meshes), or the sparse LU when `K` is not positive definite.
//! A Cholesky factor whose pivots `l_jj^2` fall below [`DEFAULT_PIVOT_THRESHOLD`] times the
//! largest is singular, as the LU's pivot rule says. The symmetric factor is what makes a
//! 3-D model of `10^4`–`10^5` dofs cheap: the LU's column ordering ignores the symmetry and
//! its simplicial kernel has no dense blocks (on a 54,000-dof cantilever it took minutes
//! where the Cholesky takes seconds).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::{Conj, MatMut, Par, Side};
use semismooth::linalg::{check_pivots, FaerSparseLu, LinearSolveError, DEFAULT_PIVOT_THRESHOLD};
use semismooth::{Factorize, LinearSolve};

use crate::model::SparseMatrix;

use super::ReductionError;

/// A factored symmetric `K` (module documentation).
pub(crate) enum StiffnessFactor {
    /// `P K P^T = L L^T`: the symbolic analysis and the values of `L`.
    Cholesky(SymbolicCholesky<usize>, Vec<f64>),
    /// `K` is not positive definite: its sparse LU.
    Lu(FaerSparseLu),
}

impl StiffnessFactor {
    /// Factors `k` (symmetric: only its lower triangle is read by the Cholesky).
    pub(crate) fn new(k: &SparseMatrix) -> Result<Self, ReductionError> {
        let failed = |e: LinearSolveError| ReductionError::Factorization {
            reason: e.to_string(),
        };
        if let Some(factor) = cholesky(k).map_err(failed)? {
            return Ok(factor);
        }
        let mut lu = FaerSparseLu::new();
        lu.factor(k).map_err(failed)?;
        Ok(Self::Lu(lu))
    }
}

/// The Cholesky factor of `k`; `None` when `k` is not positive definite, a singular error
/// when a pivot is negligible.
fn cholesky(k: &SparseMatrix) -> Result<Option<StiffnessFactor>, LinearSolveError> {
    if let Some((index, value)) = (k.val().iter().enumerate()).find(|(_, v)| !v.is_finite()) {
        let (row, col) = entry_position(k, index);
        return Err(LinearSolveError::NonFiniteEntry {
            row,
            col,
            value: *value,
        });
    }
    let memory = LinearSolveError::OutOfMemory {
        during: "the sparse Cholesky factorization of K",
    };
    let symbolic = factorize_symbolic_cholesky(
        k.symbolic(),
        Side::Lower,
        SymmetricOrdering::Amd,
        Default::default(),
    )
    .map_err(|_| memory)?;
    let mut values = vec![0.0; symbolic.len_val()];
    let par = Par::Seq;
    let mut scratch =
        MemBuffer::try_new(symbolic.factorize_numeric_llt_scratch::<f64>(par, Default::default()))
            .map_err(|_| memory)?;
    let factored = symbolic.factorize_numeric_llt(
        &mut values,
        k.as_ref(),
        Side::Lower,
        Default::default(),
        par,
        MemStack::new(&mut scratch),
        Default::default(),
    );
    if factored.is_err() {
        return Ok(None);
    }
    let pivots = diagonal(&symbolic, &values).into_iter().map(|l| l * l);
    check_pivots(
        pivots.collect::<Vec<_>>().into_iter(),
        DEFAULT_PIVOT_THRESHOLD,
    )?;
    Ok(Some(StiffnessFactor::Cholesky(symbolic, values)))
}

/// The row and column of the stored entry `index` of `k`.
fn entry_position(k: &SparseMatrix, index: usize) -> (usize, usize) {
    let col_ptr = k.symbolic().col_ptr();
    let col = col_ptr.partition_point(|&p| p <= index).saturating_sub(1);
    (k.symbolic().row_idx()[index], col)
}

/// The diagonal of `L` (in the factor's order).
fn diagonal(symbolic: &SymbolicCholesky<usize>, values: &[f64]) -> Vec<f64> {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            let (col_ptr, row_idx) = (s.col_ptr(), s.row_idx());
            (0..s.nrows())
                .map(|j| {
                    (col_ptr[j]..col_ptr[j + 1])
                        .find(|&p| row_idx[p] == j)
                        .map_or(0.0, |p| values[p])
                })
                .collect()
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            let l = SupernodalLltRef::new(s, values);
            (0..s.n_supernodes())
                .flat_map(|sn| {
                    let block = l.supernode(sn).val();
                    (0..block.ncols()).map(move |c| block[(c, c)])
                })
                .collect()
        }
    }
}

impl LinearSolve for StiffnessFactor {
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        match self {
            Self::Lu(lu) => lu.solve_in_place(rhs),
            Self::Cholesky(symbolic, values) => {
                let n = symbolic.nrows();
                if rhs.len() != n {
                    return Err(LinearSolveError::DimensionMismatch {
                        expected: n,
                        found: rhs.len(),
                    });
                }
                let par = Par::Seq;
                let mut scratch = MemBuffer::try_new(
                    symbolic.solve_in_place_scratch::<f64>(1, par),
                )
                .map_err(|_| LinearSolveError::OutOfMemory {
                    during: "a solve with the sparse Cholesky factor of K",
                })?;
                LltRef::new(symbolic, values).solve_in_place_with_conj(
                    Conj::No,
                    MatMut::from_column_major_slice_mut(rhs, n, 1),
                    par,
                    MemStack::new(&mut scratch),
                );
                Ok(())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use faer::sparse::Triplet;

    use super::*;

    /// The `n x n` matrix `tridiag(-1, d, -1)`.
    fn tridiagonal(n: usize, d: f64) -> SparseMatrix {
        let mut t = Vec::new();
        for i in 0..n {
            t.push(Triplet::new(i, i, d));
            if i + 1 < n {
                t.push(Triplet::new(i, i + 1, -1.0));
                t.push(Triplet::new(i + 1, i, -1.0));
            }
        }
        SparseMatrix::try_new_from_triplets(n, n, &t).unwrap()
    }

    fn solved(k: &SparseMatrix, b: &[f64]) -> Vec<f64> {
        let mut x = b.to_vec();
        StiffnessFactor::new(k)
            .unwrap()
            .solve_in_place(&mut x)
            .unwrap();
        x
    }

    #[test]
    fn the_cholesky_solve_agrees_with_the_lu_solve() {
        // A 3-point chain is solved by either factor; the two agree to round-off
        // (condition number ~ n^2 = 1e4 for n = 100, so 1e-10 relative is generous).
        for n in [1, 2, 3, 100] {
            let k = tridiagonal(n, 2.0);
            let factor = StiffnessFactor::new(&k).unwrap();
            assert!(matches!(factor, StiffnessFactor::Cholesky(..)));
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 1.0).collect();
            let x = solved(&k, &b);
            let mut lu = FaerSparseLu::new();
            lu.factor(&k).unwrap();
            let mut y = b.clone();
            lu.solve_in_place(&mut y).unwrap();
            let scale = y.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for (a, b) in x.iter().zip(&y) {
                assert!((a - b).abs() <= 1e-10 * scale, "{a} vs {b}");
            }
        }
    }

    #[test]
    fn an_indefinite_matrix_falls_back_to_the_lu_and_a_singular_one_is_refused() {
        // tridiag(-1, 1, -1) of size 3 has eigenvalues 1 - sqrt(2), 1, 1 + sqrt(2).
        let k = tridiagonal(3, 1.0);
        assert!(matches!(
            StiffnessFactor::new(&k).unwrap(),
            StiffnessFactor::Lu(_)
        ));
        let x = solved(&k, &[1.0, 0.0, 0.0]);
        // K x = e_1 by the residual.
        let r = [x[0] - x[1] - 1.0, -x[0] + x[1] - x[2], -x[1] + x[2]];
        assert!(r.iter().all(|v| v.abs() < 1e-12), "{r:?}");
        // The free-free chain tridiag(-1, 2, -1) with 1 at both ends is singular.
        let mut t = Vec::new();
        for (i, j, v) in [(0, 0, 1.0), (0, 1, -1.0), (1, 0, -1.0), (1, 1, 1.0)] {
            t.push(Triplet::new(i, j, v));
        }
        let singular = SparseMatrix::try_new_from_triplets(2, 2, &t).unwrap();
        assert!(StiffnessFactor::new(&singular).is_err());
    }
}
