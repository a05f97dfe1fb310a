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

use faer::linalg::solvers::{PartialPivLu, Solve};
use faer::{Mat, MatMut};
use semismooth::complementarity::min_function;
use semismooth::linalg::{check_pivots, DenseAssemble, LinearSolveError, DEFAULT_PIVOT_THRESHOLD};
use semismooth::{GeneralizedJacobian, LinearSolve, ParameterDependent, Residual};

use super::min_map::add_mat_vec;
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
    last_error: Option<LcpError>,
    builds: u64,
    scratch: Vec<f64>,
}

impl FrequencyLcp {
    /// The problem for `model` at its forcing frequency, with `options.time_samples` steps
    /// per period and the force scale `kappa` (finite, `> 0`). Builds the first LCP, so
    /// that a model the LCP cannot handle (no contact, bad option) is reported here.
    pub fn new(
        model: &StructuralModel,
        options: PeriodicLcpOptions,
        kappa: f64,
    ) -> Result<Self, LcpError> {
        if !(kappa.is_finite() && kappa > 0.0) {
            return Err(LcpError::InvalidOption {
                name: "kappa",
                value: kappa,
                allowed: "a finite number > 0",
            });
        }
        let lcp = PeriodicLcp::with_frequency_derivative(model, options.clone())?;
        let n = lcp.dim();
        Ok(Self {
            model: model.clone(),
            options,
            kappa,
            omega: model.forcing.omega,
            cache: vec![Rc::new(lcp)],
            last_error: None,
            builds: 1,
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

    /// Number of LCPs built so far (one per new frequency, bounded by the cache).
    pub fn builds(&self) -> u64 {
        self.builds
    }

    /// Why the last LCP build failed (evaluations there return NaN), if one did.
    pub fn last_error(&self) -> Option<&LcpError> {
        self.last_error.as_ref()
    }

    /// The unknowns `(w, z)` of a solution `z` of the LCP at the current frequency:
    /// `w = q + A z`.
    pub fn state_from_forces(&mut self, z: &[f64]) -> Result<Vec<f64>, LcpError> {
        let lcp = self.current()?;
        let mut y = lcp.gap(z)?;
        y.extend_from_slice(z);
        Ok(y)
    }

    /// The LCP at the current frequency if it is cached (no build).
    pub fn cached(&self) -> Option<&PeriodicLcp> {
        self.cache
            .iter()
            .find(|l| l.omega() == self.omega)
            .map(|l| &**l)
    }

    /// The LCP at the current frequency, built if needed.
    pub fn current(&mut self) -> Result<Rc<PeriodicLcp>, LcpError> {
        if let Some(i) = self.cache.iter().position(|l| l.omega() == self.omega) {
            let lcp = self.cache.remove(i);
            self.cache.insert(0, lcp.clone());
            return Ok(lcp);
        }
        let mut model = self.model.clone();
        model.forcing.omega = self.omega;
        let lcp = Rc::new(PeriodicLcp::with_frequency_derivative(
            &model,
            self.options.clone(),
        )?);
        self.builds += 1;
        self.cache.insert(0, lcp.clone());
        self.cache.truncate(CACHE);
        Ok(lcp)
    }

    /// The current LCP, or `None` after recording why it could not be built.
    fn lcp_or_record(&mut self) -> Option<Rc<PeriodicLcp>> {
        match self.current() {
            Ok(lcp) => Some(lcp),
            Err(e) => {
                self.last_error = Some(e);
                None
            }
        }
    }
}

impl FrequencyLcp {
    /// `(t, J)`: the tangent `t = (-a, 1)` in `(y, omega)` of the piece of the branch with
    /// the active set of `jac` at `(y, omega)`, `J a = dF/domega`, or `None` if singular.
    fn piece_tangent(&mut self, y: &[f64], jac: &FrequencyLcpJacobian) -> Option<Vec<f64>> {
        let mut a = vec![0.0; self.dim()];
        self.residual_parameter_derivative(y, &mut a);
        let mut solver = FrequencyLcpSolver::new();
        solver.factor(jac).ok()?;
        solver.solve_in_place(&mut a).ok()?;
        let mut t: Vec<f64> = a.iter().map(|v| -v).collect();
        t.push(1.0);
        t.iter().all(|v| v.is_finite()).then_some(t)
    }

    /// First switch of the min met from `y` along `t` (`t` in `(y, omega)`, `y` on a
    /// piece with the given active rows), excluding row `skip`: `(tau, row)` with
    /// `y + tau t` the corner (an inactive gap or an active force reaching zero).
    fn first_switch(
        &self,
        y: &[f64],
        t: &[f64],
        active: &[bool],
        skip: Option<usize>,
    ) -> Option<(f64, usize)> {
        let n = self.half();
        (0..n)
            .filter(|i| Some(*i) != skip)
            .filter_map(|i| {
                let (value, rate) = if active[i] {
                    (y[n + i], t[n + i])
                } else {
                    (y[i], t[i])
                };
                (rate < 0.0).then(|| ((value / -rate).max(0.0), i))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// A starting point on the next piece of the branch past a corner (a node entering or
    /// leaving contact) ahead of the branch point `(y, omega)`, reached from
    /// `(y_prev, omega_prev)`: `(y', omega', increasing)`, or `None` when there is no such
    /// corner or a tangent is singular.
    ///
    /// Where the branch turns by more than 90 degrees at a corner, no arclength hyperplane
    /// normal to the incoming direction cuts the outgoing piece, so the corrector fails at
    /// every step length. Here: the tangent `t1` of the current piece (active set `S`,
    /// oriented along `y - y_prev`) meets its first switch at the corner
    /// `c = (y, omega) + tau t1` (linear extrapolation: `F(c) = O(tau^2)`); the outgoing
    /// piece has the active set `S` with that row switched and the tangent `t2`, oriented
    /// so that the switched variable (the force of a node entering contact, the gap of one
    /// leaving it) grows from zero; the start is `c + eps t2` with `eps` half the smaller of
    /// `tau` (`1e-8 omega` at least) and the distance to the next switch along `t2` (all in
    /// units of `omega`, the last component of the tangents being `±1`).
    pub fn corner_step(
        &mut self,
        y: &[f64],
        omega: f64,
        y_prev: &[f64],
        omega_prev: f64,
    ) -> Option<(Vec<f64>, f64, bool)> {
        let n = self.half();
        self.set_parameter(omega);
        let mut jac = self.new_jacobian();
        self.jacobian(y, &mut jac);
        let mut t1 = self.piece_tangent(y, &jac)?;
        let heading: f64 = y
            .iter()
            .zip(y_prev)
            .zip(&t1)
            .map(|((a, b), t)| (a - b) * t)
            .sum::<f64>()
            + (omega - omega_prev) * t1[2 * n];
        if heading < 0.0 {
            t1.iter_mut().for_each(|v| *v = -*v);
        }
        let (tau, j) = self.first_switch(y, &t1, &jac.active, None)?;
        let corner: Vec<f64> = y.iter().zip(&t1).map(|(a, t)| a + tau * t).collect();
        let omega_c = omega + tau * t1[2 * n];
        // The outgoing piece: row j switched, the switched variable exactly zero.
        let mut corner = corner;
        if jac.active[j] {
            corner[n + j] = 0.0;
        } else {
            corner[j] = 0.0;
        }
        self.set_parameter(omega_c);
        let mut jac2 = self.new_jacobian();
        self.jacobian(&corner, &mut jac2);
        jac2.active.clone_from(&jac.active);
        jac2.active[j] = !jac.active[j];
        let mut t2 = self.piece_tangent(&corner, &jac2)?;
        let grows = if jac2.active[j] { t2[n + j] } else { t2[j] };
        if grows < 0.0 {
            t2.iter_mut().for_each(|v| *v = -*v);
        }
        let next = self
            .first_switch(&corner, &t2, &jac2.active, Some(j))
            .map_or(f64::INFINITY, |(tau2, _)| tau2);
        let eps = 0.5 * tau.max(1e-8 * omega).min(next);
        if !(eps.is_finite() && eps > 0.0) {
            return None;
        }
        let start: Vec<f64> = corner.iter().zip(&t2).map(|(a, t)| a + eps * t).collect();
        let omega_start = omega_c + eps * t2[2 * n];
        self.set_parameter(omega);
        Some((start, omega_start, t2[2 * n] > 0.0))
    }
}

impl Residual for FrequencyLcp {
    fn dim(&self) -> usize {
        2 * self.half()
    }

    fn residual(&mut self, y: &[f64], out: &mut [f64]) {
        let Some(lcp) = self.lcp_or_record() else {
            out.fill(f64::NAN);
            return;
        };
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

    fn jacobian(&mut self, y: &[f64], jac: &mut FrequencyLcpJacobian) {
        let n = self.half();
        let (w, z) = y.split_at(n);
        for ((a, zi), wi) in jac.active.iter_mut().zip(z).zip(w) {
            // min_function's gradient is (0, 1) exactly where kappa w < z (tie: (1, 0)).
            *a = min_function(*zi, self.kappa * wi).db == 1.0;
        }
        jac.kappa = self.kappa;
        jac.lcp = self.lcp_or_record();
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
    fn residual_parameter_derivative(&mut self, y: &[f64], out: &mut [f64]) {
        let n = self.half();
        let result = self
            .current()
            .and_then(|lcp| lcp.frequency_derivative(&y[n..], &mut out[..n]));
        if let Err(e) = result {
            self.last_error = Some(e);
            out.fill(f64::NAN);
            return;
        }
        for o in out[..n].iter_mut() {
            *o = -*o;
        }
        out[n..].fill(0.0);
    }
}

/// An element of the generalized Jacobian of [`FrequencyLcp`]: `[[I, -A], [kappa P_I,
/// P_J]]` with `P_I`, `P_J` the selections of the active and inactive rows.
#[derive(Debug, Clone)]
pub struct FrequencyLcpJacobian {
    /// `None` when the LCP at the frequency could not be built.
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

    /// The `2 m Nt` square matrix (NaN everywhere when the LCP could not be built).
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
/// documentation). A singular or non-finite block is a [`LinearSolveError`] (no
/// regularisation: the continuation then halves its step).
#[derive(Debug)]
pub struct FrequencyLcpSolver {
    lcp: Option<Rc<PeriodicLcp>>,
    active: Vec<usize>,
    inactive: Vec<usize>,
    kappa: f64,
    lu: Option<PartialPivLu<f64>>,
    block_rhs: Mat<f64>,
    dz: Vec<f64>,
    pivot_threshold: f64,
}

impl Default for FrequencyLcpSolver {
    fn default() -> Self {
        Self::new()
    }
}

impl FrequencyLcpSolver {
    /// A solver with the default relative pivot threshold [`DEFAULT_PIVOT_THRESHOLD`].
    pub fn new() -> Self {
        Self {
            lcp: None,
            active: Vec::new(),
            inactive: Vec::new(),
            kappa: 1.0,
            lu: None,
            block_rhs: Mat::zeros(0, 1),
            dz: Vec::new(),
            pivot_threshold: DEFAULT_PIVOT_THRESHOLD,
        }
    }

    /// Size of the active block of the last factorization.
    pub fn active_count(&self) -> usize {
        self.active.len()
    }
}

impl LinearSolve<FrequencyLcpJacobian> for FrequencyLcpSolver {
    fn factor(&mut self, jac: &FrequencyLcpJacobian) -> Result<(), LinearSolveError> {
        self.lu = None;
        self.lcp = None;
        let lcp = jac.lcp.clone().ok_or(LinearSolveError::NonFiniteEntry {
            row: 0,
            col: 0,
            value: f64::NAN,
        })?;
        self.active.clear();
        self.inactive.clear();
        for (i, a) in jac.active.iter().enumerate() {
            if *a {
                self.active.push(i);
            } else {
                self.inactive.push(i);
            }
        }
        self.kappa = jac.kappa;
        let a = lcp.matrix();
        let k = self.active.len();
        let mut block = Mat::<f64>::zeros(k, k);
        for (c, &j) in self.active.iter().enumerate() {
            for (r, &i) in self.active.iter().enumerate() {
                let value = a[(i, j)];
                if !value.is_finite() {
                    return Err(LinearSolveError::NonFiniteEntry {
                        row: i,
                        col: j,
                        value,
                    });
                }
                block[(r, c)] = value;
            }
        }
        if k > 0 {
            let lu = PartialPivLu::new(block.as_ref());
            let u = lu.U();
            check_pivots((0..k).map(|i| u[(i, i)]), self.pivot_threshold)?;
            self.lu = Some(lu);
        }
        self.block_rhs = Mat::zeros(k, 1);
        self.dz = vec![0.0; jac.active.len()];
        self.lcp = Some(lcp);
        Ok(())
    }

    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        let lcp = self.lcp.as_ref().ok_or(LinearSolveError::NotFactored)?;
        let n = self.dz.len();
        if rhs.len() != 2 * n {
            return Err(LinearSolveError::DimensionMismatch {
                expected: 2 * n,
                found: rhs.len(),
            });
        }
        let a = lcp.matrix();
        let (r1, r2) = rhs.split_at_mut(n);
        // Inactive rows: dz_J = r2_J; active block: dz_I from A_II dz_I = dw_I - r1_I - A_IJ dz_J.
        self.dz.fill(0.0);
        for &j in &self.inactive {
            self.dz[j] = r2[j];
        }
        if let Some(lu) = &self.lu {
            for (r, &i) in self.active.iter().enumerate() {
                let mut v = r2[i] / self.kappa - r1[i];
                for &j in &self.inactive {
                    v -= a[(i, j)] * self.dz[j];
                }
                self.block_rhs[(r, 0)] = v;
            }
            lu.solve_in_place(self.block_rhs.as_mut());
            for (r, &i) in self.active.iter().enumerate() {
                self.dz[i] = self.block_rhs[(r, 0)];
            }
        }
        // dw = r1 + A dz on the inactive rows, r2 / kappa on the active ones.
        let mut dw = r1.to_vec();
        add_mat_vec(a, &self.dz, &mut dw);
        for &i in &self.active {
            dw[i] = r2[i] / self.kappa;
        }
        r1.copy_from_slice(&dw);
        r2.copy_from_slice(&self.dz);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rod::{build_rod, MassModel, RodSpec};
    use semismooth::linalg::FaerDenseLu;

    fn problem(nt: usize) -> FrequencyLcp {
        let mut spec = RodSpec::canonical();
        spec.mass = MassModel::Modified;
        let rod = build_rod(&spec).unwrap();
        let options = PeriodicLcpOptions {
            time_samples: nt,
            ..Default::default()
        };
        let kappa = rod.model.contact_stiffness_scale();
        FrequencyLcp::new(&rod.model, options, kappa).unwrap()
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
        p.jacobian(&y, &mut jac);
        assert!(jac.active_count() > 0 && jac.active_count() < p.half());
        let rhs: Vec<f64> = (0..p.dim()).map(|i| (0.37 * i as f64).sin()).collect();
        let mut x1 = rhs.clone();
        let mut solver = FrequencyLcpSolver::new();
        solver.factor(&jac).unwrap();
        solver.solve_in_place(&mut x1).unwrap();
        let mut x2 = rhs.clone();
        let mut dense = FaerDenseLu::new();
        dense.factor(&jac).unwrap();
        LinearSolve::<FrequencyLcpJacobian>::solve_in_place(&mut dense, &mut x2).unwrap();
        let scale = x2.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        // Two backward-stable solves; the active block of A (entries O(1), smallest
        // receptance O(1e-2)) keeps the condition number moderate: 1e-10 relative.
        for (u, v) in x1.iter().zip(&x2) {
            assert!((u - v).abs() <= 1e-10 * scale, "{u} vs {v}");
        }
    }

    #[test]
    fn parameter_derivative_matches_central_differences_of_lcp_builds() {
        let mut p = problem(32);
        let y = state(&p);
        let omega = p.parameter();
        let mut analytic = vec![0.0; p.dim()];
        p.residual_parameter_derivative(&y, &mut analytic);
        // Central differences at the resonance (zeta = 0.01: F varies on the scale
        // zeta omega): truncation (h / (zeta omega))^2 ~ 1e-8 relative, rounding
        // 1e-16 |F| / h ~ 1e-10 of the derivative (|F| ~ 1, |F'| ~ 1e2).
        let h = 1e-6 * omega;
        let mut plus = vec![0.0; p.dim()];
        let mut minus = vec![0.0; p.dim()];
        p.set_parameter(omega + h);
        p.residual(&y, &mut plus);
        p.set_parameter(omega - h);
        p.residual(&y, &mut minus);
        let scale = analytic.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(scale > 0.0);
        for i in 0..p.dim() {
            let fd = (plus[i] - minus[i]) / (2.0 * h);
            assert!(
                (fd - analytic[i]).abs() <= 1e-6 * scale,
                "{i}: {fd} vs {}",
                analytic[i]
            );
        }
    }

    /// The LCP solution `(w, z)` at `omega` by min-map Newton (sequenced from zero).
    fn solution(p: &mut FrequencyLcp, omega: f64) -> Vec<f64> {
        let mut model = p.model.clone();
        model.forcing.omega = omega;
        let options = semismooth::newton::NewtonOptions {
            absolute_tolerance: 1e-13,
            max_iterations: 200,
            ..Default::default()
        };
        let s = super::super::solve_min_map_sequenced(&model, p.options.clone(), &options).unwrap();
        assert!(s.converged());
        p.set_parameter(omega);
        p.state_from_forces(&s.z).unwrap()
    }

    fn active_rows(p: &FrequencyLcp, y: &[f64]) -> Vec<bool> {
        let n = p.half();
        (0..n).map(|i| p.kappa * y[i] < y[n + i]).collect()
    }

    #[test]
    fn corner_step_lands_on_the_neighbouring_piece_of_the_branch() {
        let mut p = problem(64);
        let omega_1 = p.parameter();
        let (w0, w1) = (1.0 * omega_1, 1.0001 * omega_1);
        let y0 = solution(&mut p, w0);
        let y1 = solution(&mut p, w1);
        let (start, omega, _) = p.corner_step(&y1, w1, &y0, w0).unwrap();
        // Correct the start at its frequency by Newton on (w, z) with the structured solver.
        p.set_parameter(omega);
        let mut y = start.clone();
        let options = semismooth::newton::NewtonOptions {
            absolute_tolerance: 1e-12,
            max_iterations: 20,
            globalization: semismooth::newton::Globalization::None,
            ..Default::default()
        };
        let report =
            semismooth::newton::solve(&mut p, &mut FrequencyLcpSolver::new(), &mut y, &options)
                .unwrap();
        assert!(report.converged(), "{:?}", report.termination);
        // On the neighbouring piece: exactly one contact state differs from the branch
        // point's, and the corrected point is the start up to the O(tau^2) of the linear
        // extrapolation to the corner (here 2e-3 omega_1 ahead, on a branch whose state
        // changes by O(1) per 1e-2 omega_1: measured 2.6e-2 of the state).
        let (a1, a) = (active_rows(&p, &y1), active_rows(&p, &y));
        let switched: Vec<usize> = (0..a.len()).filter(|&i| a[i] != a1[i]).collect();
        assert_eq!(switched.len(), 1, "{switched:?}");
        let moved = y
            .iter()
            .zip(&start)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        let size = y1.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        println!(
            "switched row {switched:?}, omega {} -> {}, corrected by {moved:e} (state {size:e})",
            w1 / omega_1,
            omega / omega_1
        );
        assert!(moved <= 0.1 * size, "{moved:e}");
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
        let mut p = FrequencyLcp::new(&rod.model, options, 1.0).unwrap();
        let n = p.half();
        let mut y = vec![0.0; 2 * n];
        y[n..].fill(1.0); // z = 1 > kappa w = 0 everywhere
        let mut jac = p.new_jacobian();
        p.jacobian(&y, &mut jac);
        assert_eq!(jac.active_count(), n);
        let mut solver = FrequencyLcpSolver::new();
        assert!(matches!(
            solver.factor(&jac),
            Err(LinearSolveError::Singular { .. })
        ));
    }
}
