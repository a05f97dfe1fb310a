//! Harmonic balance for periodic contact problems: the semismooth formulation of Shi &
//! Legrand (SSN-HB, their equations (5)-(6)) and penalty harmonic balance.
//!
//! Both are built for a model and a forcing frequency `w` (the model's
//! [`HarmonicLoad`](crate::model::HarmonicLoad) on harmonics of `w`; a new frequency is
//! [`SsnHb::set_omega`] or the continuation parameter, not a new problem). Both expand the
//! displacements of the [`StructuralModel`] with `H` harmonics in the real basis of
//! [`semismooth::harmonic`] (`u(t) = u_0 + sum_k u_ck cos(k w t) + u_sk sin(k w t)`),
//! harmonic-major: unknown `j * N + dof` is coefficient `j` of `dof`. The linear dynamics
//! `M u'' + D u' + K u` become the block-diagonal `A(w, p) U` of the harmonic operator
//! ([`crate::operator`]: for harmonic `k` on `(u_ck, u_sk)` and the default modal damping
//! `xi = 0`, `[[K - (k w)^2 M, k w D], [-k w D, K - (k w)^2 M]]`; `K` alone on `u_0`), and
//! the load its coefficients `F`. The modal damping `xi` (`D - xi M`) is set at fixed `w` by
//! `set_modal_damping`.
//!
//! - [`SsnHb`]: unknowns `X = [U; Lambda]`, `Lambda` the contact-force coefficients (index
//!   `j * m + contact`), residual `R_u = A(w) U - F - G^T Lambda`,
//!   `R_lambda = Lambda + P max(0, c (G E U - g) - E Lambda)` through AFT with `Nt` samples.
//! - [`PenaltyHb`]: unknowns `U` only, `lambda(t) = -k_p max(0, G u(t) - g)`,
//!   residual `R = A(w) U - F - G^T P lambda(E U)`.
//!
//! Both write their generalized Jacobian into an [`HbJacobian`] (dynamic blocks shared, not
//! rebuilt while `w` is fixed, plus the contact coupling `P diag(h) E` per contact, block
//! diagonal by row group when a law couples several rows, [`crate::law`]). It can be
//! assembled densely ([`semismooth::linalg::DenseAssemble`], for the dense LU solvers) or
//! solved by [`StructuredHbSolver`], which factors each harmonic's dynamic block once per
//! frequency (sparse complex LU) and solves the Newton system on the `m (2H + 1)` contact
//! unknowns (receptance / Schur-complement condensation).
//!
//! [`CondensedSsnHb`] eliminates `U` once and for all (`G U = G A^{-1} F + R Lambda`) and
//! runs Newton on the `m (2H + 1)` force coefficients alone: the same Newton direction as
//! the full problem once `R_u = 0`, but a residual that costs `O(m^2 H + m Nt log Nt)`,
//! independent of `N`, and a merit function that sees only the contact equations.
//!
//! Without contacts (`m = 0`) both problems are linear and no FFT is performed.
//!
//! ```
//! use semismooth::linalg::FaerDenseLu;
//! use semismooth::polyalgorithm::{solve, solve_smoothing, PolyalgorithmOptions};
//! use semismooth::Residual;
//! use semismooth_contact::hb::{CondensedSsnHb, HbOptions, SsnHb, StructuredHbSolver};
//! use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
//!
//! let mut spec = RodSpec::canonical();
//! spec.mass = MassModel::Modified; // massless contact node: a well-posed periodic problem
//! let rod = build_rod(&spec).unwrap();
//! let options = HbOptions { harmonics: 20, ..HbOptions::default() };
//!
//! // Full unknowns [U; Lambda], structured (condensed) linear solves.
//! let mut hb = SsnHb::new(&rod.model, rod.omega(), &options).unwrap();
//! let mut x = vec![0.0; hb.dim()];
//! let newton = PolyalgorithmOptions::default();
//! let report = solve_smoothing(&mut hb, &mut StructuredHbSolver::new(), &mut x, &newton).unwrap();
//! assert!(report.converged());
//! let summary = hb.summary(&x, rod.tip_dof(), 1024).unwrap();
//! assert!(summary.displacement_min < -0.5 && summary.contact_force_mean[0] < 0.0);
//!
//! // Newton on the force coefficients alone: same solution, far fewer iterations.
//! let mut condensed = CondensedSsnHb::new(&rod.model, rod.omega(), &options).unwrap();
//! let mut lambda = vec![0.0; condensed.dim()];
//! let reduced = solve(&mut condensed, &mut FaerDenseLu::new(), &mut lambda, &newton).unwrap();
//! assert!(reduced.converged() && reduced.iterations < report.iterations);
//! let same = condensed.summary(&lambda, rod.tip_dof(), 1024).unwrap();
//! assert!((same.displacement_min - summary.displacement_min).abs() < 1e-9);
//! ```

/// The accessors and reconstructions SSN-HB and penalty HB share: both hold their
/// [`HbState`] in a field `state` and define `displacement_part(&self, x) -> Result<&[f64],
/// HbError>` (the displacement coefficients `U` of their unknowns).
macro_rules! shared_accessors {
    () => {
        /// The Fourier basis (`H`, `Nt`).
        pub fn basis(&self) -> semismooth::harmonic::FourierBasis {
            self.state.linear.basis
        }

        /// Number of degrees of freedom `N`.
        pub fn dofs(&self) -> usize {
            self.state.linear.dofs
        }

        /// Number of contacts `m`.
        pub fn contacts(&self) -> usize {
            self.state.linear.contacts()
        }

        /// Current angular frequency `w`.
        pub fn omega(&self) -> f64 {
            self.state.omega
        }

        /// Sets `w` (finite, `> 0`).
        pub fn set_omega(&mut self, omega: f64) -> Result<(), $crate::hb::HbError> {
            $crate::hb::check_omega(omega)?;
            self.state.omega = omega;
            Ok(())
        }

        /// The modal damping `xi` of the operator (`D - xi M` as the damping; 0 by default).
        pub fn modal_damping(&self) -> f64 {
            self.state.modal_damping
        }

        /// Sets the modal damping `xi` (finite; any sign) at fixed `w`.
        pub fn set_modal_damping(&mut self, xi: f64) -> Result<(), $crate::hb::HbError> {
            $crate::hb::check_modal_damping(xi)?;
            self.state.modal_damping = xi;
            Ok(())
        }

        /// `dR/d parameter` at `x` (length [`Residual::dim`](semismooth::Residual::dim)):
        /// `dA/d parameter U` on the displacement equations, zero elsewhere (only the
        /// operator depends on its parameters).
        pub fn residual_operator_derivative(
            &self,
            parameter: $crate::operator::OperatorParameter,
            x: &[f64],
            out: &mut [f64],
        ) -> Result<(), $crate::hb::HbError> {
            let len = self.displacement_len();
            $crate::hb::check_len("HB unknowns", semismooth::Residual::dim(self), x.len())?;
            $crate::hb::check_len("derivative", x.len(), out.len())?;
            self.state.parameter_derivative(parameter, x, len, out);
            Ok(())
        }

        /// `u_dof(t_n)` at `points` equally spaced times over one period (`points > 2H`).
        pub fn displacement_samples(
            &self,
            x: &[f64],
            dof: usize,
            points: usize,
        ) -> Result<Vec<f64>, $crate::hb::HbError> {
            let u = self.displacement_part(x)?;
            self.state.linear.check_dof(dof)?;
            $crate::hb::fine_samples(&self.state.linear, u, dof, points)
        }

        /// `g_i . u(t_n)` of row `i` of `G` (contacts, then friction points) at `points`
        /// equally spaced times over one period (`points > 2H`): a contact's gap closure
        /// `g . u`, or a friction point's slip.
        pub fn row_displacement_samples(
            &self,
            x: &[f64],
            row: usize,
            points: usize,
        ) -> Result<Vec<f64>, $crate::hb::HbError> {
            let u = self.displacement_part(x)?;
            $crate::hb::row_samples(&self.state.linear, u, row, points)
        }

        /// `u_dof(t)` at arbitrary times.
        pub fn displacement_at(
            &self,
            x: &[f64],
            dof: usize,
            times: &[f64],
        ) -> Result<Vec<f64>, $crate::hb::HbError> {
            let u = self.displacement_part(x)?;
            $crate::hb::displacement_at(&self.state.linear, self.state.omega, u, dof, times)
        }
    };
}

/// `w` as the parameter of SSN-HB and penalty HB (both hold an [`HbState`] `state` and
/// define `displacement_len`): only `A(w)` depends on it, `dR/dw = [dA/dw U; 0]`.
macro_rules! omega_parameter {
    ($($problem:ty),*) => {$(
        impl semismooth::ParameterDependent for $problem {
            fn parameter(&self) -> f64 {
                self.state.omega
            }

            fn set_parameter(&mut self, p: f64) {
                self.state.omega = p;
            }

            fn residual_parameter_derivative(
                &mut self,
                x: &[f64],
                out: &mut [f64],
                _scratch: &mut [f64],
            ) -> Result<(), semismooth::EvaluationError> {
                self.state.parameter_derivative(
                    $crate::operator::OperatorParameter::Omega,
                    x,
                    self.displacement_len(),
                    out,
                );
                self.add_sliding_omega_derivative(x, out);
                Ok(())
            }
        }
    )*};
}

mod condensed;
mod coupled_rows;
mod disk;
mod friction;
mod jacobian;
mod krylov;
mod laws;
mod neighbour;
mod penalty;
mod penalty_disk;
mod ssn;
mod structured;

use std::sync::Arc;

use faer::c64;
use semismooth::harmonic::{Aft, FourierBasis, HarmonicError};
use semismooth::InvalidOption;

use crate::law::LawGroup;
use crate::model::{ContactRow, FrictionalContact, InvalidModel, NormalForce, StructuralModel};
use crate::operator::{HarmonicOperator, HarmonicParameters, OperatorParameter};

pub(crate) use crate::law::{smoothed_max, smoothed_max_mu_derivative, smoothed_max_slope};
pub use condensed::CondensedSsnHb;
pub use disk::{FrictionalContactReport, FrictionalContactSummary};
pub use jacobian::{ContactCoupling, HbJacobian};
pub use krylov::KRYLOV_THRESHOLD;
pub(crate) use laws::LawLayout;
pub use penalty::{
    PenaltyHb, PenaltyHbOptions, DEFAULT_FRICTION_REGULARISATION, DEFAULT_RELATIVE_PENALTY,
};
pub use ssn::{HbOptions, SsnHb};
pub use structured::{
    CondensedSolve, StructuredHbSolver, DENSE_PRECONDITIONER_LIMIT, KRYLOV_RELATIVE_TOLERANCE,
};

omega_parameter!(SsnHb, PenaltyHb);

/// Why a harmonic-balance problem could not be built or a reconstruction not made.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum HbError {
    /// An option or parameter is outside its allowed range.
    #[error("invalid {0}")]
    InvalidOption(#[from] InvalidOption),
    /// The model is not usable (sizes, non-finite data, contacts).
    #[error(transparent)]
    Model(#[from] InvalidModel),
    /// A degree of freedom or contact index is out of range.
    #[error("{what} index {index} is out of range: allowed 0..{count}")]
    IndexOutOfRange {
        /// What the index refers to.
        what: &'static str,
        /// The index received.
        index: usize,
        /// Number of items.
        count: usize,
    },
    /// A vector has the wrong length.
    #[error("{what}: expected length {expected}, found {found}")]
    DimensionMismatch {
        /// Which vector.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Length received.
        found: usize,
    },
    /// The Fourier basis could not be built.
    #[error(transparent)]
    Harmonic(#[from] HarmonicError),
    /// The formulation does not model something the model declares.
    #[error("{formulation} does not model {what}")]
    Unsupported {
        /// The formulation.
        formulation: &'static str,
        /// What it does not model.
        what: &'static str,
    },
    /// The dynamic blocks `A(w)` could not be factored (e.g. an undamped resonance).
    #[error("dynamic blocks: {0}")]
    Linear(#[from] semismooth::linalg::LinearSolveError),
}

/// Extremes and contact diagnostics of a harmonic-balance solution over one period,
/// reconstructed on `points` equally spaced times.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct ResponseSummary {
    /// Degree of freedom whose extremes are reported.
    pub dof: usize,
    /// Number of reconstruction points per period.
    pub points: usize,
    /// Maximum of `u_dof(t)` over the period.
    pub displacement_max: f64,
    /// Minimum of `u_dof(t)` over the period.
    pub displacement_min: f64,
    /// Root mean square of `u_dof(t)` over the period (exact, by Parseval).
    pub displacement_rms: f64,
    /// `max_t max_contacts (G u(t) - g)`, clipped at 0 (0 when there is no contact).
    pub max_penetration: f64,
    /// Mean of `lambda_i(t)` over the period for each contact (`<= 0` at a solution).
    pub contact_force_mean: Vec<f64>,
}

/// The linear data shared by the formulations and their Jacobians (immutable, behind an
/// `Arc`): the harmonic operator (matrices and load), contact rows, their laws and the
/// Fourier basis.
#[derive(Debug)]
pub(crate) struct LinearData {
    pub(crate) dofs: usize,
    pub(crate) basis: FourierBasis,
    /// The linear dynamics `A(w, p)` and the load `F`.
    pub(crate) operator: HarmonicOperator,
    /// The rows of `G`: the contacts' normal rows (the first `gaps.len()`), then the
    /// friction points' tangential rows, then the rows of added law groups.
    pub(crate) rows: Vec<ContactRow>,
    /// The gap of each contact (normal row).
    pub(crate) gaps: Vec<f64>,
    /// The Coulomb coefficient and the normal force of each friction point (tangential
    /// row [`LinearData::friction_row`]).
    pub(crate) friction: Vec<(f64, NormalForce)>,
    /// The row groups with their laws and the pattern of their Jacobian blocks.
    pub(crate) laws: LawLayout,
    /// Each frictional contact with the index of its first row.
    pub(crate) frictional: Vec<(usize, FrictionalContact)>,
    /// The parts of the rows on the next cyclic sector's dofs.
    pub(crate) neighbours: neighbour::NeighbourParts,
}

impl LinearData {
    /// Validates the model and the basis parameters and copies what HB needs.
    pub(crate) fn new(
        model: &StructuralModel,
        harmonics: usize,
        time_samples: Option<usize>,
    ) -> Result<Self, HbError> {
        Self::with_laws(model, harmonics, time_samples, &[])
    }

    /// [`LinearData::new`] with the rows and laws of `groups` after the model's rows.
    pub(crate) fn with_laws(
        model: &StructuralModel,
        harmonics: usize,
        time_samples: Option<usize>,
        groups: &[LawGroup],
    ) -> Result<Self, HbError> {
        model.validate()?;
        crate::jenkins::refuse_unexpanded(model)?;
        validate_basis(harmonics, time_samples)?;
        model.load.check_harmonics(harmonics)?;
        for (point, p) in model.frictional_contacts.iter().enumerate() {
            let harmonic = p.gap_harmonics().len();
            if harmonic > harmonics {
                return Err(InvalidModel::MovingGapHarmonic {
                    point,
                    harmonic,
                    harmonics,
                }
                .into());
            }
        }
        let basis = match time_samples {
            Some(nt) => FourierBasis::new(harmonics, nt)?,
            None => FourierBasis::with_default_samples(harmonics),
        };
        let mut rows: Vec<ContactRow> = model.rows().cloned().collect();
        let laws = LawLayout::new(model, groups, model.dofs())?;
        rows.extend(groups.iter().flat_map(|g| g.rows.iter().cloned()));
        let mut first = model.contacts.len() + model.friction.len();
        let frictional = model
            .frictional_contacts
            .iter()
            .map(|p| {
                first += p.row_count();
                (first - p.row_count(), p.clone())
            })
            .collect();
        Ok(Self {
            neighbours: neighbour::NeighbourParts::of(model, rows.len()),
            dofs: model.dofs(),
            basis,
            operator: HarmonicOperator::new(model, harmonics),
            rows,
            gaps: model.contacts.iter().map(|c| c.gap).collect(),
            friction: model
                .friction
                .iter()
                .map(|f| (f.coefficient, f.normal))
                .collect(),
            laws,
            frictional,
        })
    }

    /// Number of rows of `G`, `m` (contacts, then friction points): the force unknowns per
    /// basis function.
    pub(crate) fn contacts(&self) -> usize {
        self.rows.len()
    }

    /// Number of contacts (normal rows, the first rows of `G`).
    pub(crate) fn normal_rows(&self) -> usize {
        self.gaps.len()
    }

    /// The index of friction point `f`'s row group (its law a [`crate::law::Coulomb`] on
    /// one row).
    pub(crate) fn friction_group(&self, f: usize) -> usize {
        self.laws.friction_groups[f]
    }

    /// The tangential row of friction point `f` (the first row of its group).
    pub(crate) fn friction_row(&self, f: usize) -> usize {
        self.laws.groups[self.friction_group(f)].first
    }

    /// Whether row `i` is a friction point's tangential row: its measured quantity is the
    /// slip velocity `d (g_i . u) / d(w t)`, not the displacement `g_i . u`.
    pub(crate) fn is_velocity_row(&self, i: usize) -> bool {
        self.laws.velocity[i]
    }

    /// `out[j m + i] = g_i . U_j`: the rows of `G` applied to the harmonic-major
    /// coefficients `u` (index `j N + dof`), harmonic-major out (index `j m + i`).
    pub(crate) fn gather_rows(&self, u: &[f64], out: &mut [f64]) {
        let m = self.contacts();
        if m == 0 {
            return;
        }
        for (j, block) in out.chunks_exact_mut(m).enumerate() {
            for (i, o) in block.iter_mut().enumerate() {
                *o = self.row_dot(i, u, j);
            }
        }
    }

    /// `out[j m + i]`: the measured quantity of each row from the harmonic-major
    /// coefficients `u`: `g_i . U_j` for a contact, and for a friction point the phase
    /// velocity `y = d (g_i . u) / d(w t)`, whose harmonic `k` is `(k b_k, -k a_k)` for the
    /// row's displacement `(a_k, b_k)`, and whose constant is the anchor
    /// [`MEAN_SLIP_ANCHOR`]` (g_i . U_0)`.
    pub(crate) fn gather_measured(&self, u: &[f64], out: &mut [f64]) {
        self.gather_rows(u, out);
        let m = self.contacts();
        let velocity = &self.laws.velocity_rows;
        if velocity.is_empty() {
            return;
        }
        for &i in velocity {
            out[i] *= MEAN_SLIP_ANCHOR;
        }
        for k in 1..=self.basis.harmonics() {
            let (c, s) = ((2 * k - 1) * m, 2 * k * m);
            let kf = k as f64;
            for &i in velocity {
                let (a, b) = (out[c + i], out[s + i]);
                out[c + i] = kf * b;
                out[s + i] = -kf * a;
            }
        }
    }

    /// Coefficient `j` of row `i`'s measured quantity ([`LinearData::gather_measured`])
    /// from the displacement coefficients `u` (index `j N + dof`).
    pub(crate) fn measured_coefficient(&self, i: usize, u: &[f64], j: usize) -> f64 {
        match (self.is_velocity_row(i), j) {
            (false, _) => self.row_dot(i, u, j),
            (true, 0) => MEAN_SLIP_ANCHOR * self.row_dot(i, u, 0),
            // Harmonic k of (a, b) is (k b, -k a).
            (true, j) if j % 2 == 1 => j.div_ceil(2) as f64 * self.row_dot(i, u, j + 1),
            (true, j) => -((j / 2) as f64) * self.row_dot(i, u, j - 1),
        }
    }

    /// A receptance entry of row `i` at harmonic `k` (complex form `a - i b`) as its
    /// measured quantity sees it: unchanged for a contact, times `i k` (the phase
    /// derivative) for a friction point, and times [`MEAN_SLIP_ANCHOR`] for its constant.
    pub(crate) fn measured(&self, i: usize, k: usize, value: c64) -> c64 {
        match (self.is_velocity_row(i), k) {
            (false, _) => value,
            (true, 0) => value * MEAN_SLIP_ANCHOR,
            (true, k) => value * c64::new(0.0, k as f64),
        }
    }

    /// `u[j N + .] += alpha G^T p_j`: the row forces `p` (index `j m + i`) on the dofs.
    pub(crate) fn scatter_rows(&self, p: &[f64], alpha: f64, u: &mut [f64]) {
        let m = self.contacts();
        if m == 0 {
            return;
        }
        for (j, block) in p.chunks_exact(m).enumerate() {
            for (i, pi) in block.iter().enumerate() {
                self.add_row_transpose(i, alpha * pi, u, j);
            }
        }
    }

    pub(crate) fn size(&self) -> usize {
        self.basis.basis_size()
    }

    /// `out = A(w, p) U - F` ([`HarmonicOperator::residual`]).
    pub(crate) fn dynamic_residual(&self, p: &HarmonicParameters, u: &[f64], out: &mut [f64]) {
        self.operator.residual(p, u, out);
    }

    /// `out = A(w, p) U` ([`HarmonicOperator::apply`]).
    pub(crate) fn apply_dynamic(&self, p: &HarmonicParameters, u: &[f64], out: &mut [f64]) {
        self.operator.apply(p, u, out);
    }

    /// Coefficients (length `2H + 1`) of `dof` from a harmonic-major vector.
    pub(crate) fn gather(&self, u: &[f64], dof: usize, out: &mut [f64]) {
        let n = self.dofs;
        for (j, o) in out.iter_mut().enumerate() {
            *o = u[j * n + dof];
        }
    }

    /// `Err` unless `dof` is a dof of the model.
    pub(crate) fn check_dof(&self, dof: usize) -> Result<(), HbError> {
        check_index("dof", dof, self.dofs)
    }

    /// `Err` unless `contact` is a contact's normal row (not a friction point's).
    pub(crate) fn check_normal_row(&self, contact: usize) -> Result<(), HbError> {
        check_index("contact", contact, self.normal_rows())
    }

    /// `Err` unless `contact` is a contact row (a normal row or a friction point's).
    pub(crate) fn check_contact(&self, contact: usize) -> Result<(), HbError> {
        check_index("contact", contact, self.contacts())
    }
}

/// `Err(IndexOutOfRange { what, index, count })` unless `index < count`.
pub(crate) fn check_index(what: &'static str, index: usize, count: usize) -> Result<(), HbError> {
    if index < count {
        Ok(())
    } else {
        Err(HbError::IndexOutOfRange { what, index, count })
    }
}

/// The weight of the mean slip `g_t . U_0` in the constant term of a friction point's
/// measured velocity. The velocity form fixes no mean slip: while a point sticks over the
/// whole period, every constant tangential force inside the cone gives a periodic
/// solution (the state depends on history), and the Jacobian is singular. With this
/// weight the constant term of the law reads `Lambda_0 - mean proj(z) = 0` with
/// `z = lambda - c (y + delta g_t . U_0)`: a point stuck all period is anchored at zero
/// mean slip (no locked-in force), and a slipping one sees its slip direction shifted by
/// `delta` times its mean slip, far below the truncation error.
pub(crate) const MEAN_SLIP_ANCHOR: f64 = 1e-6;

/// `harmonics >= 1` (the forcing is harmonic 1) and `time_samples > 2H` when given.
pub(crate) fn validate_basis(harmonics: usize, time_samples: Option<usize>) -> Result<(), HbError> {
    if harmonics == 0 {
        return Err(HbError::InvalidOption(InvalidOption::new(
            "harmonics",
            0.0,
            "an integer >= 1 (the forcing is harmonic 1)",
        )));
    }
    if let Some(nt) = time_samples {
        FourierBasis::new(harmonics, nt)?;
    }
    Ok(())
}

pub(crate) use crate::model::check_omega;

/// `Err(InvalidOption)` unless the modal damping `xi` is finite.
pub(crate) fn check_modal_damping(xi: f64) -> Result<(), InvalidOption> {
    InvalidOption::check(xi.is_finite(), "modal damping", xi, "a finite number")
}

/// `Err(InvalidOption { name, value, allowed })` unless `value` is finite and `> 0`.
pub(crate) fn check_positive(
    name: &'static str,
    value: f64,
    allowed: &'static str,
) -> Result<(), InvalidOption> {
    InvalidOption::check(value.is_finite() && value > 0.0, name, value, allowed)
}

/// Harmonic-balance unknowns of `from` harmonics carried to `to` harmonics: the
/// displacement coefficients (`(2 from + 1) dofs`, harmonic-major) and then, when `x` has
/// them, the force coefficients of every row of `G` (`(2 from + 1) contacts`, `contacts` the
/// rows: normal, friction and 3-D contact rows), each block lifted with
/// zero higher harmonics or truncated (the Galerkin projection onto `to` harmonics). A
/// block that `x` is too short for is taken as zero.
pub fn resize_harmonics(
    x: &[f64],
    from: usize,
    to: usize,
    dofs: usize,
    contacts: usize,
) -> Vec<f64> {
    let block = |start: usize, width: usize| {
        let have = ((2 * from + 1) * width).min(x.len().saturating_sub(start));
        let mut out = vec![0.0; (2 * to + 1) * width];
        let keep = out.len().min(have);
        out[..keep].copy_from_slice(&x[start..start + keep]);
        out
    };
    let mut out = block(0, dofs);
    if contacts > 0 {
        out.extend(block((2 * from + 1) * dofs, contacts));
    }
    out
}

pub(crate) fn check_len(what: &'static str, expected: usize, found: usize) -> Result<(), HbError> {
    Ok(semismooth::harmonic::check_length(what, expected, found)?)
}

/// Samples of one dof over a period at `points` equally spaced times `t_n = n T / points`
/// (a finer AFT grid than the solver's when `points > Nt`).
pub(crate) fn fine_samples(
    lin: &LinearData,
    u: &[f64],
    dof: usize,
    points: usize,
) -> Result<Vec<f64>, HbError> {
    let mut coeffs = vec![0.0; lin.size()];
    lin.gather(u, dof, &mut coeffs);
    samples_of(lin, &coeffs, points)
}

/// Samples of the signal with coefficients `coeffs` (`2H + 1`) at `points` equally spaced
/// times over one period.
fn samples_of(lin: &LinearData, coeffs: &[f64], points: usize) -> Result<Vec<f64>, HbError> {
    let mut aft = Aft::new(FourierBasis::new(lin.basis.harmonics(), points)?);
    let mut samples = vec![0.0; points];
    aft.to_time(coeffs, &mut samples)?;
    Ok(samples)
}

/// Where the switching function with coefficients `coeffs` (one contact's, `2H + 1`) is
/// positive over a period, its sign changes bracketed on the `Nt` AFT samples.
pub(crate) fn switching_intervals(
    lin: &LinearData,
    coeffs: &[f64],
) -> Result<Vec<(f64, f64)>, HbError> {
    Ok(semismooth::trigonometric::positive_intervals(
        &lin.basis,
        coeffs,
        lin.basis.time_samples(),
    )?)
}

/// Samples of row `i` of `G` applied to the displacements, `g_i . u(t_n)`, at `points`
/// equally spaced times over one period.
pub(crate) fn row_samples(
    lin: &LinearData,
    u: &[f64],
    row: usize,
    points: usize,
) -> Result<Vec<f64>, HbError> {
    lin.check_contact(row)?;
    let coeffs: Vec<f64> = (0..lin.size()).map(|j| lin.row_dot(row, u, j)).collect();
    samples_of(lin, &coeffs, points)
}

/// Displacement extremes, RMS and penetration from the displacement coefficients `u`.
pub(crate) fn displacement_summary(
    lin: &LinearData,
    u: &[f64],
    dof: usize,
    points: usize,
    contact_force_mean: Vec<f64>,
) -> Result<ResponseSummary, HbError> {
    lin.check_dof(dof)?;
    let samples = fine_samples(lin, u, dof, points)?;
    let displacement_max = samples.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let displacement_min = samples.iter().copied().fold(f64::INFINITY, f64::min);
    let mut coeffs = vec![0.0; lin.size()];
    lin.gather(u, dof, &mut coeffs);
    let displacement_rms = lin.basis.mean_square(&coeffs)?.sqrt();
    let mut max_penetration = 0.0f64;
    for (i, &gap) in lin.gaps.iter().enumerate() {
        for x in row_samples(lin, u, i, points)? {
            max_penetration = max_penetration.max(x - gap);
        }
    }
    Ok(ResponseSummary {
        dof,
        points,
        displacement_max,
        displacement_min,
        displacement_rms,
        max_penetration,
        contact_force_mean,
    })
}

/// `u_dof(t)` at arbitrary times from harmonic-major coefficients.
pub(crate) fn displacement_at(
    lin: &LinearData,
    omega: f64,
    u: &[f64],
    dof: usize,
    times: &[f64],
) -> Result<Vec<f64>, HbError> {
    lin.check_dof(dof)?;
    let mut coeffs = vec![0.0; lin.size()];
    lin.gather(u, dof, &mut coeffs);
    let mut out = vec![0.0; times.len()];
    lin.basis.evaluate_many(&coeffs, omega, times, &mut out)?;
    Ok(out)
}

/// Shared state of both formulations at the current frequency.
#[derive(Debug)]
pub(crate) struct HbState {
    pub(crate) linear: Arc<LinearData>,
    pub(crate) omega: f64,
    /// The modal damping `xi` of the operator (`D - xi M`; 0 by default).
    pub(crate) modal_damping: f64,
    pub(crate) aft: Aft,
}

impl HbState {
    /// Turns the switching samples of contact `i` (the AFT's samples) into the indicator
    /// `h_n = [s_n > 0]` and writes the block `P diag(h) E` of the Jacobian; records the
    /// active count.
    pub(crate) fn write_contact_block(&mut self, jac: &mut jacobian::HbJacobian, i: usize) {
        jac.active[i] = indicator(self.aft.samples_mut());
        let block = self.linear.laws.diagonal[i];
        self.aft.samples_multiplication_matrix(&mut jac.q[block]);
    }

    /// Writes the block `P diag(w) E` of contact `i` with the weights `w_n` in the AFT's
    /// samples (a smoothed indicator in `[0, 1]`); records the samples with `w_n > 1/2` as
    /// active.
    pub(crate) fn write_weighted_contact_block(
        &mut self,
        jac: &mut jacobian::HbJacobian,
        i: usize,
    ) {
        jac.active[i] = self.aft.samples_mut().iter().filter(|w| **w > 0.5).count();
        let block = self.linear.laws.diagonal[i];
        self.aft.samples_multiplication_matrix(&mut jac.q[block]);
    }

    /// The operator's parameters: `w` and the modal damping.
    pub(crate) fn parameters(&self) -> HarmonicParameters {
        HarmonicParameters {
            omega: self.omega,
            modal_damping: self.modal_damping,
        }
    }

    /// A Jacobian of this state's model at its parameters with `coupling`.
    pub(crate) fn new_jacobian(&self, coupling: ContactCoupling) -> HbJacobian {
        HbJacobian::new(self.linear.clone(), self.parameters(), coupling)
    }

    /// Makes `jac` a Jacobian of this state's model at its frequency with `coupling` (its
    /// contact blocks are then written contact by contact).
    pub(crate) fn prepare_jacobian(&self, jac: &mut HbJacobian, coupling: ContactCoupling) {
        if !Arc::ptr_eq(&jac.linear, &self.linear) {
            *jac = self.new_jacobian(coupling);
        }
        jac.parameters = self.parameters();
        jac.coupling = coupling;
    }

    /// `dR/d parameter` of the displacement equations, `dA/d parameter U`, into `out`
    /// (first `len` entries, `U = x[..len]`); the rest of `out` (force equations) is zero.
    pub(crate) fn parameter_derivative(
        &self,
        parameter: OperatorParameter,
        x: &[f64],
        len: usize,
        out: &mut [f64],
    ) {
        let (out_u, rest) = out.split_at_mut(len);
        self.linear
            .operator
            .apply_derivative(&self.parameters(), parameter, &x[..len], out_u);
        rest.fill(0.0);
    }

    pub(crate) fn new(linear: LinearData, omega: f64) -> Self {
        let aft = Aft::new(linear.basis);
        Self {
            linear: Arc::new(linear),
            omega,
            modal_damping: 0.0,
            aft,
        }
    }
}

/// Replaces each sample by the indicator `[s_n > 0]`; returns how many are 1.
pub(crate) fn indicator(samples: &mut [f64]) -> usize {
    let mut active = 0;
    for s in samples.iter_mut() {
        *s = if *s > 0.0 {
            active += 1;
            1.0
        } else {
            0.0
        };
    }
    active
}
