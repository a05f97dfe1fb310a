//! The harmonic operator: the linear dynamics `M u'' + D u' + K u = f(t)` on harmonic `k`
//! of the forcing frequency `w`, written once for every harmonic-balance formulation.
//!
//! In complex form (`u(t) = Re sum_k z_k e^{i k w t}`, `z_k = a_k - i b_k` for
//! `a_k cos(k w t) + b_k sin(k w t)`) harmonic `k` is `Z_k z_k = f_k` with
//!
//! `Z_k(w, p) = sum_s c_s(k, w, p) A_s = K + (-(k w)^2 - i k w xi) M + i k w D`,
//!
//! the sources `A_s` being `K`, `M`, `D` and the parameters `p` the modal damping `xi`
//! (`D - xi M` as the damping, the negative damping of nonlinear modes; 0 by default).
//! On the real coefficients `(a_k, b_k)` the operator acts as
//! `(Re Z a + Im Z b, Re Z b - Im Z a)`: for real `K`, `M`, `D` and `xi = 0` the block
//! `[[K - (k w)^2 M, k w D], [-k w D, K - (k w)^2 M]]`; harmonic 0 is `K` on `u_0`.
//!
//! - [`HarmonicParameters`]: `w` and every other parameter of the coefficients;
//!   [`OperatorParameter`] names one of them for derivatives.
//! - `HarmonicOperator`: the sources and the [`HarmonicLoad`]; the coefficients and their
//!   derivatives, the real form's product, residual and dense assembly (no allocation).
//! - `HarmonicFactors`: the sparse complex LU of every `Z_k` (one union pattern, one
//!   reusable slot per harmonic), refactored only when a parameter changed (the cache key
//!   is the bits of all of them), counted.

use faer::{c64, Mat, MatMut};
use semismooth::linalg::LinearSolveError;

use crate::dynamic::{DynamicStiffness, UnionPattern};
use crate::model::{
    sparse_mul_add, CouplingTerm, CyclicCoupling, HarmonicLoad, SparseMatrix, StructuralModel,
};

/// The parameters of the coefficients `c_s(k, w, p)`: the angular frequency `w` and the
/// modal damping `xi` (module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HarmonicParameters {
    /// Angular frequency `w` of harmonic 1.
    pub omega: f64,
    /// Modal damping `xi`: the damping is `D - xi M` (0: the model's own).
    pub modal_damping: f64,
}

impl HarmonicParameters {
    /// `w` with the model's own damping (`xi = 0`).
    pub fn new(omega: f64) -> Self {
        Self {
            omega,
            modal_damping: 0.0,
        }
    }

    /// True when every parameter has the same bits: a factorization at `other` is one at
    /// `self`.
    pub fn same_as(&self, other: &Self) -> bool {
        self.omega.to_bits() == other.omega.to_bits()
            && self.modal_damping.to_bits() == other.modal_damping.to_bits()
    }
}

/// A parameter of the harmonic operator, for derivatives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum OperatorParameter {
    /// The angular frequency `w`: `dc_M = -2 k^2 w - i k xi`, `dc_D = i k`.
    Omega,
    /// The modal damping `xi`: `dc_M = -i k w`.
    ModalDamping,
}

/// Coefficients of the sources `[K, M, D]`.
pub(crate) type Coefficients = [c64; 3];

/// The sources `K`, `M`, `D` and the load of the harmonic balance of one model with `H`
/// harmonics (module documentation).
#[derive(Debug, Clone)]
pub(crate) struct HarmonicOperator {
    dofs: usize,
    harmonics: usize,
    stiffness: SparseMatrix,
    mass: SparseMatrix,
    damping: Option<SparseMatrix>,
    coupling: Option<CyclicCoupling>,
    load: HarmonicLoad,
}

impl HarmonicOperator {
    /// The operator of a validated `model` with `harmonics` harmonics (its load's
    /// harmonics checked by the caller).
    pub(crate) fn new(model: &StructuralModel, harmonics: usize) -> Self {
        Self {
            dofs: model.dofs(),
            harmonics,
            stiffness: model.stiffness.clone(),
            mass: model.mass.clone(),
            damping: model.damping.clone(),
            coupling: model.cyclic.clone(),
            load: model.load.clone(),
        }
    }

    /// Every source of harmonic `k` with its coefficient, from the coefficients `c` of
    /// `[K, M, D]` (`D` absent without damping): a cyclic coupling `B_t` takes
    /// `c[source_t] e^{i sign_t k phi}`.
    fn terms(&self, k: usize, c: Coefficients) -> impl Iterator<Item = (&SparseMatrix, c64)> + '_ {
        let own = [
            Some(&self.stiffness),
            Some(&self.mass),
            self.damping.as_ref(),
        ]
        .into_iter()
        .zip(c)
        .filter_map(|(a, c)| a.map(|a| (a, c)));
        let coupling = self.coupling.iter().flat_map(move |coupling| {
            let phase = k as f64 * coupling.phase_step;
            (coupling.terms.iter()).map(move |t| (&t.matrix, coupled(t, phase, c)))
        });
        own.chain(coupling)
    }

    /// Every source in the order of [`HarmonicOperator::terms`].
    fn source_matrices(&self) -> Vec<SparseMatrix> {
        let mut sources = vec![self.stiffness.clone(), self.mass.clone()];
        sources.extend(self.damping.clone());
        let coupling = self.coupling.iter().flat_map(|c| &c.terms);
        sources.extend(coupling.map(|t| t.matrix.clone()));
        sources
    }

    /// `c_s(k, w, xi)` of `[K, M, D]`: `[1, -(k w)^2 - i k w xi, i k w]`.
    pub(crate) fn coefficients(k: usize, p: &HarmonicParameters) -> Coefficients {
        let kw = k as f64 * p.omega;
        let mass_im = if p.modal_damping == 0.0 {
            0.0
        } else {
            -kw * p.modal_damping
        };
        [
            c64::new(1.0, 0.0),
            c64::new(-kw * kw, mass_im),
            c64::new(0.0, kw),
        ]
    }

    /// `d c_s / d parameter` of `[K, M, D]` at harmonic `k`.
    pub(crate) fn derivative(
        k: usize,
        p: &HarmonicParameters,
        parameter: OperatorParameter,
    ) -> Coefficients {
        let kf = k as f64;
        let zero = c64::new(0.0, 0.0);
        match parameter {
            OperatorParameter::Omega => [
                zero,
                c64::new(-2.0 * kf * kf * p.omega, -kf * p.modal_damping),
                c64::new(0.0, kf),
            ],
            OperatorParameter::ModalDamping => [zero, c64::new(0.0, -kf * p.omega), zero],
        }
    }

    /// `out = A U` for the real form of the coefficients `coefficients(k)` on the
    /// harmonic-major `u` (`u[j N + dof]`; module documentation); zero parts are skipped.
    fn apply_with(&self, coefficients: impl Fn(usize) -> Coefficients, u: &[f64], out: &mut [f64]) {
        let n = self.dofs;
        out.fill(0.0);
        for (a, c) in self.terms(0, coefficients(0)) {
            if c.re != 0.0 {
                sparse_mul_add(a.as_ref(), c.re, &u[..n], &mut out[..n]);
            }
        }
        for k in 1..=self.harmonics {
            let (cos, sin) = ((2 * k - 1) * n, 2 * k * n);
            let (a, b) = (&u[cos..cos + n], &u[sin..sin + n]);
            let (out_c, out_s) = out[cos..sin + n].split_at_mut(n);
            for (matrix, c) in self.terms(k, coefficients(k)) {
                let matrix = matrix.as_ref();
                // z = a - i b: Z z = (Re Z a + Im Z b) - i (Re Z b - Im Z a).
                if c.re != 0.0 {
                    sparse_mul_add(matrix, c.re, a, out_c);
                    sparse_mul_add(matrix, c.re, b, out_s);
                }
                if c.im != 0.0 {
                    sparse_mul_add(matrix, c.im, b, out_c);
                    sparse_mul_add(matrix, -c.im, a, out_s);
                }
            }
        }
    }

    /// `out = A(w, p) U` (real form, harmonic-major).
    pub(crate) fn apply(&self, p: &HarmonicParameters, u: &[f64], out: &mut [f64]) {
        self.apply_with(|k| Self::coefficients(k, p), u, out);
    }

    /// `out = A(w, p) U - F`, `F` the load's coefficients.
    pub(crate) fn residual(&self, p: &HarmonicParameters, u: &[f64], out: &mut [f64]) {
        self.apply(p, u, out);
        self.load.add_coefficients(-1.0, self.harmonics, out);
    }

    /// `out = dA/d parameter U` (real form, harmonic-major).
    pub(crate) fn apply_derivative(
        &self,
        p: &HarmonicParameters,
        parameter: OperatorParameter,
        u: &[f64],
        out: &mut [f64],
    ) {
        self.apply_with(|k| Self::derivative(k, p, parameter), u, out);
    }

    /// `out = F`: the load's coefficients (harmonic-major, length `N (2H + 1)`).
    pub(crate) fn load_coefficients(&self, out: &mut [f64]) {
        out.fill(0.0);
        self.load.add_coefficients(1.0, self.harmonics, out);
    }

    /// Adds the real form of `A(w, p)` to the leading `N (2H + 1)` square of `out`.
    pub(crate) fn add_dense(&self, p: &HarmonicParameters, out: &mut MatMut<'_, f64>) {
        let n = self.dofs;
        let mut add = |m: &SparseMatrix, r0: usize, c0: usize, alpha: f64| {
            let m = m.as_ref();
            let symbolic = m.symbolic();
            let (rows, values) = (symbolic.row_idx(), m.val());
            for j in 0..n {
                for q in symbolic.col_range(j) {
                    out[(r0 + rows[q], c0 + j)] += alpha * values[q];
                }
            }
        };
        for (a, c) in self.terms(0, Self::coefficients(0, p)) {
            if c.re != 0.0 {
                add(a, 0, 0, c.re);
            }
        }
        for k in 1..=self.harmonics {
            let (cos, sin) = ((2 * k - 1) * n, 2 * k * n);
            for (a, c) in self.terms(k, Self::coefficients(k, p)) {
                if c.re != 0.0 {
                    add(a, cos, cos, c.re);
                    add(a, sin, sin, c.re);
                }
                if c.im != 0.0 {
                    add(a, cos, sin, c.im);
                    add(a, sin, cos, -c.im);
                }
            }
        }
    }

    /// The operator with `1 x 1` empty matrices and no load: its [`HarmonicOperator::terms`]
    /// give the coefficients of every source without holding the matrices twice.
    fn without_matrices(&self) -> Self {
        let empty = || SparseMatrix::try_new_from_triplets(1, 1, &[]).expect("a 1 x 1 matrix");
        let coupling = self.coupling.as_ref().map(|c| {
            let terms = c.terms.iter().map(|t| CouplingTerm {
                source: t.source,
                matrix: empty(),
                sign: t.sign,
            });
            CyclicCoupling::new(c.phase_step, c.sectors, terms.collect())
        });
        Self {
            dofs: self.dofs,
            harmonics: self.harmonics,
            stiffness: empty(),
            mass: empty(),
            damping: self.damping.as_ref().map(|_| empty()),
            coupling,
            load: HarmonicLoad::zero(0),
        }
    }

    /// Empty factorizations of every `Z_k` (`k = 0..=H`), with scratch for solves of up to
    /// `max_columns` right-hand sides at once; `one_at_a_time`: a single slot, each harmonic
    /// factored when a solve needs it (replacing the previous one).
    pub(crate) fn factors(
        &self,
        max_columns: usize,
        one_at_a_time: bool,
    ) -> Result<HarmonicFactors, LinearSolveError> {
        let slots = if one_at_a_time { 1 } else { self.harmonics + 1 };
        Ok(HarmonicFactors {
            stiffness: DynamicStiffness::with_sources(self.source_matrices(), slots, max_columns)?,
            one_at_a_time,
            held: None,
            operator: self.without_matrices(),
            coefficients: Vec::new(),
            dofs: self.dofs,
            harmonics: self.harmonics,
            key: None,
            complex: Mat::zeros(self.dofs, 1),
        })
    }
}

/// `c[source] e^{i sign phase}`: the coefficient of a coupling term at the harmonic
/// phase `phase = k phi`.
fn coupled(term: &CouplingTerm, phase: f64, c: Coefficients) -> c64 {
    let angle = term.sign * phase;
    c[term.source.index()] * c64::new(angle.cos(), angle.sin())
}

/// The sparse complex LU of every `Z_k(w, p)`, `k = 0..=H`, of one [`HarmonicOperator`]
/// (module documentation): [`HarmonicFactors::factor`] refactors only when a parameter
/// changed. One at a time, only one harmonic's factorization is held: a solve on another
/// harmonic factors it first (memory of one factor, a factorization per change of harmonic).
#[derive(Debug)]
pub(crate) struct HarmonicFactors {
    stiffness: DynamicStiffness,
    /// One slot, refilled per harmonic on demand.
    one_at_a_time: bool,
    /// One at a time: the harmonic whose factorization the slot holds.
    held: Option<usize>,
    /// The operator's coupling phases and which sources it has (its matrices emptied).
    operator: HarmonicOperator,
    /// Scratch: the coefficients of every source at one harmonic.
    coefficients: Vec<c64>,
    dofs: usize,
    harmonics: usize,
    /// The parameters of the factorizations held (`None`: none or failed).
    key: Option<HarmonicParameters>,
    /// `N x 1` complex scratch of [`HarmonicFactors::solve_real`].
    complex: Mat<c64>,
}

impl HarmonicFactors {
    /// Factors every `Z_k` at `p` unless they are factored there already; `Ok(true)` when
    /// it factored. A breakdown is [`LinearSolveError::Singular`] indexed by the pivot's
    /// dof as an unknown of the real form (the cosine block of harmonic `k`).
    pub(crate) fn factor(&mut self, p: &HarmonicParameters) -> Result<bool, LinearSolveError> {
        if self.key.is_some_and(|key| key.same_as(p)) {
            return Ok(false);
        }
        self.key = None;
        self.held = None;
        if !self.one_at_a_time {
            for k in 0..=self.harmonics {
                self.factor_harmonic(k, k, p)?;
            }
        }
        self.key = Some(*p);
        Ok(true)
    }

    /// Factors `Z_k(w, p)` into `slot` (a breakdown as [`HarmonicFactors::factor`]'s).
    fn factor_harmonic(
        &mut self,
        k: usize,
        slot: usize,
        p: &HarmonicParameters,
    ) -> Result<(), LinearSolveError> {
        let n = self.dofs;
        let base = HarmonicOperator::coefficients(k, p);
        self.coefficients.clear();
        (self.coefficients).extend(self.operator.terms(k, base).map(|(_, c)| c));
        self.stiffness
            .factor_combination(slot, &self.coefficients)
            .map_err(|e| match e {
                LinearSolveError::Singular {
                    index,
                    pivot,
                    max_pivot,
                } => LinearSolveError::Singular {
                    index: if k == 0 {
                        index
                    } else {
                        (2 * k - 1) * n + index
                    },
                    pivot,
                    max_pivot,
                },
                other => other,
            })
    }

    /// The slot holding `Z_k`'s factorization, factoring it first when one at a time and
    /// another harmonic is held.
    fn slot_of(&mut self, k: usize) -> Result<usize, LinearSolveError> {
        if !self.one_at_a_time {
            return Ok(k);
        }
        if self.held != Some(k) {
            let key = self.key.ok_or(LinearSolveError::NotFactored)?;
            self.held = None;
            self.factor_harmonic(k, 0, &key)?;
            self.held = Some(k);
        }
        Ok(0)
    }

    /// `rhs <- Z_k^{-1} rhs` (`rhs` has `N` rows).
    pub(crate) fn solve_in_place(
        &mut self,
        k: usize,
        rhs: MatMut<'_, c64>,
    ) -> Result<(), LinearSolveError> {
        let slot = self.slot_of(k)?;
        self.stiffness.solve_in_place(slot, rhs)
    }

    /// `u <- A^{-1} u` on the harmonic-major real coefficients, harmonic by harmonic in
    /// complex form (`u_0`; `u_ck - i u_sk`).
    pub(crate) fn solve_real(&mut self, u: &mut [f64]) -> Result<(), LinearSolveError> {
        for k in 0..=self.harmonics {
            self.solve_real_harmonic(k, u)?;
        }
        Ok(())
    }

    /// `u <- A^{-1} u` on harmonic `k`'s part of the harmonic-major real coefficients `u`
    /// (`u_0` for `k = 0`, `u_ck - i u_sk` in complex form otherwise); the rest untouched.
    pub(crate) fn solve_real_harmonic(
        &mut self,
        k: usize,
        u: &mut [f64],
    ) -> Result<(), LinearSolveError> {
        if self.key.is_none() {
            return Err(LinearSolveError::NotFactored);
        }
        let n = self.dofs;
        let slot = self.slot_of(k)?;
        let (cosine, mut sine) = if k == 0 {
            (&mut u[..n], None)
        } else {
            let (c, s) = u[(2 * k - 1) * n..(2 * k + 1) * n].split_at_mut(n);
            (c, Some(s))
        };
        let rhs = first_column(&mut self.complex);
        for (i, z) in rhs.iter_mut().enumerate() {
            *z = c64::new(cosine[i], sine.as_ref().map_or(0.0, |s| -s[i]));
        }
        self.stiffness.solve_in_place(slot, self.complex.as_mut())?;
        let rhs = first_column(&mut self.complex);
        for (i, z) in rhs.iter().enumerate() {
            cosine[i] = z.re;
            if let Some(s) = sine.as_mut() {
                s[i] = -z.im;
            }
        }
        Ok(())
    }
}

/// The first column of `rhs` as a slice (an owned matrix's columns are contiguous).
fn first_column(rhs: &mut Mat<c64>) -> &mut [c64] {
    rhs.col_mut(0)
        .try_as_col_major_mut()
        .expect("a column of an owned matrix is contiguous")
        .as_slice_mut()
}

impl StructuralModel {
    /// How much the undamped linear response at `omega` exceeds the static one:
    /// `max |(K - omega^2 M)^{-1} f| / max |K^{-1} f|` (`f` the load's cosine part on the
    /// forcing frequency), infinite when `K - omega^2 M` is
    /// singular (forced at a natural frequency: an undamped structure without contact then
    /// has no periodic solution); `None` when `K` cannot be factored or the load is zero.
    /// Ignores damping and contacts.
    pub fn undamped_amplification(&self, omega: f64) -> Option<f64> {
        use semismooth::linalg::FaerSparseLu;
        use semismooth::{Factorize, LinearSolve};
        let n = self.dofs();
        let response = |matrix: &SparseMatrix| -> Option<f64> {
            let mut lu = FaerSparseLu::new();
            if lu.factor(matrix).is_err() {
                return Some(f64::INFINITY);
            }
            let mut u = self.load.forcing_cosine();
            lu.solve_in_place(&mut u).ok()?;
            Some(u.iter().fold(0.0f64, |m, v| m.max(v.abs())))
        };
        let static_response = response(&self.stiffness)?;
        if !(static_response > 0.0 && static_response.is_finite()) {
            return None;
        }
        // Harmonic 1 of the operator without damping: K + Re(c_M) M = K - w^2 M.
        let mass = HarmonicOperator::coefficients(1, &HarmonicParameters::new(omega))[1].re;
        let dynamic =
            UnionPattern::linear_combination(n, &[&self.stiffness, &self.mass], &[1.0, mass]);
        let amplification = response(&dynamic)? / static_response;
        Some(if amplification.is_nan() {
            f64::INFINITY
        } else {
            amplification
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::Triplet;

    /// `K`, `M`, `D` on 3 dofs (`D` unsymmetric: the real form must not assume symmetry)
    /// with `H = 2` harmonics.
    fn operator() -> HarmonicOperator {
        let sparse = |entries: &[(usize, usize, f64)]| {
            let t: Vec<_> = entries
                .iter()
                .map(|&(i, j, v)| Triplet::new(i, j, v))
                .collect();
            SparseMatrix::try_new_from_triplets(3, 3, &t).unwrap()
        };
        let k = sparse(&[
            (0, 0, 3.0),
            (0, 1, -1.0),
            (1, 0, -1.0),
            (1, 1, 2.0),
            (2, 2, 1.5),
        ]);
        let m = sparse(&[
            (0, 0, 1.0),
            (1, 1, 0.5),
            (2, 2, 0.8),
            (2, 1, 0.1),
            (1, 2, 0.1),
        ]);
        let d = sparse(&[(0, 0, 0.2), (0, 2, 0.05), (1, 1, 0.1), (2, 2, 0.3)]);
        let model = StructuralModel::new(m, k, vec![1.0, 0.0, -0.5]).with_damping(d);
        HarmonicOperator::new(&model, 2)
    }

    fn dense(a: &SparseMatrix) -> Mat<f64> {
        let mut out = Mat::zeros(a.nrows(), a.ncols());
        let r = a.as_ref();
        for j in 0..a.ncols() {
            for (i, v) in r.row_idx_of_col(j).zip(r.val_of_col(j)) {
                out[(i, j)] += v;
            }
        }
        out
    }

    fn coefficients_u() -> Vec<f64> {
        (0..15).map(|i| ((i * 7) % 11) as f64 / 5.0 - 1.0).collect()
    }

    #[test]
    fn real_form_is_the_complex_block_on_cosine_minus_i_sine() {
        let op = operator();
        let p = HarmonicParameters {
            omega: 0.9,
            modal_damping: 0.2,
        };
        let u = coefficients_u();
        let mut out = vec![0.0; 15];
        op.apply(&p, &u, &mut out);
        let (k, m, d) = (
            dense(&op.stiffness),
            dense(&op.mass),
            dense(op.damping.as_ref().unwrap()),
        );
        for h in 0..=2 {
            // Z_h = K - (h w)^2 M + i h w (D - xi M), written out independently.
            let hw = h as f64 * p.omega;
            let z = |i: usize, j: usize| {
                c64::new(
                    k[(i, j)] - hw * hw * m[(i, j)],
                    hw * (d[(i, j)] - p.modal_damping * m[(i, j)]),
                )
            };
            for i in 0..3 {
                let mut y = c64::new(0.0, 0.0);
                for j in 0..3 {
                    let x = if h == 0 {
                        c64::new(u[j], 0.0)
                    } else {
                        c64::new(u[(2 * h - 1) * 3 + j], -u[2 * h * 3 + j])
                    };
                    y += z(i, j) * x;
                }
                // A few roundings of terms of order 1.
                if h == 0 {
                    assert!((out[i] - y.re).abs() < 1e-14);
                } else {
                    assert!((out[(2 * h - 1) * 3 + i] - y.re).abs() < 1e-14);
                    assert!((out[2 * h * 3 + i] + y.im).abs() < 1e-14);
                }
            }
        }
    }

    #[test]
    fn without_modal_damping_it_is_the_symmetric_block_bit_for_bit() {
        let op = operator();
        let p = HarmonicParameters::new(1.7);
        let u = coefficients_u();
        let mut out = vec![0.0; 15];
        op.apply(&p, &u, &mut out);
        // [[K - (k w)^2 M, k w D], [-k w D, K - (k w)^2 M]] term by term, in that order.
        let mut expected = vec![0.0; 15];
        let d = op.damping.as_ref().unwrap();
        sparse_mul_add(op.stiffness.as_ref(), 1.0, &u[..3], &mut expected[..3]);
        for k in 1..=2 {
            let kw = k as f64 * p.omega;
            let (c, s) = ((2 * k - 1) * 3, 2 * k * 3);
            let (a, b) = (&u[c..c + 3], &u[s..s + 3]);
            let (out_c, out_s) = expected[c..s + 3].split_at_mut(3);
            sparse_mul_add(op.stiffness.as_ref(), 1.0, a, out_c);
            sparse_mul_add(op.mass.as_ref(), -kw * kw, a, out_c);
            sparse_mul_add(op.stiffness.as_ref(), 1.0, b, out_s);
            sparse_mul_add(op.mass.as_ref(), -kw * kw, b, out_s);
            sparse_mul_add(d.as_ref(), kw, b, out_c);
            sparse_mul_add(d.as_ref(), -kw, a, out_s);
        }
        assert_eq!(out, expected);
        // The dense real form is the same operator.
        let mut a = Mat::<f64>::zeros(15, 15);
        op.add_dense(&p, &mut a.as_mut());
        for (i, e) in expected.iter().enumerate() {
            let row: f64 = (0..15).map(|j| a[(i, j)] * u[j]).sum();
            assert!((row - e).abs() < 1e-13);
        }
    }

    #[test]
    fn parameter_derivatives_are_the_central_differences() {
        let op = operator();
        let p = HarmonicParameters {
            omega: 1.1,
            modal_damping: -0.3,
        };
        let u = coefficients_u();
        let step = 1e-4;
        for parameter in [OperatorParameter::Omega, OperatorParameter::ModalDamping] {
            let shifted = |delta: f64| {
                let mut q = p;
                match parameter {
                    OperatorParameter::Omega => q.omega += delta,
                    OperatorParameter::ModalDamping => q.modal_damping += delta,
                }
                let mut out = vec![0.0; 15];
                op.apply(&q, &u, &mut out);
                out
            };
            let (plus, minus) = (shifted(step), shifted(-step));
            let mut derivative = vec![0.0; 15];
            op.apply_derivative(&p, parameter, &u, &mut derivative);
            // The operator is quadratic in w and linear in xi: the central difference is
            // exact but for rounding, eps |A u| / step ~ 1e-11.
            for i in 0..15 {
                let fd = (plus[i] - minus[i]) / (2.0 * step);
                assert!((fd - derivative[i]).abs() < 1e-9, "{parameter:?} {i}");
            }
        }
    }

    #[test]
    fn factors_invert_the_real_form_and_refactor_only_on_a_new_parameter() {
        let op = operator();
        let mut factors = op.factors(1, false).unwrap();
        let u = coefficients_u();
        let mut x = u.clone();
        assert_eq!(
            factors.solve_real(&mut x),
            Err(LinearSolveError::NotFactored)
        );
        let p = HarmonicParameters {
            omega: 0.6,
            modal_damping: 0.1,
        };
        assert!(factors.factor(&p).unwrap());
        assert!(!factors.factor(&p).unwrap());
        op.apply(&p, &u, &mut x);
        factors.solve_real(&mut x).unwrap();
        for (a, b) in x.iter().zip(&u) {
            assert!((a - b).abs() < 1e-13);
        }
        let q = HarmonicParameters {
            modal_damping: 0.2,
            ..p
        };
        assert!(factors.factor(&q).unwrap());
        assert!(!factors.factor(&q).unwrap());
    }
}
