//! SSN-HB condensed onto the contact-force coefficients.

use faer::{c64, Mat};
use semismooth::harmonic::{Aft, FourierBasis};
use semismooth::{
    EvaluationError, Factorize, GeneralizedJacobian, ParameterDependent, ProblemCounters, Residual,
    Smoothing,
};

use super::friction::{self, FrictionSamples};
use super::jacobian::{ContactCoupling, HbJacobian};
use super::ssn::{smoothed_max, smoothed_max_mu_derivative, smoothed_max_slope, HbOptions, SsnHb};
use super::structured::{condensed_matrix, CondensedSolve, CrossBlocks, StructuredHbSolver};
use super::{check_len, indicator, HbError, ResponseSummary};
use crate::model::{mean_stiffness, NormalForce, StructuralModel};
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
    /// `Q_i = P diag(h_i) E` per contact.
    q: Vec<Mat<f64>>,
    aft: Aft,
    /// The dynamic part `A(w)` handed to the structured solver.
    dynamic: HbJacobian,
    /// Full-size workspace for `U` and `(dA/dw) U`.
    full_u: Vec<f64>,
    full_w: Vec<f64>,
    /// Indicator `h_n` of the active samples, or a friction point's stick weights (for
    /// `dR/dw`).
    mask: Vec<f64>,
    /// Sample buffers of the friction law.
    friction: FrictionSamples,
    /// Smoothing parameter `mu >= 0` of the laws' `max` terms (0: the formulation itself).
    smoothing: f64,
    /// The friction points' blocks `X` on their contacts' forces.
    cross: CrossBlocks,
    /// `w` of the last factorization differs from the problem's.
    stale: bool,
}

impl CondensedSsnHb {
    /// Builds the problem at the forcing frequency `omega` and factors `A(w)` (validates
    /// like [`SsnHb::new`]; a singular dynamic block is [`HbError::Linear`]).
    pub fn new(model: &StructuralModel, omega: f64, options: &HbOptions) -> Result<Self, HbError> {
        let full = SsnHb::new(model, omega, options)?;
        let basis = full.basis();
        let (m, size) = (full.contacts(), basis.basis_size());
        let mut this = Self {
            receptance: Vec::new(),
            // The receptance blocks are read here: the dense condensed path keeps them.
            solver: StructuredHbSolver::new().with_condensed_solve(CondensedSolve::Dense),
            linear_response: vec![0.0; full.displacement_len()],
            contact_linear: vec![0.0; m * size],
            y: vec![0.0; m * size],
            q: (0..m).map(|_| Mat::zeros(size, size)).collect(),
            aft: Aft::new(basis),
            dynamic: full.new_jacobian(),
            full_u: vec![0.0; full.displacement_len()],
            full_w: vec![0.0; full.displacement_len()],
            mask: vec![0.0; basis.time_samples()],
            friction: FrictionSamples::new(basis.time_samples()),
            smoothing: 0.0,
            cross: CrossBlocks::new(&full.state.linear),
            stale: false,
            full,
        };
        this.refactor()?;
        Ok(this)
    }

    /// Factors `A(w, p)` at the current parameters, then `A^{-1} F`, `G A^{-1} F` and `R`.
    fn refactor(&mut self) -> Result<(), HbError> {
        self.dynamic.parameters = self.full.state.parameters();
        self.solver.factor(&self.dynamic)?;
        let lin = self.full.state.linear.clone();
        let (m, h) = (lin.contacts(), lin.basis.harmonics());
        lin.operator.load_coefficients(&mut self.linear_response);
        self.solver
            .apply_dynamic_inverse(&mut self.linear_response)?;
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

    /// Samples of `s = c (G u - g) - lambda` of contact `i` into the AFT's samples.
    fn switching_samples(&mut self, lambda: &[f64], i: usize) {
        let lin = &self.full.state.linear;
        let m = lin.contacts();
        let c = self.full.c();
        let coeffs = self.aft.coefficients_mut();
        for (j, coeff) in coeffs.iter_mut().enumerate() {
            *coeff = c * self.y[j * m + i] - lambda[j * m + i];
        }
        coeffs[0] -= c * lin.gaps[i];
        self.aft.coefficients_to_samples();
    }

    /// [`friction::point_samples`] of friction point `f` from `y = y_lin + R Lambda`.
    fn friction_samples(&mut self, lambda: &[f64], f: usize) {
        let lin = &self.full.state.linear;
        let i = lin.normal_rows() + f;
        let (m, y) = (lin.contacts(), &self.y);
        let c = self.full.c();
        friction::point_samples(
            &mut self.aft,
            lin,
            f,
            c,
            lambda,
            |j| y[j * m + i],
            &mut self.friction,
        );
    }

    /// The weights of row `i`'s block `Q_i = P diag(w) E` into the AFT's samples: the
    /// indicator `h` of a contact's switching function (its smoothed slope when
    /// smoothing), a friction point's stick weights (its block `X`'s weights then in
    /// `self.friction`).
    fn activity_weights(&mut self, lambda: &[f64], i: usize) {
        let lin = self.full.state.linear.clone();
        let mu = self.smoothing;
        match i.checked_sub(lin.normal_rows()) {
            None if mu > 0.0 => {
                self.switching_samples(lambda, i);
                for s in self.aft.samples_mut() {
                    *s = smoothed_max_slope(*s, mu);
                }
            }
            None => {
                self.switching_samples(lambda, i);
                indicator(self.aft.samples_mut());
            }
            Some(f) => {
                self.friction_samples(lambda, f);
                friction::point_jacobian_weights(&mut self.aft, &lin, f, &mut self.friction, mu);
            }
        }
    }
}

impl Residual for CondensedSsnHb {
    fn dim(&self) -> usize {
        self.full.contacts() * self.full.basis().basis_size()
    }

    fn residual(&mut self, lambda: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        self.ensure_factored()?;
        let lin = self.full.state.linear.clone();
        let m = lin.contacts();
        self.contact_displacements(lambda);
        for i in 0..lin.normal_rows() {
            self.switching_samples(lambda, i);
            let mu = self.smoothing;
            for s in self.aft.samples_mut() {
                *s = smoothed_max(*s, mu);
            }
            self.aft.samples_to_coefficients();
            for (j, c) in self.aft.coefficients().iter().enumerate() {
                out[j * m + i] = lambda[j * m + i] + c;
            }
        }
        for f in 0..lin.friction.len() {
            self.friction_samples(lambda, f);
            let mu = self.smoothing;
            friction::point_residual(&mut self.aft, &lin, f, lambda, &self.friction, mu, out);
        }
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
        self.ensure_factored()?;
        let lin = self.full.state.linear.clone();
        let m = lin.contacts();
        self.contact_displacements(lambda);
        for i in 0..m {
            self.activity_weights(lambda, i);
            self.aft.samples_multiplication_matrix(&mut self.q[i]);
            if let Some(f) = i.checked_sub(lin.normal_rows()) {
                if matches!(lin.friction[f].1, NormalForce::Contact(_)) {
                    let weights = self.friction.cross_weights();
                    self.aft.samples_mut().copy_from_slice(weights);
                    self.aft
                        .samples_multiplication_matrix(self.cross.block_mut(f));
                }
            }
        }
        condensed_matrix(
            &self.receptance,
            &self.q,
            &self.cross,
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

    /// `dR/dw = c P diag(h) E dy/dw`, `dy/dw = -G A^{-1} (dA/dw) U` (type documentation).
    fn residual_parameter_derivative(
        &mut self,
        lambda: &[f64],
        out: &mut [f64],
        _scratch: &mut [f64],
    ) -> Result<(), EvaluationError> {
        self.ensure_factored()?;
        let lin = self.full.state.linear.clone();
        let m = lin.contacts();
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
        for i in 0..m {
            self.activity_weights(lambda, i);
            self.mask.copy_from_slice(self.aft.samples());
            for (j, coeff) in self.aft.coefficients_mut().iter_mut().enumerate() {
                *coeff = -c * lin.measured_coefficient(i, &self.full_w, j);
            }
            self.aft.coefficients_to_samples();
            for (s, h) in self.aft.samples_mut().iter_mut().zip(&self.mask) {
                *s *= h;
            }
            self.aft.samples_to_coefficients();
            for (j, coeff) in self.aft.coefficients().iter().enumerate() {
                out[j * m + i] = *coeff;
            }
        }
        Ok(())
    }
}

/// The smoothing path of [`SsnHb`] on the condensed unknowns: each `max` of the laws
/// becomes `phi_mu` (the polyalgorithm's start from far away).
impl Smoothing for CondensedSsnHb {
    fn smoothing_scale(&self) -> f64 {
        self.full.smoothing_scale()
    }

    fn set_smoothing(&mut self, mu: f64) {
        self.smoothing = mu.max(0.0);
    }

    /// `dR/dmu`: `P phi_mu'` of the switching samples for a contact, `-P d proj / d mu` of
    /// a friction point's.
    fn residual_smoothing_derivative(
        &mut self,
        lambda: &[f64],
        out: &mut [f64],
    ) -> Result<(), EvaluationError> {
        self.ensure_factored()?;
        let lin = self.full.state.linear.clone();
        let (m, mu) = (lin.contacts(), self.smoothing);
        self.contact_displacements(lambda);
        for i in 0..m {
            match i.checked_sub(lin.normal_rows()) {
                None => {
                    self.switching_samples(lambda, i);
                    for s in self.aft.samples_mut() {
                        *s = smoothed_max_mu_derivative(*s, mu);
                    }
                }
                Some(f) => {
                    self.friction_samples(lambda, f);
                    let bounds = self.friction.bounds();
                    for (z, b) in self.aft.samples_mut().iter_mut().zip(bounds) {
                        *z = -friction::projection_mu_derivative(*z, *b, mu);
                    }
                }
            }
            self.aft.samples_to_coefficients();
            for (j, c) in self.aft.coefficients().iter().enumerate() {
                out[j * m + i] = *c;
            }
        }
        Ok(())
    }
}
