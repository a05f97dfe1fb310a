//! SSN-HB: harmonic balance with the contact law as a semismooth equation (Shi & Legrand,
//! equations (5)-(6)).

use semismooth::harmonic::FourierBasis;
use semismooth::linalg::LinearSolveError;
use semismooth::{EvaluationError, GeneralizedJacobian, ProblemCounters, Residual, Smoothing};

use super::jacobian::{ContactCoupling, HbJacobian};
use super::laws::LawSampler;
use super::{
    check_len, check_omega, check_positive, displacement_summary, validate_basis, HbError, HbState,
    LinearData, ResponseSummary,
};
use crate::law::LawGroup;
use crate::model::StructuralModel;

/// Options of [`SsnHb`].
///
/// | field | default | allowed |
/// |---|---|---|
/// | `harmonics` (`H`) | 20 | `>= 1` |
/// | `time_samples` (`Nt`) | `None`: [`semismooth::harmonic::default_time_samples`]`(H)` (256 for `H = 20`) | `> 2H` |
/// | `c` | `None`: [`StructuralModel::default_complementarity_constant`] (10 x the static contact stiffness shared by the contacts that close together, [`StructuralModel::shared_contact_stiffness`]) | finite, `> 0` |
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HbOptions {
    /// Number of harmonics `H`.
    pub harmonics: usize,
    /// AFT samples per period `Nt` (the quadrature of the nonsmooth terms).
    pub time_samples: Option<usize>,
    /// Complementarity constant `c` in `lambda + max(0, c (G u - g) - lambda) = 0`.
    pub c: Option<f64>,
}

impl Default for HbOptions {
    fn default() -> Self {
        Self {
            harmonics: 20,
            time_samples: None,
            c: None,
        }
    }
}

impl HbOptions {
    /// Checks what can be checked without a model: `harmonics >= 1`, `time_samples > 2H`,
    /// `c` finite and `> 0` when given.
    pub fn validate(&self) -> Result<(), HbError> {
        validate_basis(self.harmonics, self.time_samples)?;
        self.c.map_or(Ok(()), check_c)
    }
}

fn check_c(c: f64) -> Result<(), HbError> {
    Ok(check_positive(
        "c",
        c,
        "a finite complementarity constant > 0 (force per length)",
    )?)
}

/// SSN-HB on a [`StructuralModel`] with `m >= 0` contacts.
///
/// Unknowns `X = [U; Lambda]`: `U` of length `N (2H + 1)` (index `j N + dof`), `Lambda` of
/// length `m (2H + 1)` (index `j m + contact`), the Fourier coefficients of the contact
/// forces `lambda(t) <= 0`. Residual
///
/// - `R_u = A(w) U - F - G^T Lambda` (Galerkin projection of the equation of motion),
/// - `R_lambda = Lambda + P max(0, c (G E U - g) - E Lambda)` (Galerkin projection of the
///   complementarity function, `Nt`-point quadrature).
///
/// Generalized Jacobian: `dR_lambda/dU = c P diag(h) G E`, `dR_lambda/dLambda = I - P diag(h) E`,
/// `h_n = 1` where `s_n = c (G u_n - g) - lambda_n > 0` (else 0). The parameter of
/// [`ParameterDependent`](semismooth::ParameterDependent) is `w`; only `A(w)` depends on it.
#[derive(Debug)]
pub struct SsnHb {
    pub(crate) state: HbState,
    c: f64,
    /// Smoothing parameter `mu >= 0` of `max(0, s)` (0: the formulation itself).
    smoothing: f64,
    /// Sample buffers of the contact laws.
    laws: LawSampler,
}

impl SsnHb {
    shared_accessors!();

    /// The displacement coefficients `U` of the unknowns `X = [U; Lambda]`.
    fn displacement_part<'a>(&self, x: &'a [f64]) -> Result<&'a [f64], HbError> {
        self.displacement_coefficients(x)
    }

    /// Builds the problem at the forcing frequency `omega` (finite, `> 0`); validates the
    /// model, the frequency and the options.
    pub fn new(model: &StructuralModel, omega: f64, options: &HbOptions) -> Result<Self, HbError> {
        Self::with_laws(model, omega, options, &[])
    }

    /// [`SsnHb::new`] with the row groups `laws` added after the model's contacts and
    /// friction points (their rows and force unknowns follow the model's, in order): each
    /// group's law is sampled like the built-in ones ([`crate::law`]). Refuses a group
    /// whose rows, offsets or reads do not fit ([`HbError::DimensionMismatch`],
    /// [`HbError::IndexOutOfRange`], [`HbError::InvalidOption`]).
    pub fn with_laws(
        model: &StructuralModel,
        omega: f64,
        options: &HbOptions,
        laws: &[LawGroup],
    ) -> Result<Self, HbError> {
        options.validate()?;
        check_omega(omega)?;
        let linear = LinearData::with_laws(model, options.harmonics, options.time_samples, laws)?;
        let c = match options.c {
            Some(c) => c,
            None => model.default_complementarity_constant(),
        };
        check_c(c)?;
        let laws = LawSampler::new(&linear);
        Ok(Self {
            state: HbState::new(linear, omega),
            c,
            smoothing: 0.0,
            laws,
        })
    }

    /// The complementarity constant `c` in use.
    pub fn c(&self) -> f64 {
        self.c
    }

    /// Sets the complementarity constant `c` (finite, `> 0`).
    pub fn set_c(&mut self, c: f64) -> Result<(), HbError> {
        check_c(c)?;
        self.c = c;
        Ok(())
    }

    /// Number of friction points (their rows follow the contacts').
    pub fn friction_points(&self) -> usize {
        self.state.linear.friction.len()
    }

    /// Length of `U`, `N (2H + 1)`; `Lambda` starts here in `X`.
    pub fn displacement_len(&self) -> usize {
        self.dofs() * self.state.linear.size()
    }

    /// `U` part of `X`.
    pub fn displacement_coefficients<'a>(&self, x: &'a [f64]) -> Result<&'a [f64], HbError> {
        check_len("HB unknowns", self.dim(), x.len())?;
        Ok(&x[..self.displacement_len()])
    }

    /// `Lambda` part of `X`.
    pub fn force_coefficients<'a>(&self, x: &'a [f64]) -> Result<&'a [f64], HbError> {
        check_len("HB unknowns", self.dim(), x.len())?;
        Ok(&x[self.displacement_len()..])
    }

    /// `lambda_i(t_n) = (E Lambda_i)_n` at `points` equally spaced times over one period.
    pub fn contact_force_samples(
        &self,
        x: &[f64],
        contact: usize,
        points: usize,
    ) -> Result<Vec<f64>, HbError> {
        let lambda = self.force_coefficients(x)?;
        let lin = &self.state.linear;
        lin.check_contact(contact)?;
        let basis = FourierBasis::new(lin.basis.harmonics(), points)?;
        let coeffs = self.contact_coefficients(lambda, contact);
        let mut aft = semismooth::harmonic::Aft::new(basis);
        let mut out = vec![0.0; points];
        aft.to_time(&coeffs, &mut out)?;
        Ok(out)
    }

    /// `lambda_i(t)` at arbitrary times.
    pub fn contact_force_at(
        &self,
        x: &[f64],
        contact: usize,
        times: &[f64],
    ) -> Result<Vec<f64>, HbError> {
        let lambda = self.force_coefficients(x)?;
        self.state.linear.check_contact(contact)?;
        let coeffs = self.contact_coefficients(lambda, contact);
        let mut out = vec![0.0; times.len()];
        self.state
            .linear
            .basis
            .evaluate_many(&coeffs, self.state.omega, times, &mut out)?;
        Ok(out)
    }

    /// Extremes of `u_dof`, penetration and mean contact forces (`Lambda_0`) over a period
    /// reconstructed on `points` times.
    pub fn summary(
        &self,
        x: &[f64],
        dof: usize,
        points: usize,
    ) -> Result<ResponseSummary, HbError> {
        let u = self.displacement_coefficients(x)?;
        let lambda = self.force_coefficients(x)?;
        let means = lambda[..self.state.linear.normal_rows()].to_vec();
        displacement_summary(&self.state.linear, u, dof, points, means)
    }

    /// The intervals of the period where contact `i` is closed, as fractions of the period
    /// (module [`semismooth::trigonometric`]): where the contact law's switching function
    /// `s_i(t) = c (s u_dof(t) - g_i) - lambda_i(t)` is positive, the set whose samples
    /// the generalized Jacobian treats as active (`h_n = 1`), with the interval ends
    /// refined between the `Nt` samples on the truncated Fourier series.
    pub fn closed_intervals(&self, x: &[f64], contact: usize) -> Result<Vec<(f64, f64)>, HbError> {
        let coeffs = self.switching_coefficients(x, contact)?;
        super::switching_intervals(&self.state.linear, &coeffs)
    }

    /// The harmonics of contact `contact`'s switching function `c (g . u - g) - lambda`
    /// (positive where the law is active).
    fn switching_coefficients(&self, x: &[f64], contact: usize) -> Result<Vec<f64>, HbError> {
        check_len("HB unknowns", self.dim(), x.len())?;
        let lin = &self.state.linear;
        lin.check_normal_row(contact)?;
        let (n, m) = (lin.dofs, lin.contacts());
        let offset = n * lin.size();
        let mut coeffs: Vec<f64> = (0..lin.size())
            .map(|j| self.c * lin.row_dot(contact, x, j) - x[offset + j * m + contact])
            .collect();
        coeffs[0] -= self.c * lin.gaps[contact];
        Ok(coeffs)
    }

    /// The contact law applied to the reconstructed samples, `-max(0, c (g . u(t_n) - g) -
    /// lambda(t_n))` at `points` equally spaced times: `lambda(t_n)` where the equation
    /// holds, never tension where the truncated series of `lambda` rings above zero.
    pub fn contact_force_law_samples(
        &self,
        x: &[f64],
        contact: usize,
        points: usize,
    ) -> Result<Vec<f64>, HbError> {
        let coeffs = self.switching_coefficients(x, contact)?;
        let basis = FourierBasis::new(self.state.linear.basis.harmonics(), points)?;
        let mut aft = semismooth::harmonic::Aft::new(basis);
        let mut out = vec![0.0; points];
        aft.to_time(&coeffs, &mut out)?;
        Ok(out
            .into_iter()
            .map(|s| if s > 0.0 { -s } else { 0.0 })
            .collect())
    }

    fn contact_coefficients(&self, lambda: &[f64], contact: usize) -> Vec<f64> {
        let m = self.contacts();
        (0..self.state.linear.size())
            .map(|j| lambda[j * m + contact])
            .collect()
    }

    /// `dR/dw` of the force equations through the sliding obstacles' offsets `s / w` (as
    /// the measured `y` moving by `s / w^2`) into their groups' rows of `out[len..]` (zero
    /// before: the force equations have no other dependence on `w`).
    pub(crate) fn add_sliding_omega_derivative(&mut self, x: &[f64], out: &mut [f64]) {
        let lin = self.state.linear.clone();
        if lin.laws.sliding.iter().all(|s| *s == 0.0) {
            return;
        }
        let (len, omega) = (self.displacement_len(), self.state.omega);
        let dy = |row: usize, j: usize| {
            if j == 0 {
                lin.laws.sliding[row] / (omega * omega)
            } else {
                0.0
            }
        };
        for (g, group) in lin.laws.groups.iter().enumerate() {
            let rows = group.first..group.first + group.law.rows();
            if lin.laws.sliding[rows].iter().all(|s| *s == 0.0) {
                continue;
            }
            self.sample_group(x, g);
            let at = (g, self.c, self.smoothing);
            (self.laws).measured_response(&mut self.state.aft, &lin, at, dy, &mut out[len..]);
        }
    }

    /// `U = A(w, p)^{-1} F`, the response with every contact force zero (factored afresh:
    /// it is asked for only when full Newton steps failed; one harmonic's factor at a time).
    fn linear_response(&self) -> Result<Vec<f64>, LinearSolveError> {
        let lin = &self.state.linear;
        let mut factors = lin.operator.factors(1, true)?;
        factors.factor(&self.state.parameters())?;
        let mut u = vec![0.0; lin.dofs * lin.size()];
        lin.operator.load_coefficients(&mut u);
        factors.solve_real(&mut u)?;
        Ok(u)
    }

    /// Samples group `g`'s arguments `z = lambda - c (y - o)` and the forces it reads
    /// from the full unknowns `x = [U; Lambda]`.
    fn sample_group(&mut self, x: &[f64], g: usize) {
        let lin = self.state.linear.clone();
        let (u, forces) = x.split_at(lin.dofs * lin.size());
        let measured = |row: usize, j: usize| lin.measured_coefficient(row, u, j);
        let at = (g, self.c, self.state.omega);
        (self.laws).sample(&mut self.state.aft, &lin, at, forces, measured);
    }
}

impl Residual for SsnHb {
    fn dim(&self) -> usize {
        let lin = &self.state.linear;
        (lin.dofs + lin.contacts()) * lin.size()
    }

    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        let lin = self.state.linear.clone();
        let offset = lin.dofs * lin.size();
        let (out_u, out_l) = out.split_at_mut(offset);
        lin.dynamic_residual(&self.state.parameters(), &x[..offset], out_u);
        lin.scatter_rows(&x[offset..], -1.0, out_u);
        let forces = &x[offset..];
        for g in 0..lin.laws.groups.len() {
            self.sample_group(x, g);
            let at = (g, self.smoothing);
            self.laws
                .residual(&mut self.state.aft, &lin, at, forces, out_l);
        }
        Ok(())
    }

    /// `ffts`: the transforms of the alternating frequency/time scheme.
    fn problem_counters(&self) -> ProblemCounters {
        ProblemCounters::new().with("ffts", self.state.aft.fft_count())
    }
}

impl GeneralizedJacobian for SsnHb {
    type Jacobian = HbJacobian;

    fn new_jacobian(&self) -> HbJacobian {
        self.state
            .new_jacobian(ContactCoupling::Complementarity { c: self.c })
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut HbJacobian) -> Result<(), EvaluationError> {
        self.state
            .prepare_jacobian(jac, ContactCoupling::Complementarity { c: self.c });
        let lin = self.state.linear.clone();
        for g in 0..lin.laws.groups.len() {
            self.sample_group(x, g);
            let blocks = (jac.q.as_mut_slice(), jac.cross.as_mut_slice());
            let at = (g, self.smoothing);
            (self.laws).jacobian(&mut self.state.aft, &lin, at, blocks, &mut jac.active);
        }
        Ok(())
    }
}

impl Smoothing for SsnHb {
    /// The gaps counted up to the reach of the linear response (contacts open) at each
    /// row, the slip limits as they are (see `LawLayout::smoothing_scale`).
    fn smoothing_scale(&self) -> f64 {
        let lin = &self.state.linear;
        let measured = self.linear_response().ok().map(|u| {
            let mut y = vec![0.0; lin.contacts() * lin.size()];
            lin.gather_measured(&u, &mut y);
            y
        });
        lin.laws.smoothing_scale(self.c, measured.as_deref())
    }

    fn set_smoothing(&mut self, mu: f64) {
        self.smoothing = mu.max(0.0);
    }

    fn residual_smoothing_derivative(
        &mut self,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), EvaluationError> {
        let lin = self.state.linear.clone();
        let offset = lin.dofs * lin.size();
        out[..offset].fill(0.0);
        for g in 0..lin.laws.groups.len() {
            self.sample_group(x, g);
            let at = (g, self.smoothing);
            (self.laws).smoothing_derivative(&mut self.state.aft, &lin, at, &mut out[offset..]);
        }
        Ok(())
    }
}
