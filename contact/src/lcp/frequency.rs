//! The periodic LCP as an equation in the gaps and the forces, parametrised by the forcing
//! frequency, for pseudo-arclength continuation in `omega` (method `"lcp-ssn"` of
//! `ssn sweep`).
//!
//! Unknowns `y = (w, z)`: the gaps `w` (a length) and the compressive forces `z` (a force) at
//! the `Nt` time nodes (time-major, `m Nt` each), and
//!
//! ```text
//! F1 = w - q(omega) - A(omega) z = 0,        F2 = min(z, kappa w) = 0,
//! ```
//!
//! `kappa > 0` a stiffness scale, so that both arguments of the min are forces. Solutions
//! are those of the LCP `w = q + A z, w >= 0, z >= 0, w . z = 0` of [`PeriodicLcp`].
//! Unlike the min-map in `z` alone, the free response moves the unknowns (`w = q`, `z = 0`
//! below contact onset), and the contact onset is an ordinary switch of the min.
//!
//! Jacobian: rows `F1` are `[I, -A]`; row `i` of `F2` is `e_i` on `z` where `z_i` is the min
//! (*inactive*, a tie included) and `kappa e_i` on `w` where `kappa w_i < z_i` (*active*).
//! [`FrequencyLcpSolver`] solves `J (dw, dz) = (r1, r2)` as `dz_J = r2_J` on the inactive
//! rows, `dw_I = r2_I / kappa` on the active ones, then
//! `A_II dz_I = dw_I - r1_I - A_IJ dz_J` (one `|I| x |I|` LU) and `dw_J = r1_J + (A dz)_J`.
//! `J` is singular exactly when `A_II` is.
//!
//! The parameter derivative is analytic: `dF1/domega = -(dq/domega + dA/domega z)`
//! ([`PeriodicLcp::frequency_derivative`]); `dF2/domega = 0`.

use std::rc::Rc;

use faer::MatMut;
use semismooth::complementarity::min_function;
use semismooth::linalg::{DenseAssemble, LinearSolveError};
use semismooth::InvalidOption;
use semismooth::{
    EvaluationError, Factorize, GeneralizedJacobian, LinearSolve, ParameterDependent, Residual,
};

use super::min_map::{add_mat_vec, ActiveSetSolver};
use super::{LcpError, PeriodicLcp, PeriodicLcpOptions};
use crate::model::StructuralModel;

/// The LCPs kept for recent frequencies: the corrector moves `omega` at every iteration
/// and a failed step returns to the last accepted point.
const CACHE: usize = 2;

/// `F(w, z; omega) = (w - q - A z, min(z, kappa w))` (module documentation).
#[derive(Debug, Clone)]
pub struct FrequencyLcp {
    model: StructuralModel,
    options: PeriodicLcpOptions,
    kappa: f64,
    omega: f64,
    /// Most recent first.
    cache: Vec<Rc<PeriodicLcp>>,
    scratch: Vec<f64>,
}

impl FrequencyLcp {
    /// The problem for `model` starting at the forcing frequency `omega`, with
    /// `options.time_samples` steps per period and the force scale `kappa` (finite, `> 0`).
    /// Builds the first LCP, so that a model the LCP cannot handle (no contact, bad option or
    /// frequency) is reported here. The model is kept (one copy); every frequency's LCP is
    /// built from it.
    pub fn new(
        model: &StructuralModel,
        omega: f64,
        options: PeriodicLcpOptions,
        kappa: f64,
    ) -> Result<Self, LcpError> {
        if !(kappa.is_finite() && kappa > 0.0) {
            return Err(LcpError::InvalidOption(InvalidOption::new(
                "kappa",
                kappa,
                "a finite number > 0",
            )));
        }
        let lcp = PeriodicLcp::with_frequency_derivative(model, omega, options.clone())?;
        let n = lcp.dim();
        Ok(Self {
            model: model.clone(),
            options,
            kappa,
            omega,
            cache: vec![Rc::new(lcp)],
            scratch: vec![0.0; n],
        })
    }

    /// Size `m Nt` of each half `w`, `z` of the unknowns.
    pub fn half(&self) -> usize {
        self.scratch.len()
    }

    /// The force scale `kappa`.
    pub fn kappa(&self) -> f64 {
        self.kappa
    }

    /// The unknowns `(w, z)` of a solution `z` of the LCP at the current frequency:
    /// `w = q + A z`.
    pub fn state_from_forces(&mut self, z: &[f64]) -> Result<Vec<f64>, LcpError> {
        let lcp = self.current()?;
        let mut y = lcp.gap(z)?;
        y.extend_from_slice(z);
        Ok(y)
    }

    /// The LCP at `omega`: the cached one, or a new one (not cached).
    pub fn lcp_at(&self, omega: f64) -> Result<Rc<PeriodicLcp>, LcpError> {
        if let Some(lcp) = self.cache.iter().find(|l| l.omega() == omega) {
            return Ok(lcp.clone());
        }
        Ok(Rc::new(PeriodicLcp::with_frequency_derivative(
            &self.model,
            omega,
            self.options.clone(),
        )?))
    }

    /// The LCP at the current frequency, built if needed.
    pub fn current(&mut self) -> Result<Rc<PeriodicLcp>, LcpError> {
        if let Some(i) = self.cache.iter().position(|l| l.omega() == self.omega) {
            let lcp = self.cache.remove(i);
            self.cache.insert(0, lcp.clone());
            return Ok(lcp);
        }
        let lcp = Rc::new(PeriodicLcp::with_frequency_derivative(
            &self.model,
            self.omega,
            self.options.clone(),
        )?);
        self.cache.insert(0, lcp.clone());
        self.cache.truncate(CACHE);
        Ok(lcp)
    }

    /// The current LCP; a frequency where it cannot be built (a bin of the dynamic
    /// stiffness singular) is outside the problem's domain.
    fn current_in_domain(&mut self) -> Result<Rc<PeriodicLcp>, EvaluationError> {
        self.current().map_err(|_| EvaluationError::OutsideDomain {
            what: "omega (the periodic LCP cannot be built at this frequency)",
            value: self.omega,
        })
    }
}

impl Residual for FrequencyLcp {
    fn dim(&self) -> usize {
        2 * self.half()
    }

    fn residual(&mut self, y: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        let lcp = self.current_in_domain()?;
        let n = self.half();
        let (w, z) = y.split_at(n);
        let (f1, f2) = out.split_at_mut(n);
        // F1 = w - q - A z.
        self.scratch.copy_from_slice(lcp.q());
        add_mat_vec(lcp.matrix(), z, &mut self.scratch);
        for ((f, wi), g) in f1.iter_mut().zip(w).zip(&self.scratch) {
            *f = wi - g;
        }
        for ((f, zi), wi) in f2.iter_mut().zip(z).zip(w) {
            *f = min_function(*zi, self.kappa * wi).value;
        }
        Ok(())
    }
}

impl GeneralizedJacobian for FrequencyLcp {
    type Jacobian = FrequencyLcpJacobian;

    fn new_jacobian(&self) -> FrequencyLcpJacobian {
        FrequencyLcpJacobian {
            lcp: None,
            active: vec![false; self.half()],
            kappa: self.kappa,
        }
    }

    fn jacobian(
        &mut self,
        y: &[f64],
        jac: &mut FrequencyLcpJacobian,
    ) -> Result<(), EvaluationError> {
        let n = self.half();
        let (w, z) = y.split_at(n);
        for ((a, zi), wi) in jac.active.iter_mut().zip(z).zip(w) {
            // min_function's gradient is (0, 1) exactly where kappa w < z (tie: (1, 0)).
            *a = min_function(*zi, self.kappa * wi).db == 1.0;
        }
        jac.kappa = self.kappa;
        jac.lcp = Some(self.current_in_domain()?);
        Ok(())
    }
}

impl ParameterDependent for FrequencyLcp {
    fn parameter(&self) -> f64 {
        self.omega
    }

    /// Sets `omega`; the LCP is (re)built lazily at the next evaluation.
    fn set_parameter(&mut self, omega: f64) {
        self.omega = omega;
    }

    /// `dF1/domega = -d(q + A z)/domega` (analytic), `dF2/domega = 0`.
    fn residual_parameter_derivative(
        &mut self,
        y: &[f64],
        out: &mut [f64],
        _scratch: &mut [f64],
    ) -> Result<(), EvaluationError> {
        let n = self.half();
        let lcp = self.current_in_domain()?;
        lcp.frequency_derivative(&y[n..], &mut out[..n])
            .map_err(|_| EvaluationError::OutsideDomain {
                what: "omega (the frequency derivative of the periodic LCP is unavailable)",
                value: self.omega,
            })?;
        for o in out[..n].iter_mut() {
            *o = -*o;
        }
        out[n..].fill(0.0);
        Ok(())
    }
}

/// An element of the generalized Jacobian of [`FrequencyLcp`]: `[[I, -A], [kappa P_I,
/// P_J]]` with `P_I`, `P_J` the selections of the active and inactive rows.
#[derive(Debug, Clone)]
pub struct FrequencyLcpJacobian {
    /// The LCP at the frequency of the last evaluation (`None` before the first).
    lcp: Option<Rc<PeriodicLcp>>,
    active: Vec<bool>,
    kappa: f64,
}

impl FrequencyLcpJacobian {
    /// Which rows of `F2` are active (`kappa w_i < z_i`: in contact).
    pub fn active(&self) -> &[bool] {
        &self.active
    }

    /// Number of active rows.
    pub fn active_count(&self) -> usize {
        self.active.iter().filter(|a| **a).count()
    }
}

impl DenseAssemble for FrequencyLcpJacobian {
    fn dim(&self) -> usize {
        2 * self.active.len()
    }

    /// The `2 m Nt` square matrix (NaN everywhere before the first evaluation).
    fn assemble_dense(&self, mut out: MatMut<'_, f64>) {
        let n = self.active.len();
        let Some(lcp) = &self.lcp else {
            out.fill(f64::NAN);
            return;
        };
        let a = lcp.matrix();
        out.fill(0.0);
        for i in 0..n {
            out[(i, i)] = 1.0;
            for j in 0..n {
                out[(i, n + j)] = -a[(i, j)];
            }
            if self.active[i] {
                out[(n + i, i)] = self.kappa;
            } else {
                out[(n + i, n + i)] = 1.0;
            }
        }
    }
}

/// Solves with a [`FrequencyLcpJacobian`] by one LU of the active block `A_II` (module
/// documentation): the `z` part is the min-map system `[A_I; P_J] dz = (r2_I / kappa - r1_I,
/// r2_J)` of [`ActiveSetSolver`] (without regularisation, its default: a singular or non-finite
/// block is a [`LinearSolveError`], and the continuation halves its step), then
/// `dw = r1 + A dz` on the inactive rows and `r2 / kappa` on the active ones.
#[derive(Debug)]
pub struct FrequencyLcpSolver {
    lcp: Option<Rc<PeriodicLcp>>,
    active: Vec<bool>,
    kappa: f64,
    block: ActiveSetSolver,
    /// Scratch: `dw`, and `r2_I / kappa` on the active rows (in order).
    dw: Vec<f64>,
    dw_active: Vec<f64>,
}

impl Default for FrequencyLcpSolver {
    fn default() -> Self {
        Self::new()
    }
}

impl FrequencyLcpSolver {
    /// A solver with the default relative pivot threshold of [`ActiveSetSolver`].
    pub fn new() -> Self {
        Self {
            lcp: None,
            active: Vec::new(),
            kappa: 1.0,
            block: ActiveSetSolver::new(),
            dw: Vec::new(),
            dw_active: Vec::new(),
        }
    }

    /// Size of the active block of the last factorization.
    pub fn active_count(&self) -> usize {
        self.block.active_count()
    }
}

impl Factorize<FrequencyLcpJacobian> for FrequencyLcpSolver {
    fn factor(&mut self, jac: &FrequencyLcpJacobian) -> Result<(), LinearSolveError> {
        self.lcp = None;
        // A Jacobian never evaluated holds no matrix: nothing to factor.
        let lcp = jac.lcp.clone().ok_or(LinearSolveError::NotFactored)?;
        self.block.factor_rows(lcp.matrix(), &jac.active)?;
        self.active.clone_from(&jac.active);
        self.kappa = jac.kappa;
        self.lcp = Some(lcp);
        Ok(())
    }
}

impl LinearSolve for FrequencyLcpSolver {
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        let lcp = self.lcp.as_ref().ok_or(LinearSolveError::NotFactored)?;
        let n = self.active.len();
        if rhs.len() != 2 * n {
            return Err(LinearSolveError::DimensionMismatch {
                expected: 2 * n,
                found: rhs.len(),
            });
        }
        let (r1, r2) = rhs.split_at_mut(n);
        // dw_I = r2_I / kappa (kept aside); r2 becomes the min-map right-hand side, then dz.
        self.dw_active.clear();
        for (i, &active) in self.active.iter().enumerate() {
            if active {
                let dw = r2[i] / self.kappa;
                self.dw_active.push(dw);
                r2[i] = dw - r1[i];
            }
        }
        self.block.solve_in_place(r2)?;
        // dw = r1 + A dz on the inactive rows.
        self.dw.clear();
        self.dw.extend_from_slice(r1);
        add_mat_vec(lcp.matrix(), r2, &mut self.dw);
        let mut kept = self.dw_active.iter();
        for (dw, &active) in self.dw.iter_mut().zip(&self.active) {
            if active {
                *dw = *kept.next().unwrap_or(&f64::NAN);
            }
        }
        r1.copy_from_slice(&self.dw);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lcp::LcpScheme;
    use crate::rod::{build_rod, MassModel, RodSpec};
    use semismooth::linalg::FaerDenseLu;

    fn problem(nt: usize) -> FrequencyLcp {
        problem_with(nt, LcpScheme::Trapezoidal)
    }

    fn problem_with(nt: usize, scheme: LcpScheme) -> FrequencyLcp {
        let mut spec = RodSpec::canonical();
        spec.mass = MassModel::Modified;
        let rod = build_rod(&spec).unwrap();
        let options = PeriodicLcpOptions {
            time_samples: nt,
            scheme,
            ..Default::default()
        };
        let kappa = rod.model.contact_stiffness_scale();
        FrequencyLcp::new(&rod.model, rod.omega(), options, kappa).unwrap()
    }

    /// A state with both active and inactive rows: `z` positive on half of the nodes.
    fn state(p: &FrequencyLcp) -> Vec<f64> {
        let n = p.half();
        let mut y = vec![0.0; 2 * n];
        for i in 0..n {
            let t = i as f64 / n as f64;
            y[i] = 0.3 * (2.0 * std::f64::consts::PI * t).sin();
            y[n + i] = (0.2 * (2.0 * std::f64::consts::PI * t).cos()).max(0.0) + 0.01;
        }
        y
    }

    #[test]
    fn structured_solve_matches_dense_lu_of_the_assembled_jacobian() {
        let mut p = problem(32);
        let y = state(&p);
        let mut jac = p.new_jacobian();
        p.jacobian(&y, &mut jac).unwrap();
        assert!(jac.active_count() > 0 && jac.active_count() < p.half());
        let rhs: Vec<f64> = (0..p.dim()).map(|i| (0.37 * i as f64).sin()).collect();
        let mut x1 = rhs.clone();
        let mut solver = FrequencyLcpSolver::new();
        solver.factor(&jac).unwrap();
        solver.solve_in_place(&mut x1).unwrap();
        let mut x2 = rhs.clone();
        let mut dense = FaerDenseLu::new();
        dense.factor(&jac).unwrap();
        dense.solve_in_place(&mut x2).unwrap();
        let scale = x2.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // Two backward-stable solves; the active block of A (entries O(1), smallest
        // receptance O(1e-2)) keeps the condition number moderate: 1e-10 relative.
        for (u, v) in x1.iter().zip(&x2) {
            assert!((u - v).abs() <= 1e-10 * scale, "{u} vs {v}");
        }
    }

    #[test]
    fn parameter_derivative_matches_central_differences_of_lcp_builds() {
        for scheme in [LcpScheme::Trapezoidal, LcpScheme::Bdf2] {
            parameter_derivative_matches_central_differences(scheme);
        }
    }

    fn parameter_derivative_matches_central_differences(scheme: LcpScheme) {
        let mut p = problem_with(32, scheme);
        let y = state(&p);
        let omega = p.parameter();
        let mut analytic = vec![0.0; p.dim()];
        p.residual_parameter_derivative(&y, &mut analytic, &mut vec![0.0; p.dim()])
            .unwrap();
        // Central differences at the resonance (zeta = 0.01: F varies on the scale
        // zeta omega): truncation (h / (zeta omega))^2 ~ 1e-8 relative, rounding
        // 1e-16 |F| / h ~ 1e-10 of the derivative (|F| ~ 1, |F'| ~ 1e2).
        let h = 1e-6 * omega;
        let mut plus = vec![0.0; p.dim()];
        let mut minus = vec![0.0; p.dim()];
        p.set_parameter(omega + h);
        p.residual(&y, &mut plus).unwrap();
        p.set_parameter(omega - h);
        p.residual(&y, &mut minus).unwrap();
        let scale = analytic.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0);
        for i in 0..p.dim() {
            let fd = (plus[i] - minus[i]) / (2.0 * h);
            assert!(
                (fd - analytic[i]).abs() <= 1e-6 * scale,
                "{scheme:?} {i}: {fd} vs {}",
                analytic[i]
            );
        }
    }

    #[test]
    fn singular_active_block_is_a_linear_solve_error() {
        // All nodes active: A_II = A, which has the alternating null vector of the
        // damped massless tip (Nyquist receptance 0 with stiffness-proportional damping).
        let mut spec = RodSpec::canonical();
        spec.mass = MassModel::Modified;
        let rod = build_rod(&spec).unwrap();
        let options = PeriodicLcpOptions {
            time_samples: 16,
            ..Default::default()
        };
        let mut p = FrequencyLcp::new(&rod.model, rod.omega(), options, 1.0).unwrap();
        let n = p.half();
        let mut y = vec![0.0; 2 * n];
        y[n..].fill(1.0); // z = 1 > kappa w = 0 everywhere
        let mut jac = p.new_jacobian();
        p.jacobian(&y, &mut jac).unwrap();
        assert_eq!(jac.active_count(), n);
        let mut solver = FrequencyLcpSolver::new();
        assert!(matches!(
            solver.factor(&jac),
            Err(LinearSolveError::Singular { .. })
        ));
    }
}
