//! The condensed SSN-HB system solved matrix-free: the operator `S = I - Q + c Q R` on the
//! `m (2H + 1)` contact-force coefficients applied through the per-harmonic sparse factors,
//! and a block-Jacobi preconditioner over contacts.
//!
//! **Operator.** `R = G A(w)^{-1} G^T` is block diagonal in harmonics; harmonic `k` acts
//! on the complex coefficients `p_c - i p_s` as `G Z_k^{-1} G^T` with
//! `Z_k = K - (k w)^2 M + i k w D`, so `R p` costs one sparse solve per harmonic with the
//! factors of `Z_k` already made for the frequency (no `m x m` receptance and no `N x m`
//! response is stored). `Q_i = P diag(h_i) E` is applied per contact from the Jacobian's
//! blocks; a contact with no active sample has `Q_i = 0` and its rows of `S` are the
//! identity.
//!
//! **Preconditioner.** Dropping the receptance between different contacts (`R_ij`,
//! `i != j`) leaves `S` block diagonal over contacts: `S_i = I - Q_i + c Q_i R_ii` with the
//! exact activity of contact `i` and its own receptance `R_ii` (a scalar per harmonic).
//! Rows whose laws couple them (the normal and two tangent rows of a 3-D frictional
//! contact: the disk's 2 x 2 blocks and its column on the normal force) form one unit
//! ([`CoupledRows`]) and keep, in one `u (2H + 1)`-square block, the law's blocks and the
//! receptance between them: dropping the disk's off-diagonal blocks, which carry the
//! turning of a sliding force, left GMRES without a useful preconditioner. The
//! receptance between the rows of each unit is computed once per frequency (one sparse
//! solve per row and harmonic, in blocks of [`RECEPTANCE_BLOCK`] right-hand sides), the
//! blocks are factored by dense LU once per Newton iteration (`O(m u^2 H^3)`), and
//! applying them costs `O(m u H^2)`. It is exact when the units do not interact; GMRES
//! corrects for their coupling through the structure.
//!
//! **Dense preconditioner.** Contacts close together (every second node of a fine rod)
//! are coupled through the structure far beyond their own blocks: the receptance between
//! two of them is nearly their own. When GMRES with the blocks misses its tolerance after
//! one restart cycle and the condensed system has at most
//! [`DENSE_PRECONDITIONER_LIMIT`](super::DENSE_PRECONDITIONER_LIMIT) unknowns, the dense
//! condensed matrix of that iterate is formed (the full receptance, one block of contacts
//! at a time) and factored, and GMRES goes on with it as the preconditioner (exact at
//! that iterate: one or two more iterations). It stays the preconditioner at the next
//! iterates, and is refactored at the next one after a solve needed more than 30
//! iterations (about the cost of a factorization), or at once when one needs 60. Measured
//! on 100 contacts at H = 5 after the first full step: the blocks leave GMRES short after
//! 200 iterations, the dense preconditioner finishes in one (`tests/krylov_condensed.rs`).
//!
//! Measured at the converged active set (`examples/contact_scaling.rs`, mistuned disk of
//! 100 blades, H = 5): 30 / 44 GMRES iterations for 30 / 100 contacts, against 108 / 208
//! with the alternative block-diagonal-in-harmonics preconditioner of the time-averaged
//! activity (`Q_i ~ (Q_i)_00 I`, coupling kept, activity averaged), which was removed.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::lu::partial_pivoting::{factor as dense_lu, solve as dense_solve};
use faer::perm::PermRef;
use faer::{c64, Conj, Mat, Par};
use semismooth::linalg::{check_pivots, KrylovOperator, LinearSolveError, DEFAULT_PIVOT_THRESHOLD};

use super::coupled_rows::CoupledRows;
use super::laws::LawLayout;
use super::structured::{law_receptance_column, real_receptance, FactoredCondensed};
use super::LinearData;
use crate::operator::HarmonicFactors;

/// Above this many condensed unknowns `m (2H + 1)` the default structured solver applies
/// the condensed SSN-HB system matrix-free inside GMRES instead of forming and factoring it.
/// Below it the dense LU (`8 (m (2H + 1))^2` bytes, `(2/3) (m (2H + 1))^3` flops per Newton
/// iteration: 32 MB and about 1 s at 2,000) is affordable, and it is exact also at the
/// far-off iterates of full-step cycling where GMRES can stall.
pub const KRYLOV_THRESHOLD: usize = 2000;

/// The condensed operator `S` and its preconditioner at one Newton iterate (module
/// documentation).
pub(crate) struct CondensedOperator<'a> {
    pub(crate) dynamic: &'a mut HarmonicFactors,
    pub(crate) lin: &'a LinearData,
    /// The row groups' blocks `Q_ab` (the layout is `lin.laws`).
    pub(crate) q: &'a [Mat<f64>],
    /// The row groups' blocks `X` on the rows they read.
    pub(crate) cross: &'a [Mat<f64>],
    pub(crate) c: f64,
    /// `N x 1` complex scratch.
    pub(crate) rhs: &'a mut Mat<c64>,
    /// `m (2H + 1)` scratch.
    pub(crate) work: &'a mut Vec<f64>,
    pub(crate) preconditioner: CondensedPreconditioner<'a>,
}

/// The preconditioner of GMRES on the condensed system: the contact blocks, or the dense
/// LU of the condensed matrix at a recent iterate (module documentation).
pub(crate) enum CondensedPreconditioner<'a> {
    Blocks(&'a mut ContactBlocks, &'a CoupledRows),
    Dense(FactoredCondensed<'a>),
}

impl KrylovOperator for CondensedOperator<'_> {
    fn dim(&self) -> usize {
        self.lin.contacts() * self.lin.size()
    }

    /// `out = p - Q p + c Q R p + X p = p + Q (c R p - p) + X p`.
    fn apply(&mut self, p: &[f64], out: &mut [f64]) -> Result<(), LinearSolveError> {
        let lin = self.lin;
        let m = lin.contacts();
        let t = &mut *self.work;
        for k in 0..=lin.basis.harmonics() {
            // G^T p_k in complex form p_c - i p_s.
            self.rhs.fill(c64::new(0.0, 0.0));
            for i in 0..m {
                let z = if k == 0 {
                    c64::new(p[i], 0.0)
                } else {
                    c64::new(p[(2 * k - 1) * m + i], -p[2 * k * m + i])
                };
                lin.add_row_column(i, k, z, self.rhs.as_mut(), 0);
            }
            self.dynamic.solve_in_place(k, self.rhs.as_mut())?;
            for i in 0..m {
                let v = lin.measured(i, k, lin.row_complex(i, k, self.rhs.as_ref(), 0));
                if k == 0 {
                    t[i] = v.re;
                } else {
                    t[(2 * k - 1) * m + i] = v.re;
                    t[2 * k * m + i] = -v.im;
                }
            }
        }
        for (ti, pi) in t.iter_mut().zip(p) {
            *ti = self.c * *ti - pi;
        }
        lin.laws.apply_q(self.q, m, t, out);
        for (o, pi) in out.iter_mut().zip(p) {
            *o += pi;
        }
        lin.laws.apply_x_add(self.cross, m, p, out);
        Ok(())
    }

    fn precondition(&mut self, b: &[f64], out: &mut [f64]) -> Result<(), LinearSolveError> {
        match &mut self.preconditioner {
            CondensedPreconditioner::Blocks(blocks, rows) => blocks.solve(rows, b, out),
            CondensedPreconditioner::Dense(lu) => {
                lu.solve(b, out);
                Ok(())
            }
        }
    }
}

/// Contacts solved together by one block of right-hand sides when the receptance diagonal
/// is computed.
pub(crate) const RECEPTANCE_BLOCK: usize = 32;

/// The block-Jacobi preconditioner over units of coupled rows ([`CoupledRows`]):
/// `S_u = I - Q_u + c Q_u R_uu + X_u` per unit (`u (2H + 1)` square: the exact activity
/// of the unit's laws, their blocks between its rows and the receptance between its rows;
/// the coupling between units dropped), factored by dense LU. A unit of one row is the
/// contact block `S_i = I - Q_i + c Q_i R_ii`.
pub(crate) struct ContactBlocks {
    blocks: Vec<Mat<f64>>,
    fwd: Vec<Vec<usize>>,
    inv: Vec<Vec<usize>>,
    /// Unit with no active sample and no read: `S_u = I`.
    identity: Vec<bool>,
    rhs: Mat<f64>,
    mem: Option<MemBuffer>,
}

impl Default for ContactBlocks {
    fn default() -> Self {
        Self {
            blocks: Vec::new(),
            fwd: Vec::new(),
            inv: Vec::new(),
            identity: Vec::new(),
            rhs: Mat::zeros(0, 0),
            mem: None,
        }
    }
}

/// Adds `c Q_ab R~ - [own] Q_ab` to the columns `(place of b2) size ..` of the rows
/// `(place of a) size ..` of `s`, `R~` the real form of the receptance `R_k[b, b2]` on each
/// harmonic's pair (`r(k)`), `own` when `b2 = b`.
fn add_law_block(
    s: &mut Mat<f64>,
    qab: &Mat<f64>,
    (pa, pb2, own): (usize, usize, bool),
    r: impl Fn(usize) -> c64,
    c: f64,
) {
    let size = qab.nrows();
    let (row0, col0) = (pa * size, pb2 * size);
    for l in 0..size {
        let rho = real_receptance(r(l.div_ceil(2)), l);
        law_receptance_column(qab, (l, own), rho, c, |row, value| {
            s[(row0 + row, col0 + l)] += value;
        });
    }
}

impl ContactBlocks {
    /// Sizes the blocks of `rows`' units for `size = 2H + 1` basis functions.
    fn allocate(&mut self, rows: &CoupledRows, size: usize) -> Result<(), LinearSolveError> {
        let widths: Vec<usize> = rows.units.iter().map(|u| u.len() * size).collect();
        let widest = widths.iter().copied().max().unwrap_or(0);
        self.blocks = widths.iter().map(|&w| Mat::zeros(w, w)).collect();
        self.fwd = widths.iter().map(|&w| vec![0; w]).collect();
        self.inv = self.fwd.clone();
        self.identity = vec![true; widths.len()];
        self.rhs = Mat::zeros(widest, 1);
        let req = StackReq::any_of(&[
            dense_lu::lu_in_place_scratch::<usize, f64>(
                widest,
                widest,
                Par::Seq,
                Default::default(),
            ),
            dense_solve::solve_in_place_scratch::<usize, f64>(widest, 1, Par::Seq),
        ]);
        self.mem = Some(
            MemBuffer::try_new(req).map_err(|_| LinearSolveError::OutOfMemory {
                during: "allocating the contact-block preconditioner",
            })?,
        );
        Ok(())
    }

    /// Factors `S_u` of every unit of `rows` from the law blocks `Q_ab` and `X_as` of
    /// `layout` (`blocks`), the receptance between each unit's rows (`r[k E + entry(a,
    /// b)] = R_k[a, b]`, `E` the entries of `rows`) and `c`.
    pub(crate) fn factor(
        &mut self,
        (rows, layout): (&CoupledRows, &LawLayout),
        (q, cross): (&[Mat<f64>], &[Mat<f64>]),
        r: &[c64],
        c: f64,
    ) -> Result<(), LinearSolveError> {
        let size = q.first().map_or(0, |qi| qi.nrows());
        let fits = self.blocks.len() == rows.units.len()
            && self
                .blocks
                .iter()
                .zip(&rows.units)
                .all(|(b, u)| b.nrows() == u.len() * size);
        if !fits || self.mem.is_none() {
            self.allocate(rows, size)?;
        }
        let entries = rows.entries();
        for s in &mut self.blocks {
            s.fill(0.0);
        }
        self.identity.fill(true);
        for (qab, &(a, b)) in q.iter().zip(&layout.q_pairs) {
            let (unit, pa) = rows.place[a];
            if (0..size).all(|l| qab.col_as_slice(l).iter().all(|v| *v == 0.0)) {
                continue;
            }
            self.identity[unit] = false;
            for (pb2, &b2) in rows.units[unit].iter().enumerate() {
                let at = rows.entry(b, b2);
                add_law_block(
                    &mut self.blocks[unit],
                    qab,
                    (pa, pb2, b2 == b),
                    |k| r[k * entries + at],
                    c,
                );
            }
        }
        for (xas, &(a, s_row)) in cross.iter().zip(&layout.x_pairs) {
            let ((unit, pa), (_, ps)) = (rows.place[a], rows.place[s_row]);
            if (0..size).all(|l| xas.col_as_slice(l).iter().all(|v| *v == 0.0)) {
                continue;
            }
            self.identity[unit] = false;
            let s = &mut self.blocks[unit];
            for l in 0..size {
                for row in 0..size {
                    s[(pa * size + row, ps * size + l)] += xas[(row, l)];
                }
            }
        }
        self.factor_units()
    }

    /// LU of every unit's `I + S_u` (the identity added here), the identity units skipped.
    fn factor_units(&mut self) -> Result<(), LinearSolveError> {
        let Some(mem) = self.mem.as_mut() else {
            return Err(LinearSolveError::NotFactored);
        };
        for (unit, s) in self.blocks.iter_mut().enumerate() {
            if self.identity[unit] {
                continue;
            }
            let width = s.nrows();
            for l in 0..width {
                s[(l, l)] += 1.0;
            }
            dense_lu::lu_in_place(
                s.as_mut(),
                &mut self.fwd[unit],
                &mut self.inv[unit],
                Par::Seq,
                MemStack::new(mem),
                Default::default(),
            );
            check_pivots((0..width).map(|j| s[(j, j)]), DEFAULT_PIVOT_THRESHOLD)?;
        }
        Ok(())
    }

    /// `out = blockdiag(S_u)^{-1} b` (index `j m + row`) over the units of `rows`.
    pub(crate) fn solve(
        &mut self,
        rows: &CoupledRows,
        b: &[f64],
        out: &mut [f64],
    ) -> Result<(), LinearSolveError> {
        let m = rows.place.len();
        let Some(mem) = self.mem.as_mut() else {
            out.copy_from_slice(b);
            return Ok(());
        };
        for (unit, members) in rows.units.iter().enumerate() {
            let s = &self.blocks[unit];
            let size = s.nrows() / members.len().max(1);
            if self.identity[unit] {
                for &row in members {
                    for j in 0..size {
                        out[j * m + row] = b[j * m + row];
                    }
                }
                continue;
            }
            for (p, &row) in members.iter().enumerate() {
                for j in 0..size {
                    self.rhs[(p * size + j, 0)] = b[j * m + row];
                }
            }
            let width = s.nrows();
            let perm = PermRef::new_checked(&self.fwd[unit], &self.inv[unit], width);
            dense_solve::solve_in_place_with_conj(
                s.as_ref(),
                s.as_ref(),
                perm,
                Conj::No,
                self.rhs.as_mut().subrows_mut(0, width),
                Par::Seq,
                MemStack::new(mem),
            );
            for (p, &row) in members.iter().enumerate() {
                for j in 0..size {
                    out[j * m + row] = self.rhs[(p * size + j, 0)];
                }
            }
        }
        Ok(())
    }
}
