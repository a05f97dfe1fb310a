//! A complex symmetric dynamic stiffness `Z = R + i S` (`R`, `S` real symmetric: every
//! source symmetric) factored as the real symmetric indefinite matrix of twice its size,
//! `[[R, S], [S, -R]]` on `(x, -y)` for `z = x + i y`, the two unknowns of a dof adjacent.
//!
//! The factorization is faer's supernodal `P A P^T = L B L^T` (Bunch–Kaufman pivoting inside
//! each supernode, `B` of 1 x 1 and 2 x 2 blocks) in the approximate minimum degree ordering
//! of `Z`'s own pattern, each dof expanded to its pair: the fill is that of a sparse
//! Cholesky of `Z`'s pattern and the kernel works on dense blocks, where a general LU with a
//! column ordering ignores the symmetry and (simplicial) has no dense blocks. A dof's pair
//! is always in one supernode, so the 2 x 2 pivot `[[a, b], [b, -a]]` of a dof's own block
//! (determinant `-|z_jj|^2`) is there to choose. Used where faer's analysis of the pattern
//! chooses a supernodal factorization (2-D and 3-D meshes); banded chains keep the LU.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::supernodal::SupernodalIntranodeLbltRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, CholeskySymbolicParams, IntranodeLbltRef, SymbolicCholesky,
    SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};
use faer::{c64, Conj, Mat, MatMut, Par, Side};
use semismooth::linalg::LinearSolveError;

/// Which part of an entry of `Z` an entry of the real form holds.
#[derive(Debug, Clone, Copy)]
enum Part {
    Real,
    Imaginary,
    NegatedReal,
}

/// One numeric factorization: the values of `L` and `B`, and the pivoting inside the
/// supernodes (allocated at the slot's first factorization).
#[derive(Debug, Default)]
struct Slot {
    values: Vec<f64>,
    subdiagonal: Vec<f64>,
    forward: Vec<usize>,
    inverse: Vec<usize>,
    factored: bool,
}

/// The real form's analysis once per pattern and its factorizations in `slots` slots
/// (module documentation).
pub(crate) struct SymmetricFactors {
    dofs: usize,
    /// The real form's lower triangle.
    pattern: SymbolicSparseColMat<usize>,
    /// For each stored entry of the real form: the entry of `Z` (its storage index) and
    /// the part of it.
    parts: Vec<(usize, Part)>,
    symbolic: SymbolicCholesky<usize>,
    real_values: Vec<f64>,
    slots: Vec<Slot>,
    mem: MemBuffer,
    solve_columns: usize,
    real_rhs: Mat<f64>,
}

impl std::fmt::Debug for SymmetricFactors {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SymmetricFactors")
            .field("dofs", &self.dofs)
            .field("factor_entries", &self.symbolic.len_val())
            .field("slots", &self.slots.len())
            .finish_non_exhaustive()
    }
}

fn out_of_memory(during: &'static str) -> impl Fn(faer::sparse::FaerError) -> LinearSolveError {
    move |_| LinearSolveError::OutOfMemory { during }
}

impl SymmetricFactors {
    /// The analysis of the structurally symmetric pattern `z` (sorted rows, the diagonal
    /// stored) with `slots` slots and scratch for solves of `max_columns` right-hand sides;
    /// `None` when faer's analysis of `z` chooses a simplicial factorization (a banded
    /// chain), unless `force`.
    pub(crate) fn analyze(
        z: SymbolicSparseColMatRef<'_, usize>,
        slots: usize,
        max_columns: usize,
        force: bool,
    ) -> Result<Option<Self>, LinearSolveError> {
        let n = z.ncols();
        let ordering = factorize_symbolic_cholesky(
            z,
            Side::Lower,
            SymmetricOrdering::Amd,
            CholeskySymbolicParams::default(),
        )
        .map_err(out_of_memory("ordering the dynamic stiffness"))?;
        if matches!(ordering.raw(), SymbolicCholeskyRaw::Simplicial(_)) && !force {
            return Ok(None);
        }
        let (forward, inverse) = match ordering.perm() {
            Some(perm) => {
                let (f, i) = perm.arrays();
                (f.to_vec(), i.to_vec())
            }
            None => ((0..n).collect(), (0..n).collect()),
        };
        drop(ordering);
        let pair =
            |p: &[usize]| -> Vec<usize> { p.iter().flat_map(|&j| [2 * j, 2 * j + 1]).collect() };
        let (forward, inverse) = (pair(&forward), pair(&inverse));
        let (pattern, parts) = real_form_pattern(z);
        let params = CholeskySymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
            ..Default::default()
        };
        let perm = PermRef::new_checked(&forward, &inverse, 2 * n);
        let symbolic = factorize_symbolic_cholesky(
            pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Custom(perm),
            params,
        )
        .map_err(out_of_memory("analysing the dynamic stiffness"))?;
        let solve_columns = max_columns.max(1);
        let req = StackReq::or(
            symbolic.factorize_numeric_intranode_lblt_scratch::<f64>(Par::Seq, Default::default()),
            symbolic.solve_in_place_scratch::<f64>(solve_columns, Par::Seq),
        );
        let mem = MemBuffer::try_new(req).map_err(|_| LinearSolveError::OutOfMemory {
            during: "allocating the dynamic stiffness's scratch",
        })?;
        Ok(Some(Self {
            dofs: n,
            real_values: vec![0.0; parts.len()],
            pattern,
            parts,
            symbolic,
            slots: (0..slots.max(1)).map(|_| Slot::default()).collect(),
            mem,
            solve_columns,
            real_rhs: Mat::zeros(2 * n, solve_columns),
        }))
    }

    /// Factors `Z` (values in the storage order of the analysed pattern) into `slot`. A
    /// pivot block of `B` that is zero or not finite is [`LinearSolveError::Singular`]
    /// with the dof of the pivot as its index and squared moduli as `pivot` and
    /// `max_pivot`; the slot is then unfactored.
    pub(crate) fn factor(&mut self, slot: usize, z: &[c64]) -> Result<(), LinearSolveError> {
        let n2 = 2 * self.dofs;
        let Some(s) = self.slots.get_mut(slot) else {
            return Err(LinearSolveError::NotFactored);
        };
        s.factored = false;
        for (value, &(p, part)) in self.real_values.iter_mut().zip(&self.parts) {
            *value = match part {
                Part::Real => z[p].re,
                Part::Imaginary => z[p].im,
                Part::NegatedReal => -z[p].re,
            };
        }
        if s.values.len() != self.symbolic.len_val() {
            let memory = || LinearSolveError::OutOfMemory {
                during: "allocating a factorization of the dynamic stiffness",
            };
            s.values = try_zeros(self.symbolic.len_val()).ok_or_else(memory)?;
            s.subdiagonal = vec![0.0; n2];
            s.forward = vec![0; n2];
            s.inverse = vec![0; n2];
        }
        let a = SparseColMatRef::new(self.pattern.as_ref(), &self.real_values);
        self.symbolic.factorize_numeric_intranode_lblt(
            &mut s.values,
            &mut s.subdiagonal,
            &mut s.forward,
            &mut s.inverse,
            a,
            Side::Lower,
            Par::Seq,
            MemStack::new(&mut self.mem),
            Default::default(),
        );
        check_blocks(&self.symbolic, s)?;
        s.factored = true;
        Ok(())
    }

    /// `rhs <- Z^{-1} rhs` with the factorization in `slot` (`rhs` has `N` rows).
    pub(crate) fn solve_in_place(
        &mut self,
        slot: usize,
        mut rhs: MatMut<'_, c64>,
    ) -> Result<(), LinearSolveError> {
        let n = self.dofs;
        let s = match self.slots.get(slot) {
            Some(s) if s.factored => s,
            _ => return Err(LinearSolveError::NotFactored),
        };
        if rhs.nrows() != n {
            return Err(LinearSolveError::DimensionMismatch {
                expected: n,
                found: rhs.nrows(),
            });
        }
        let perm = PermRef::new_checked(&s.forward, &s.inverse, 2 * n);
        let factor = IntranodeLbltRef::new(&self.symbolic, &s.values, &s.subdiagonal, perm);
        let mut start = 0;
        while start < rhs.ncols() {
            let width = self.solve_columns.min(rhs.ncols() - start);
            let mut real = self.real_rhs.as_mut().subcols_mut(0, width);
            for c in 0..width {
                for i in 0..n {
                    let z = rhs[(i, start + c)];
                    real[(2 * i, c)] = z.re;
                    real[(2 * i + 1, c)] = z.im;
                }
            }
            let stack = MemStack::new(&mut self.mem);
            factor.solve_in_place_with_conj(Conj::No, real.as_mut(), Par::Seq, stack);
            // The unknowns are (x, -y) for z = x + i y.
            for c in 0..width {
                for i in 0..n {
                    rhs[(i, start + c)] = c64::new(real[(2 * i, c)], -real[(2 * i + 1, c)]);
                }
            }
            start += width;
        }
        Ok(())
    }
}

/// A zeroed vector of `len` numbers, `None` when it cannot be allocated.
fn try_zeros(len: usize) -> Option<Vec<f64>> {
    let mut v = Vec::new();
    v.try_reserve_exact(len).ok()?;
    v.resize(len, 0.0);
    Some(v)
}

/// The lower triangle of the real form `[[R, S], [S, -R]]` of a structurally symmetric
/// pattern with sorted rows, dof `j`'s unknowns at `2 j` and `2 j + 1`, and the part of an
/// entry of `Z` each of its entries holds.
fn real_form_pattern(
    z: SymbolicSparseColMatRef<'_, usize>,
) -> (SymbolicSparseColMat<usize>, Vec<(usize, Part)>) {
    let n = z.ncols();
    let mut col_ptr = Vec::with_capacity(2 * n + 1);
    col_ptr.push(0);
    let (mut row_idx, mut parts) = (Vec::new(), Vec::new());
    for j in 0..n {
        let lower = || (z.col_range(j)).filter(move |&p| z.row_idx()[p] >= j);
        // Column 2 j (x_j): R_ij on the equation of Re, S_ij on that of Im.
        for p in lower() {
            let i = z.row_idx()[p];
            row_idx.extend([2 * i, 2 * i + 1]);
            parts.extend([(p, Part::Real), (p, Part::Imaginary)]);
        }
        col_ptr.push(row_idx.len());
        // Column 2 j + 1 (-y_j): S_ij and -R_ij (only -R_jj on the diagonal block's lower half).
        for p in lower() {
            let i = z.row_idx()[p];
            if i > j {
                row_idx.push(2 * i);
                parts.push((p, Part::Imaginary));
            }
            row_idx.push(2 * i + 1);
            parts.push((p, Part::NegatedReal));
        }
        col_ptr.push(row_idx.len());
    }
    let pattern = SymbolicSparseColMat::new_checked(2 * n, 2 * n, col_ptr, None, row_idx);
    (pattern, parts)
}

/// `Ok` unless a pivot block of `B` is zero or not finite (`Singular`: the dof of its first
/// column, its squared modulus — a 2 x 2 block's `|det|` — and the largest).
fn check_blocks(symbolic: &SymbolicCholesky<usize>, s: &Slot) -> Result<(), LinearSolveError> {
    let SymbolicCholeskyRaw::Supernodal(supernodal) = symbolic.raw() else {
        return Err(LinearSolveError::NotFactored);
    };
    let perm = PermRef::new_checked(&s.forward, &s.inverse, s.forward.len());
    let factor = SupernodalIntranodeLbltRef::new(supernodal, &s.values, &s.subdiagonal, perm);
    let mut pivots = Vec::new();
    for sn in 0..supernodal.n_supernodes() {
        let node = factor.supernode(sn);
        let (start, block) = (node.start(), node.val());
        let mut c = 0;
        while c < block.ncols() {
            let off = s.subdiagonal[start + c];
            if off == 0.0 {
                pivots.push((start + c, block[(c, c)] * block[(c, c)]));
                c += 1;
            } else {
                let det = block[(c, c)] * block[(c + 1, c + 1)] - off * off;
                pivots.push((start + c, det.abs()));
                c += 2;
            }
        }
    }
    let max_pivot = pivots.iter().map(|p| p.1).fold(0.0, f64::max);
    match pivots.iter().find(|(_, p)| !p.is_finite() || *p == 0.0) {
        None => Ok(()),
        Some(&(position, pivot)) => {
            // Position `q` of the factor holds unknown `fwd[dyn_fwd[q]]` of the real form.
            let unknown = symbolic
                .perm()
                .map_or(s.forward[position], |p| p.arrays().0[s.forward[position]]);
            Err(LinearSolveError::Singular {
                index: unknown / 2,
                pivot,
                max_pivot,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamic::UnionPattern;
    use crate::model::SparseMatrix;
    use faer::sparse::Triplet;
    use semismooth::linalg::{PivotRule, SparseLu};

    /// The 2-D 9-point grid operator on `g x g` nodes (`K`: 8 on the diagonal, -1 to each
    /// neighbour) and a lumped mass.
    fn grid(g: usize) -> (SparseMatrix, SparseMatrix) {
        let n = g * g;
        let mut k = Vec::new();
        for a in 0..g {
            for b in 0..g {
                let i = a * g + b;
                k.push(Triplet::new(i, i, 8.0));
                for (da, db) in [(0, 1), (1, -1), (1, 0), (1, 1)] {
                    let (a2, b2) = (a as i64 + da, b as i64 + db);
                    if a2 < g as i64 && (0..g as i64).contains(&b2) {
                        let j = a2 as usize * g + b2 as usize;
                        k.push(Triplet::new(i, j, -1.0));
                        k.push(Triplet::new(j, i, -1.0));
                    }
                }
            }
        }
        let m: Vec<_> = (0..n)
            .map(|i| Triplet::new(i, i, 1.0 + (i % 3) as f64))
            .collect();
        (
            SparseMatrix::try_new_from_triplets(n, n, &k).unwrap(),
            SparseMatrix::try_new_from_triplets(n, n, &m).unwrap(),
        )
    }

    #[test]
    fn real_form_solves_as_the_complex_lu_does() {
        let (k, m) = grid(12);
        let n = k.nrows();
        let pattern = UnionPattern::new(n, &[&k, &m]);
        let mut z = vec![c64::new(0.0, 0.0); pattern.nnz()];
        // Between natural frequencies (indefinite real part) with damping 0.02 K.
        let (a, b) = (c64::new(-3.7, 0.0), c64::new(0.02, 0.0));
        let stiffness = c64::new(1.0, 0.0) + c64::new(0.0, 1.0) * b;
        pattern.combine([(&k, stiffness), (&m, a)], &mut z);
        let mut factors = SymmetricFactors::analyze(pattern.symbolic.as_ref(), 2, 3, true)
            .unwrap()
            .unwrap();
        factors.factor(1, &z).unwrap();
        let rhs = Mat::<c64>::from_fn(n, 4, |i, c| c64::new((i + c) as f64, 1.0 - c as f64));
        let mut x = rhs.clone();
        factors.solve_in_place(1, x.as_mut()).unwrap();
        let mut lu = SparseLu::<c64>::new().with_pivot_rule(PivotRule::Breakdown);
        lu.factor_slot(0, pattern.matrix(&z)).unwrap();
        let mut y = rhs.clone();
        lu.solve_slot_in_place(0, y.as_mut()).unwrap();
        // Two backward-stable factorizations of a matrix of condition number below 1e3
        // agree to a few hundred round-offs of the solution's size.
        let scale = y.norm_max();
        assert!(
            (&x - &y).norm_max() < 1e-12 * scale,
            "{}",
            (&x - &y).norm_max()
        );
        assert_eq!(
            factors.solve_in_place(0, x.as_mut()),
            Err(LinearSolveError::NotFactored)
        );
    }

    #[test]
    fn real_form_reports_an_exact_zero_pivot_by_its_dof() {
        // K - M with K = diag(2, 1, 3), M = I: dof 1's pivot is exactly zero.
        let k = SparseMatrix::try_new_from_triplets(
            3,
            3,
            &[
                Triplet::new(0, 0, 2.0),
                Triplet::new(1, 1, 1.0),
                Triplet::new(2, 2, 3.0),
            ],
        )
        .unwrap();
        let pattern = UnionPattern::new(3, &[&k]);
        let z: Vec<c64> = k.val().iter().map(|&v| c64::new(v - 1.0, 0.0)).collect();
        let mut factors = SymmetricFactors::analyze(pattern.symbolic.as_ref(), 1, 1, true)
            .unwrap()
            .unwrap();
        match factors.factor(0, &z) {
            Err(LinearSolveError::Singular { index, pivot, .. }) => {
                assert_eq!((index, pivot), (1, 0.0));
            }
            other => panic!("{other:?}"),
        }
        let mut r = Mat::<c64>::zeros(3, 1);
        assert_eq!(
            factors.solve_in_place(0, r.as_mut()),
            Err(LinearSolveError::NotFactored)
        );
    }
}
