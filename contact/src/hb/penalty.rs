//! Penalty harmonic balance: the contact force is `lambda(t) = -k_p max(0, G u(t) - g)`,
//! and a friction point's force the regularised (tanh) Coulomb law of NLvib,
//! `lambda_t = -mu N tanh(v_t / eps)` under its prescribed normal load `N`: the regularised
//! forms of the laws [`crate::law::Unilateral`] and [`crate::law::Coulomb`].
//!
//! The regularisation is written on the phase velocity `y = v_t / w` of the point's row,
//! `lambda_t = -b tanh(y / eta)` (`b = mu N`, so `eps = w eta`): the residual depends on
//! `w` only through the dynamic blocks, as SSN-HB's. `eta`, a slip length, is
//! [`DEFAULT_FRICTION_REGULARISATION`] (or [`PenaltyHb::set_friction_regularisation`])
//! times `b C_tt`, the slip a force `b` makes statically (`C_tt` the row's static
//! compliance): the relative width of the law's stick band. As `eta -> 0` the regularised
//! force tends to Coulomb's in slip, and the stick phases are replaced by slow creep.

use semismooth::continuation::PiecewiseAffine;
use semismooth::{EvaluationError, GeneralizedJacobian, ProblemCounters, Residual};

use super::friction::FrictionPeriod;
use super::jacobian::{ContactCoupling, HbJacobian};
use super::penalty_disk::{disk_widths, DiskSamples};
use super::{
    check_len, check_positive, displacement_summary, row_samples, validate_basis, HbError, HbState,
    LinearData, ResponseSummary,
};
use crate::contacts::FrictionReport;
use crate::law::LawSamples;
use crate::model::{NormalForce, StructuralModel};

/// The static compliance `C_ii` of row `i` from the contact rows' static compliance
/// `compliance` (`m x m`, row-major), or `1 / (g_i K g_i^T)` when `K` could not be factored.
fn row_compliance(
    model: &StructuralModel,
    lin: &LinearData,
    compliance: Option<&[f64]>,
    i: usize,
) -> f64 {
    let m = lin.contacts();
    compliance
        .map(|c| c[i * m + i])
        .filter(|c| c.is_finite() && *c > 0.0)
        .unwrap_or_else(|| 1.0 / lin.rows[i].quadratic_form(&model.stiffness))
}

/// The static slip `b C_tt` of each friction point of `model` (`C_tt` its row's
/// [`row_compliance`]).
fn static_slips(model: &StructuralModel, lin: &LinearData, compliance: Option<&[f64]>) -> Vec<f64> {
    lin.friction
        .iter()
        .enumerate()
        .map(|(f, &(mu, normal))| {
            let c = row_compliance(model, lin, compliance, lin.friction_row(f));
            let b = match normal {
                NormalForce::Prescribed(load) => mu * load,
                NormalForce::Contact(_) => 0.0,
            };
            // (A point without friction, b = 0, carries no force whatever its width.)
            if b > 0.0 {
                b * c
            } else {
                c
            }
        })
        .collect()
}

/// The static compliance `C_tt` ([`row_compliance`]) of the first tangent row of each
/// frictional contact of `model`.
fn disk_compliances(
    model: &StructuralModel,
    lin: &LinearData,
    compliance: Option<&[f64]>,
) -> Vec<f64> {
    lin.frictional
        .iter()
        .map(|(first, contact)| {
            row_compliance(model, lin, compliance, contact.rows_from(*first).1[0])
        })
        .collect()
}

/// Default penalty stiffness, relative to the contact stiffness scale
/// ([`StructuralModel::contact_stiffness_scale`]).
pub const DEFAULT_RELATIVE_PENALTY: f64 = 1e5;

/// Default width of the regularised friction law, relative to the static slip `b C_tt` of
/// each friction point (module documentation).
pub const DEFAULT_FRICTION_REGULARISATION: f64 = 1e-3;

/// Options of [`PenaltyHb`].
///
/// | field | default ([`PenaltyHbOptions::for_model`]) | allowed |
/// |---|---|---|
/// | `harmonics` (`H`) | 20 | `>= 1` |
/// | `time_samples` (`Nt`) | `None`: [`semismooth::harmonic::default_time_samples`]`(H)` | `> 2H` |
/// | `penalty_stiffness` (`k_p`) | [`PenaltyHbOptions::default_penalty_stiffness`]: [`DEFAULT_RELATIVE_PENALTY`] `x` [`StructuralModel::contact_stiffness_scale`] | finite, `> 0` |
///
/// `penalty_stiffness` is **absolute** (force per length); the scenes give it relative to
/// the contact stiffness scale, and their default is the same `1e5 x scale`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PenaltyHbOptions {
    /// Number of harmonics `H`.
    pub harmonics: usize,
    /// AFT samples per period `Nt`.
    pub time_samples: Option<usize>,
    /// Penalty stiffness `k_p` (absolute).
    pub penalty_stiffness: f64,
}

impl PenaltyHbOptions {
    /// The default options for `model`: 20 harmonics, the default `Nt` and
    /// [`PenaltyHbOptions::default_penalty_stiffness`].
    pub fn for_model(model: &StructuralModel) -> Self {
        Self {
            harmonics: 20,
            time_samples: None,
            penalty_stiffness: Self::default_penalty_stiffness(model),
        }
    }

    /// The default penalty stiffness of `model`: [`DEFAULT_RELATIVE_PENALTY`] times its
    /// contact stiffness scale ([`StructuralModel::contact_stiffness_scale`]).
    pub fn default_penalty_stiffness(model: &StructuralModel) -> f64 {
        DEFAULT_RELATIVE_PENALTY * model.contact_stiffness_scale()
    }

    /// Checks `harmonics >= 1`, `time_samples > 2H`, `penalty_stiffness` finite and `> 0`.
    pub fn validate(&self) -> Result<(), HbError> {
        validate_basis(self.harmonics, self.time_samples)?;
        check_penalty_stiffness(self.penalty_stiffness)
    }
}

fn check_penalty_stiffness(kp: f64) -> Result<(), HbError> {
    Ok(check_positive(
        "penalty_stiffness",
        kp,
        "a finite penalty stiffness > 0 (absolute, force per length)",
    )?)
}

/// Penalty HB on a [`StructuralModel`]: unknowns `U` (length `N (2H + 1)`, harmonic-major),
/// residual `R = A(w) U - F - G^T P lambda(E U)` with
/// `lambda_i(t_n) = -k_p max(0, u_{dof_i}(t_n) - g_i)`, generalized Jacobian
/// `A(w) + k_p G^T P diag(h) G E`, `h_n = 1` where `G u_n - g > 0`.
///
/// With the activity `h` held fixed the residual is affine in `U`: the branch of solutions
/// in `w` is made of pieces `U_h(w)` (one per set of active samples), each a graph over
/// `w`, joined at corners where one sample's gap changes sign: the problem is
/// [`PiecewiseAffine`], its switching functions the gaps at the samples, and the
/// continuation crosses its corners exactly.
#[derive(Debug)]
pub struct PenaltyHb {
    pub(crate) state: HbState,
    stiffness: f64,
    /// Held piece `h` (contact-major, `m Nt` entries): while `holding`, the penalty force is
    /// `k_p h_n (G u_n - g)` (the affine piece) instead of `k_p max(0, G u_n - g)`.
    frozen: Vec<bool>,
    /// Whether `frozen` is held (its storage is kept either way).
    holding: bool,
    /// The static slip `b C_tt` of each friction point (the unit of its `eta`).
    static_slip: Vec<f64>,
    /// The regularisation width `eta` of each friction point (a phase-velocity, i.e.
    /// slip-length, scale).
    eta: Vec<f64>,
    /// The regularised laws' force and slope samples (`Nt` each).
    force: Vec<f64>,
    slope: Vec<f64>,
    /// The static compliance `C_tt` of each frictional contact's first tangent row.
    disk_compliance: Vec<f64>,
    /// The band `eta` of each frictional contact's regularised disk law
    /// ([`super::penalty_disk`]).
    pub(super) disk_eta: Vec<f64>,
    /// Samples of one frictional contact (reused).
    pub(super) disk_samples: DiskSamples,
}

impl PenaltyHb {
    shared_accessors!();

    /// How the penalty enters the Jacobian.
    fn coupling(&self) -> ContactCoupling {
        ContactCoupling::Penalty {
            stiffness: self.stiffness,
        }
    }

    /// Length of `U`: all the unknowns.
    pub fn displacement_len(&self) -> usize {
        self.dim()
    }

    /// The displacement coefficients `U` (all the unknowns).
    fn displacement_part<'a>(&self, u: &'a [f64]) -> Result<&'a [f64], HbError> {
        check_len("HB unknowns", self.dim(), u.len())?;
        Ok(u)
    }

    /// Builds the problem at the forcing frequency `omega` (finite, `> 0`); validates the
    /// model, the frequency and the options.
    pub fn new(
        model: &StructuralModel,
        omega: f64,
        options: &PenaltyHbOptions,
    ) -> Result<Self, HbError> {
        options.validate()?;
        super::check_omega(omega)?;
        let kp = options.penalty_stiffness;
        if model
            .friction
            .iter()
            .any(|f| matches!(f.normal, NormalForce::Contact(_)))
        {
            return Err(HbError::Unsupported {
                formulation: "penalty harmonic balance",
                what: "friction on a contact's normal force (its regularised friction takes a \
                       prescribed normal load; use ssn-hb)",
            });
        }
        let linear = LinearData::new(model, options.harmonics, options.time_samples)?;
        // One factorization of K for both: the contact rows' static compliance.
        let compliance = model.static_contact_compliance();
        let static_slip = static_slips(model, &linear, compliance.as_deref());
        let disk_compliance = disk_compliances(model, &linear, compliance.as_deref());
        let nt = linear.basis.time_samples();
        let mut problem = Self {
            state: HbState::new(linear, omega),
            stiffness: kp,
            frozen: Vec::new(),
            holding: false,
            eta: Vec::new(),
            static_slip,
            force: vec![0.0; nt],
            slope: vec![0.0; nt],
            disk_compliance,
            disk_eta: Vec::new(),
            disk_samples: DiskSamples::default(),
        };
        problem.set_friction_regularisation(DEFAULT_FRICTION_REGULARISATION)?;
        Ok(problem)
    }

    /// Sets the width of the regularised friction law relative to each point's static slip
    /// `b C_tt` (finite, `> 0`; module documentation).
    pub fn set_friction_regularisation(&mut self, relative: f64) -> Result<(), HbError> {
        check_positive(
            "friction_regularisation",
            relative,
            "a finite width > 0 relative to the static slip mu N C_tt",
        )?;
        self.eta = self.static_slip.iter().map(|s| relative * s).collect();
        self.disk_eta = disk_widths(&self.state.linear, &self.disk_compliance, relative);
        Ok(())
    }

    /// The regularisation width `eps = w eta` of each friction point, a slip velocity:
    /// `lambda_t = -mu N tanh(v_t / eps)`.
    pub fn friction_velocity_widths(&self) -> Vec<f64> {
        self.eta.iter().map(|e| self.state.omega * e).collect()
    }

    /// Friction point `f` over one period on `points` equally spaced times (`points > 2H`):
    /// the regularised force `-b tanh(v_t / eps)`, the slip velocity, and sticking where
    /// `|v_t| < eps` (the law's stick band).
    pub fn friction_report(
        &self,
        u: &[f64],
        f: usize,
        points: usize,
    ) -> Result<FrictionReport, HbError> {
        check_len("HB unknowns", self.dim(), u.len())?;
        let lin = &self.state.linear;
        let omega = self.state.omega;
        let period =
            FrictionPeriod::reconstruct(lin, (u, omega, 0.0), f, None, &|_, _| 0.0, points)?;
        let eps = omega * self.eta[f];
        let force = period
            .slip_velocity
            .iter()
            .zip(&period.slip_limit)
            .map(|(v, b)| -b * (v / eps).tanh())
            .collect();
        let stuck: Vec<bool> = period.slip_velocity.iter().map(|v| v.abs() < eps).collect();
        Ok(FrictionReport::from_samples(
            f,
            force,
            period.slip_velocity,
            &period.slip_limit,
            stuck.into_iter(),
        ))
    }

    /// Samples of friction point `f`'s phase velocity `y_n / eta` (no mean-slip anchor)
    /// into the AFT's samples.
    fn friction_samples(&mut self, u: &[f64], f: usize) {
        let lin = &self.state.linear;
        let i = lin.friction_row(f);
        let eta = self.eta[f];
        let coeffs = self.state.aft.coefficients_mut();
        coeffs[0] = 0.0;
        for (j, coeff) in coeffs.iter_mut().enumerate().skip(1) {
            *coeff = lin.measured_coefficient(i, u, j) / eta;
        }
        self.state.aft.coefficients_to_samples();
    }

    /// Row group `g`'s regularised law ([`crate::law::ContactLaw::regularised`]) at the
    /// AFT's samples into `force` and `slope` (contact `i` is group `i`, friction point `f`
    /// group [`LinearData::friction_group`]).
    fn regularise(&mut self, g: usize) {
        let lin = &self.state.linear;
        let law = &lin.laws.groups[g].law;
        let at = LawSamples {
            z: self.state.aft.samples(),
            read: &[],
            samples: lin.basis.time_samples(),
            smoothing: 0.0,
        };
        // (Every law of a model penalty HB accepts has its regularised form.)
        let regularised = law.regularised(&at, &mut self.force, &mut self.slope);
        debug_assert!(regularised, "group {g} has no regularised law");
    }

    /// The penalty stiffness `k_p` in use.
    pub fn penalty_stiffness(&self) -> f64 {
        self.stiffness
    }

    /// Sets the penalty stiffness `k_p` (finite, `> 0`).
    pub fn set_penalty_stiffness(&mut self, k: f64) -> Result<(), HbError> {
        check_penalty_stiffness(k)?;
        self.stiffness = k;
        Ok(())
    }

    /// The intervals of the period where contact `i` is closed, as fractions of the period
    /// (module [`semismooth::trigonometric`]): where the penetration `s u_dof(t) - g_i` of
    /// the truncated Fourier series is positive (the penalty spring acts), with the
    /// interval ends refined between the `Nt` samples.
    pub fn closed_intervals(&self, u: &[f64], contact: usize) -> Result<Vec<(f64, f64)>, HbError> {
        check_len("HB unknowns", self.dim(), u.len())?;
        let lin = &self.state.linear;
        lin.check_normal_row(contact)?;
        let mut coeffs: Vec<f64> = (0..lin.size())
            .map(|j| lin.row_dot(contact, u, j))
            .collect();
        coeffs[0] -= lin.gaps[contact];
        super::switching_intervals(lin, &coeffs)
    }

    /// Penalty force `lambda_i(t_n) = -k_p max(0, u(t_n) - g_i)` at `points` equally spaced
    /// times (evaluated pointwise on the fine grid, not through the `H`-harmonic projection).
    pub fn contact_force_samples(
        &self,
        u: &[f64],
        contact: usize,
        points: usize,
    ) -> Result<Vec<f64>, HbError> {
        check_len("HB unknowns", self.dim(), u.len())?;
        let lin = &self.state.linear;
        lin.check_normal_row(contact)?;
        let gap = lin.gaps[contact];
        let samples = row_samples(lin, u, contact, points)?;
        Ok(samples
            .into_iter()
            .map(|x| -self.stiffness * (x - gap).max(0.0))
            .collect())
    }

    /// Extremes of `u_dof` and penetration over a period reconstructed on `points` times,
    /// and the mean penalty force of each contact as the equations see it: the mean over
    /// the `Nt` AFT samples, `(P lambda)_0` (the static balance `K u_0 = f_0 + G^T Lambda_0`).
    /// A finer grid would resolve a stiff penalty's narrow force peaks that the `Nt`-point
    /// quadrature does not, and give a mean inconsistent with the solution.
    pub fn summary(
        &self,
        u: &[f64],
        dof: usize,
        points: usize,
    ) -> Result<ResponseSummary, HbError> {
        check_len("HB unknowns", self.dim(), u.len())?;
        let nt = self.state.linear.basis.time_samples();
        let means = (0..self.state.linear.normal_rows())
            .map(|i| {
                self.contact_force_samples(u, i, nt)
                    .map(|f| f.iter().sum::<f64>() / nt as f64)
            })
            .collect::<Result<Vec<f64>, HbError>>()?;
        displacement_summary(&self.state.linear, u, dof, points, means)
    }

    fn time_samples(&self) -> usize {
        self.state.linear.basis.time_samples()
    }

    /// Replaces the gap samples of contact `i` (the AFT's samples) by the penalty
    /// "activity-weighted gaps": `max(0, s_n)`, or `h_n s_n` when the activity is frozen.
    fn penetrations(&mut self, i: usize) {
        let samples = self.state.aft.samples_mut();
        let nt = samples.len();
        match self.holding.then_some(&self.frozen) {
            Some(h) => {
                for (s, &on) in samples.iter_mut().zip(&h[i * nt..(i + 1) * nt]) {
                    if !on {
                        *s = 0.0;
                    }
                }
            }
            None => {
                self.regularise(i);
                for (s, f) in self.state.aft.samples_mut().iter_mut().zip(&self.force) {
                    *s = -f;
                }
            }
        }
    }

    /// Samples `G u_n - g` of contact `i` into the AFT's samples.
    fn gap_samples(&mut self, u: &[f64], i: usize) {
        let lin = &self.state.linear;
        let coeffs = self.state.aft.coefficients_mut();
        for (j, c) in coeffs.iter_mut().enumerate() {
            *c = lin.row_dot(i, u, j);
        }
        coeffs[0] -= lin.gaps[i];
        self.state.aft.coefficients_to_samples();
    }
}

impl Residual for PenaltyHb {
    fn dim(&self) -> usize {
        self.state.linear.dofs * self.state.linear.size()
    }

    fn residual(&mut self, u: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        let lin = self.state.linear.clone();
        lin.dynamic_residual(&self.state.parameters(), u, out);
        for f in 0..lin.friction.len() {
            // - G_t^T P lambda_t = + G_t^T P b tanh(y / eta).
            self.friction_samples(u, f);
            self.regularise(lin.friction_group(f));
            for (s, force) in self.state.aft.samples_mut().iter_mut().zip(&self.force) {
                *s = -force;
            }
            self.state.aft.samples_to_coefficients();
            let row = lin.friction_row(f);
            for (j, c) in self.state.aft.coefficients().iter().enumerate() {
                lin.add_row_transpose(row, *c, out, j);
            }
        }
        for i in 0..lin.normal_rows() {
            self.gap_samples(u, i);
            self.penetrations(i);
            for s in self.state.aft.samples_mut() {
                *s *= self.stiffness;
            }
            self.state.aft.samples_to_coefficients();
            // - G^T P lambda = + k_p G^T P max(0, G u - g).
            for (j, c) in self.state.aft.coefficients().iter().enumerate() {
                lin.add_row_transpose(i, *c, out, j);
            }
        }
        self.add_frictional_residual(u, out);
        Ok(())
    }

    /// `ffts`: the transforms of the alternating frequency/time scheme.
    fn problem_counters(&self) -> ProblemCounters {
        ProblemCounters::new().with("ffts", self.state.aft.fft_count())
    }
}

impl GeneralizedJacobian for PenaltyHb {
    type Jacobian = HbJacobian;

    fn new_jacobian(&self) -> HbJacobian {
        self.state.new_jacobian(self.coupling())
    }

    fn jacobian(&mut self, u: &[f64], jac: &mut HbJacobian) -> Result<(), EvaluationError> {
        self.state.prepare_jacobian(jac, self.coupling());
        let nt = self.time_samples();
        let lin = self.state.linear.clone();
        for f in 0..lin.friction.len() {
            // dR/dU = G_t^T P diag(b sech^2(y / eta) / eta) E D G_t, written as
            // k_p G_t^T Q D G_t (the coupling's stiffness divided out).
            self.friction_samples(u, f);
            self.regularise(lin.friction_group(f));
            let i = lin.friction_row(f);
            let scale = -1.0 / (self.eta[f] * self.stiffness);
            for (s, d) in self.state.aft.samples_mut().iter_mut().zip(&self.slope) {
                *s = scale * d;
            }
            self.state.write_weighted_contact_block(jac, i);
        }
        for i in 0..lin.normal_rows() {
            self.gap_samples(u, i);
            if let Some(h) = self.holding.then_some(&self.frozen) {
                // The indicator is the sign of the sample: impose the frozen one.
                let samples = self.state.aft.samples_mut();
                for (s, &on) in samples.iter_mut().zip(&h[i * nt..(i + 1) * nt]) {
                    *s = if on { 1.0 } else { 0.0 };
                }
                self.state.write_contact_block(jac, i);
            } else {
                // The law's slope per unit stiffness, -[G u - g > 0].
                self.regularise(i);
                for (s, d) in self.state.aft.samples_mut().iter_mut().zip(&self.slope) {
                    *s = -d;
                }
                self.state.write_weighted_contact_block(jac, i);
            }
        }
        self.write_frictional_jacobian(u, jac)
    }
}

/// The switching functions are the gaps `G u(t_n) - g` at the `Nt` AFT samples,
/// contact-major (`i Nt + n`): a sample carries penalty force where its gap is positive.
impl PiecewiseAffine for PenaltyHb {
    fn switching_count(&self) -> usize {
        self.state.linear.normal_rows() * self.time_samples()
    }

    fn switching(&mut self, u: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        let nt = self.time_samples();
        for i in 0..self.state.linear.normal_rows() {
            self.gap_samples(u, i);
            out[i * nt..(i + 1) * nt].copy_from_slice(self.state.aft.samples());
        }
        Ok(())
    }

    fn hold_piece(&mut self, piece: Option<&[bool]>) {
        self.holding = piece.is_some();
        if let Some(h) = piece {
            self.frozen.clear();
            self.frozen.extend_from_slice(h);
        }
    }
}
