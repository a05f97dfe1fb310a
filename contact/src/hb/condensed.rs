//! SSN-HB condensed onto the contact-force coefficients.

use std::sync::Arc;

use faer::{c64, Mat};
use semismooth::harmonic::{Aft, FourierBasis};
use semismooth::{
    EvaluationError, GeneralizedJacobian, ParameterDependent, ProblemCounters, Residual, Smoothing,
};

use super::jacobian::{ContactCoupling, HbJacobian};
use super::laws::LawSampler;
use super::ssn::{HbOptions, SsnHb};
use super::structured::{condensed_matrix, CondensedSolve, StructuredHbSolver};
use super::{check_len, HbError, LinearData, ResponseSummary};
use crate::model::{mean_stiffness, StructuralModel};
use crate::operator::OperatorParameter;

/// SSN-HB with the displacements eliminated: unknowns `Lambda` only (length `m (2H + 1)`,
/// index `j m + row`, the contacts' rows then the friction points' tangential rows).
///
/// At fixed `w` the equation of motion `A(w) U = F + G^T Lambda` gives
/// `G U = y_lin + R Lambda` with `y_lin = G A^{-1} F` and the receptance
/// `R = G A^{-1} G^T` (block diagonal per harmonic), both computed once per frequency by the
/// per-harmonic sparse LU of [`StructuredHbSolver`]. The residual is
/// `Lambda + P max(0, c (E (y_lin + R Lambda) - g) - E Lambda)` and its generalized Jacobian
/// the dense `I - Q + c Q R` (`Q = P diag(h) E` per contact): solve it with a dense LU
/// (`semismooth::linalg::FaerDenseLu`). A friction point's row measures its slip `y_t`
/// (the phase velocity of its row, module `hb::friction`) in `y_lin + R Lambda`, and its
/// equation `Lambda_t - P proj(Lambda_t - c y_t)` has the same Jacobian form with
/// `Q_t = P diag(stick) E`, plus its block `X` on its contact's force. The full solution `[U; Lambda]` of [`SsnHb`] is
/// recovered by [`CondensedSsnHb::expand`], and is a root of the full residual.
///
/// The parameter of [`ParameterDependent`] is `w`: setting it marks the factorization stale
/// (it is redone at the next evaluation; a `w` where a dynamic block is singular is outside
/// the domain), and `dR/dw = c P diag(h) E dy/dw` with `dy/dw = -G A^{-1} (dA/dw) U`,
/// `U = A^{-1} (F + G^T Lambda)`: one structured solve per evaluation.
#[derive(Debug)]
pub struct CondensedSsnHb {
    full: SsnHb,
    receptance: Vec<Mat<c64>>,
    solver: StructuredHbSolver,
    linear_response: Vec<f64>,
    contact_linear: Vec<f64>,
    y: Vec<f64>,
    /// The blocks `Q_ab` of the row groups (block diagonal by group).
    q: Vec<Mat<f64>>,
    aft: Aft,
    /// The dynamic part `A(w)` handed to the structured solver.
    dynamic: HbJacobian,
    /// Full-size workspace for `U` and `(dA/dw) U`.
    full_u: Vec<f64>,
    full_w: Vec<f64>,
    /// Sample buffers of the contact laws.
    laws: LawSampler,
    /// The active sample count of each row (the Jacobian's, unused here).
    active: Vec<usize>,
    /// Smoothing parameter `mu >= 0` of the laws' `max` terms (0: the formulation itself).
    smoothing: f64,
    /// The row groups' blocks `X` on the rows they read.
    cross: Vec<Mat<f64>>,
    /// `w` of the last factorization differs from the problem's.
    stale: bool,
}

impl CondensedSsnHb {
    /// Builds the problem at the forcing frequency `omega` and factors `A(w)` (validates
    /// like [`SsnHb::new`]; a singular dynamic block is [`HbError::Linear`]).
    pub fn new(model: &StructuralModel, omega: f64, options: &HbOptions) -> Result<Self, HbError> {
        Self::condense(SsnHb::new(model, omega, options)?)
    }

    /// The condensed form of the full problem `full` (with whatever row groups it was built
    /// with, e.g. by [`SsnHb::with_laws`]); factors its `A(w)` as [`CondensedSsnHb::new`].
    pub fn condense(full: SsnHb) -> Result<Self, HbError> {
        // The receptance blocks are read here: the dense condensed path keeps them.
        let solver = StructuredHbSolver::new().with_condensed_solve(CondensedSolve::Dense);
        Self::condense_with(full, solver)
    }

    /// [`CondensedSsnHb::new`] holding one harmonic's sparse factorization at a time: each
    /// `Z_k` is factored, solved for `Z_k^{-1} G^T` and `Z_k^{-1} F` (all the residual, the
    /// Jacobian and [`CondensedSsnHb::expand`] read) and replaced by the next, so the memory
    /// is one factor and `(2H + 1)(m + 1)` state-sized vectors instead of `H + 1` factors.
    /// The same equations and answers as [`CondensedSsnHb::new`]; each change of `w`
    /// refactors every harmonic once, and [`ParameterDependent::residual_parameter_derivative`]
    /// refactors each again (a sweep is better served by [`CondensedSsnHb::new`]).
    pub fn one_factorization_at_a_time(
        model: &StructuralModel,
        omega: f64,
        options: &HbOptions,
    ) -> Result<Self, HbError> {
        let solver = StructuredHbSolver::new()
            .with_condensed_solve(CondensedSolve::Dense)
            .with_one_factorization_at_a_time();
        Self::condense_with(SsnHb::new(model, omega, options)?, solver)
    }

    /// The condensed form of `full` with `solver` for the dynamic blocks (dense condensed
    /// solve).
    fn condense_with(full: SsnHb, solver: StructuredHbSolver) -> Result<Self, HbError> {
        let basis = full.basis();
        let (m, size) = (full.contacts(), basis.basis_size());
        let (q, cross) = full.state.linear.laws.zero_blocks(size);
        let mut this = Self {
            receptance: Vec::new(),
            solver,
            linear_response: vec![0.0; full.displacement_len()],
            contact_linear: vec![0.0; m * size],
            y: vec![0.0; m * size],
            q,
            aft: Aft::new(basis),
            dynamic: full.new_jacobian(),
            full_u: vec![0.0; full.displacement_len()],
            full_w: vec![0.0; full.displacement_len()],
            laws: LawSampler::new(&full.state.linear),
            active: vec![0; m],
            smoothing: 0.0,
            cross,
            stale: false,
            full,
        };
        this.refactor()?;
        Ok(this)
    }

    /// Factors `A(w, p)` at the current parameters, then `A^{-1} F`, `G A^{-1} F` and `R`.
    fn refactor(&mut self) -> Result<(), HbError> {
        self.dynamic.parameters = self.full.state.parameters();
        let lin = self.full.state.linear.clone();
        let (m, h) = (lin.contacts(), lin.basis.harmonics());
        lin.operator.load_coefficients(&mut self.linear_response);
        (self.solver).factor_and_apply_dynamic_inverse(&self.dynamic, &mut self.linear_response)?;
        lin.gather_measured(&self.linear_response, &mut self.contact_linear);
        self.receptance.resize_with(h + 1, || Mat::zeros(m, m));
        for (k, r) in self.receptance.iter_mut().enumerate() {
            if let Some(factored) = self.solver.receptance(k) {
                r.copy_from(factored);
            }
        }
        self.stale = false;
        Ok(())
    }

    /// Refactors when `w` changed since the last factorization.
    fn ensure_factored(&mut self) -> Result<(), EvaluationError> {
        if !self.stale {
            return Ok(());
        }
        self.refactor().map_err(|_| EvaluationError::OutsideDomain {
            what: "omega (a dynamic block of harmonic balance is singular)",
            value: self.full.omega(),
        })
    }

    /// The full problem on `[U; Lambda]` whose solutions [`CondensedSsnHb::expand`] builds.
    pub fn full_problem(&self) -> &SsnHb {
        &self.full
    }

    /// The Fourier basis (`H`, `Nt`).
    pub fn basis(&self) -> FourierBasis {
        self.full.basis()
    }

    /// The complementarity constant `c`.
    pub fn c(&self) -> f64 {
        self.full.c()
    }

    /// Sets the complementarity constant `c` (finite, `> 0`).
    pub fn set_c(&mut self, c: f64) -> Result<(), HbError> {
        self.full.set_c(c)
    }

    /// Static stiffness seen by the contacts: the mean over contacts of
    /// `1 / (G K^{-1} G^T)_ii` (for the rod, `EA / L` whatever the mesh), the formula of
    /// [`StructuralModel::static_contact_stiffness`] on the harmonic-0 receptance already
    /// factored here; 1 without contacts (or when `K` is not positive definite). A
    /// mesh-independent scale for `c`, unlike `K[dof, dof]` (which grows like the element
    /// count); see [`CondensedSsnHb::set_c`].
    pub fn static_contact_stiffness(&self) -> f64 {
        let compliances = self
            .receptance
            .first()
            .into_iter()
            .flat_map(|r0| (0..r0.nrows()).map(|i| r0[(i, i)].re));
        mean_stiffness(compliances).unwrap_or(1.0)
    }

    /// Current angular frequency `w`.
    pub fn omega(&self) -> f64 {
        self.full.omega()
    }

    /// Sets `w` and refactors the dynamic blocks.
    pub fn set_omega(&mut self, omega: f64) -> Result<(), HbError> {
        self.full.set_omega(omega)?;
        self.refactor()
    }

    /// The modal damping `xi` of the operator (`D - xi M`; 0 by default).
    pub fn modal_damping(&self) -> f64 {
        self.full.modal_damping()
    }

    /// Sets the modal damping `xi` (finite) at fixed `w` and refactors the dynamic blocks
    /// when it changed.
    pub fn set_modal_damping(&mut self, xi: f64) -> Result<(), HbError> {
        self.full.set_modal_damping(xi)?;
        self.refactor()
    }

    /// Number of times the dynamic blocks were factored (once per change of `w` or `xi`).
    pub fn dynamic_factorizations(&self) -> u64 {
        self.solver.dynamic_factorizations()
    }

    /// The full unknowns `[U; Lambda]` of [`SsnHb`] from `Lambda` at the current `w`:
    /// `U = A^{-1} (F + G^T Lambda)` (refactoring first if `w` changed).
    pub fn expand(&mut self, lambda: &[f64]) -> Result<Vec<f64>, HbError> {
        check_len("contact-force coefficients", self.dim(), lambda.len())?;
        if self.stale {
            self.refactor()?;
        }
        let mut x = self.linear_response.clone();
        self.solver.add_response(lambda, 1.0, &mut x);
        x.extend_from_slice(lambda);
        Ok(x)
    }

    /// [`SsnHb::summary`] of the expanded solution.
    pub fn summary(
        &mut self,
        lambda: &[f64],
        dof: usize,
        points: usize,
    ) -> Result<ResponseSummary, HbError> {
        let x = self.expand(lambda)?;
        self.full.summary(&x, dof, points)
    }

    /// `self.y = y_lin + R Lambda` (contact-displacement coefficients).
    fn contact_displacements(&mut self, lambda: &[f64]) {
        let m = self.full.contacts();
        self.y.copy_from_slice(&self.contact_linear);
        for (k, r) in self.receptance.iter().enumerate() {
            for i in 0..m {
                for ip in 0..m {
                    let (cr, ci) = (r[(i, ip)].re, r[(i, ip)].im);
                    if k == 0 {
                        self.y[i] += cr * lambda[ip];
                    } else {
                        let (c, s) = ((2 * k - 1) * m, 2 * k * m);
                        let (pc, ps) = (lambda[c + ip], lambda[s + ip]);
                        self.y[c + i] += cr * pc + ci * ps;
                        self.y[s + i] += -ci * pc + cr * ps;
                    }
                }
            }
        }
    }

    /// Forms `y = y_lin + R Lambda` (factoring first if needed), then samples each group
    /// `g` of the laws in turn ([`CondensedSsnHb::sample_group`]) and calls `each` on it;
    /// the linear data the groups were read from.
    fn for_each_group(
        &mut self,
        lambda: &[f64],
        mut each: impl FnMut(&mut Self, &LinearData, usize),
    ) -> Result<Arc<LinearData>, EvaluationError> {
        self.ensure_factored()?;
        let lin = self.full.state.linear.clone();
        self.contact_displacements(lambda);
        for g in 0..lin.laws.groups.len() {
            self.sample_group(lambda, g);
            each(self, &lin, g);
        }
        Ok(lin)
    }

    /// Samples group `g`'s arguments `z = lambda - c (y - o)` and the forces it reads
    /// from `y = y_lin + R Lambda`.
    fn sample_group(&mut self, lambda: &[f64], g: usize) {
        let lin = &self.full.state.linear;
        let (m, y) = (lin.contacts(), &self.y);
        let measured = |row: usize, j: usize| y[j * m + row];
        let at = (g, self.full.c(), self.full.omega());
        (self.laws).sample(&mut self.aft, lin, at, lambda, measured);
    }
}

impl Residual for CondensedSsnHb {
    fn dim(&self) -> usize {
        self.full.contacts() * self.full.basis().basis_size()
    }

    fn residual(&mut self, lambda: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        self.for_each_group(lambda, |s, lin, g| {
            (s.laws).residual(&mut s.aft, lin, (g, s.smoothing), lambda, out);
        })?;
        Ok(())
    }

    /// `ffts`: the transforms of the alternating frequency/time scheme.
    fn problem_counters(&self) -> ProblemCounters {
        ProblemCounters::new().with("ffts", self.aft.fft_count())
    }
}

impl GeneralizedJacobian for CondensedSsnHb {
    type Jacobian = Mat<f64>;

    fn new_jacobian(&self) -> Mat<f64> {
        let n = self.dim();
        Mat::zeros(n, n)
    }

    fn jacobian(&mut self, lambda: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        let lin = self.for_each_group(lambda, |s, lin, g| {
            let blocks = (s.q.as_mut_slice(), s.cross.as_mut_slice());
            (s.laws).jacobian(&mut s.aft, lin, (g, s.smoothing), blocks, &mut s.active);
        })?;
        let m = lin.contacts();
        condensed_matrix(
            &self.receptance,
            (&lin.laws, &self.q, &self.cross),
            ContactCoupling::Complementarity { c: self.full.c() },
            m,
            jac.as_mut(),
        );
        Ok(())
    }
}

impl ParameterDependent for CondensedSsnHb {
    fn parameter(&self) -> f64 {
        self.full.omega()
    }

    /// Sets `w`; the dynamic blocks are refactored at the next evaluation.
    fn set_parameter(&mut self, omega: f64) {
        if omega.to_bits() != self.full.omega().to_bits() {
            self.full.set_parameter(omega);
            self.stale = true;
        }
    }

    /// `dR/dw = c P diag(d proj / dz) E dy/dw` per group, `dy/dw = -G A^{-1} (dA/dw) U` (type documentation).
    fn residual_parameter_derivative(
        &mut self,
        lambda: &[f64],
        out: &mut [f64],
        _scratch: &mut [f64],
    ) -> Result<(), EvaluationError> {
        self.ensure_factored()?;
        let lin = self.full.state.linear.clone();
        // U = A^{-1} F + A^{-1} G^T Lambda.
        self.full_u.copy_from_slice(&self.linear_response);
        self.solver.add_response(lambda, 1.0, &mut self.full_u);
        let parameters = self.full.state.parameters();
        let omega = OperatorParameter::Omega;
        (lin.operator).apply_derivative(&parameters, omega, &self.full_u, &mut self.full_w);
        self.solver
            .apply_dynamic_inverse(&mut self.full_w)
            .map_err(|_| EvaluationError::OutsideDomain {
                what: "omega (a dynamic block of harmonic balance is singular)",
                value: self.full.omega(),
            })?;
        self.contact_displacements(lambda);
        let c = self.full.c();
        // dy/dw = -G A^{-1} (dA/dw) U.
        let moved = std::mem::take(&mut self.full_w);
        // (and the sliding offsets s / w move by -s / w^2: as y by s / w^2).
        let omega = self.full.omega();
        let dy = |row: usize, j: usize| {
            let sliding = if j == 0 {
                lin.laws.sliding[row] / (omega * omega)
            } else {
                0.0
            };
            sliding - lin.measured_coefficient(row, &moved, j)
        };
        for g in 0..lin.laws.groups.len() {
            self.sample_group(lambda, g);
            let at = (g, c, self.smoothing);
            (self.laws).measured_response(&mut self.aft, &lin, at, dy, out);
        }
        self.full_w = moved;
        Ok(())
    }
}

/// The smoothing path of [`SsnHb`] on the condensed unknowns: each `max` of the laws
/// becomes `phi_mu` (the polyalgorithm's start from far away).
impl Smoothing for CondensedSsnHb {
    /// As [`SsnHb`]'s, from the contact rows' linear response `y_lin` held here.
    fn smoothing_scale(&self) -> f64 {
        if self.stale {
            return self.full.smoothing_scale();
        }
        (self.full.state.linear.laws).smoothing_scale(self.full.c(), Some(&self.contact_linear))
    }

    fn set_smoothing(&mut self, mu: f64) {
        self.smoothing = mu.max(0.0);
    }

    /// `dR/dmu = -P d proj / d mu` of each group's law.
    fn residual_smoothing_derivative(
        &mut self,
        lambda: &[f64],
        out: &mut [f64],
    ) -> Result<(), EvaluationError> {
        self.for_each_group(lambda, |s, lin, g| {
            (s.laws).smoothing_derivative(&mut s.aft, lin, (g, s.smoothing), out);
        })?;
        Ok(())
    }
}
