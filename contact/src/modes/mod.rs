//! Nonlinear modes by the extended periodic motion concept (EPMC, Krack 2015) on SSN-HB:
//! exact contact and friction, no regularisation.
//!
//! The autonomous equation `M u'' + (D - xi M) u' + K u = G^T lambda(t)` (no load) with the
//! contact and friction laws of [`SsnHb`]: the negative modal damping `-xi M u'` cancels the
//! dissipation on average, so the motion is periodic. Unknowns
//! `x = [U; Lambda; w; xi]`: the harmonics of the motion and of the contact forces
//! ([`SsnHb`]'s unknowns, harmonic `k` on `k w`), the frequency `w` and the modal damping
//! `xi` (the term `+ i k w xi M` of the harmonic operator, [`crate::operator`]). Two more
//! equations close the system, both on a linear functional `q(u) = a . u` (the modal
//! coordinate `phi^T M u` of the mode followed, or one dof):
//!
//! - phase: the sine part of harmonic 1 of `q` is zero, `a . U_s1 = 0`;
//! - amplitude: the cosine part of harmonic 1 of `q` is the amplitude, `a . U_c1 = A`.
//!
//! `A` is the parameter of [`ParameterDependent`], followed by the core's continuation
//! ([`semismooth::continuation`], through folds). The Jacobian [`EpmcJacobian`] is the HB
//! Jacobian bordered by the columns `dR/dw`, `dR/dxi` and the two rows above. The HB
//! Jacobian alone is singular on every periodic motion of an autonomous system (the time
//! shift `U'` is in its kernel), so the bordered matrix is factored as a whole
//! ([`EpmcJacobian`] is [`DenseAssemble`], for the core's dense LU), and the
//! continuation adds its own border to that regular matrix. For large models
//! ([`Epmc::deflated`], [`EpmcStructuredSolver`]) a grounding spring `s` on one dof makes
//! the inner Jacobian regular and the residual takes it out again: the inner block is
//! factored by the structured HB solver once per iteration, under a border `2H + 3` wide.
//!
//! At small amplitude (contacts open, friction points stuck) the solution is the linear
//! mode ([`linear_mode`]): `w = omega_n`, `xi = phi^T D phi = 2 zeta omega_n`. The damping
//! ratio reported is NLvib's `zeta = xi / (2 w)`. Without damping and friction `xi` stays
//! zero: the backbone of a conservative system, frequency against energy.
//!
//! Reference: M. Krack, *Nonlinear modal analysis of nonconservative systems: Extension of
//! the periodic motion concept*, Computers & Structures 154 (2015) 59-71.

mod backbone;
mod linear;
mod sector;
mod structured;

use faer::MatMut;
use semismooth::linalg::DenseAssemble;
use semismooth::{EvaluationError, GeneralizedJacobian, ParameterDependent, Residual};

use crate::hb::{HbError, HbJacobian, HbOptions, SsnHb};
use crate::model::{sparse_mul_add, SparseMatrix, StructuralModel};
use crate::operator::OperatorParameter;

pub use backbone::{
    backbone, backbone_continuation, Backbone, BackboneOptions, BackbonePoint, EpmcSolve,
    BACKBONE_CORRECTOR_ITERATIONS, BACKBONE_MIN_STEP, DEFAULT_RELATIVE_TOLERANCE,
};
pub use linear::{linear_mode, LinearMode};
pub use structured::EpmcStructuredSolver;

/// Why a nonlinear mode could not be set up.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ModesError {
    /// The harmonic balance could not be built (model, options).
    #[error(transparent)]
    Hb(#[from] HbError),
    /// The mode asked for does not exist.
    #[error("mode {mode} asked for, the structure has {available} finite ones (numbered from 1)")]
    NoSuchMode {
        /// The mode asked for.
        mode: usize,
        /// Number of modes with a finite frequency.
        available: usize,
    },
    /// The linear eigenproblem could not be solved.
    #[error("linear modes: {0}")]
    LinearMode(String),
    /// The amplitude functional is zero on the mode's shape (e.g. a dof at a node).
    #[error("the amplitude measure is zero on mode {mode}'s shape")]
    AmplitudeNotSeen {
        /// The mode.
        mode: usize,
    },
    /// The bordered Jacobian, factored densely, would be too large.
    #[error(
        "{unknowns} EPMC unknowns exceed the {limit} of the dense bordered solve: reduce the \
         harmonics or the dofs, or use the structured solve"
    )]
    TooLarge {
        /// `(N + m)(2H + 1) + 2`.
        unknowns: usize,
        /// [`MAX_DENSE_UNKNOWNS`].
        limit: usize,
    },
    /// The continuation could not start (options, range).
    #[error("continuation: {0}")]
    Continuation(String),
    /// A reduced cyclic sector whose harmonic 1 lies on a travelling wave: its linear modes
    /// have complex shapes, which the linear start does not take (module `sector`).
    #[error(
        "a cyclic sector's nonlinear mode starts from a standing wave: harmonic 1 lies on \
         nodal diameter {nodal_diameter} of {sectors} sectors, whose modes are travelling waves \
         (complex shapes); engine order 0 (or N/2 for even N) puts it on nodal diameter 0 \
         (or N/2)"
    )]
    TravellingWaveSector {
        /// Harmonic 1's nodal diameter, folded to `0..=N/2`.
        nodal_diameter: usize,
        /// `N`.
        sectors: usize,
    },
}

/// The largest number of EPMC unknowns [`backbone`] factors densely (a matrix of 512 MB).
pub const MAX_DENSE_UNKNOWNS: usize = 8000;

/// What the amplitude of a nonlinear mode measures: the cosine part of harmonic 1 of a
/// linear functional of `u`, once the phase makes the sine part zero.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum AmplitudeMeasure {
    /// The modal coordinate `phi^T M u` of the linear mode followed.
    ModalCoordinate,
    /// The displacement of one dof.
    Dof(usize),
}

/// The EPMC problem: [`SsnHb`] without load, bordered by `w`, `xi` and the phase and
/// amplitude equations (module documentation).
#[derive(Debug)]
pub struct Epmc {
    hb: SsnHb,
    /// The functional `a` of the phase and amplitude equations (length `N`).
    weights: Vec<f64>,
    /// Scale of the two border rows (a stiffness: they read as forces, like `R_u`).
    row_scale: f64,
    amplitude: f64,
    /// The load-free model's linear mode followed.
    mode: LinearMode,
    /// `K` and `M` of each harmonic `0..=H` of a reduced cyclic sector (its couplings at
    /// their real phases, module `sector`), one pair for every harmonic otherwise: the
    /// energy.
    energy_matrices: Vec<(SparseMatrix, SparseMatrix)>,
    /// The grounding spring the inner harmonic balance carries for the structured solve
    /// ([`Epmc::deflated`]); `None`: the model's own stiffness.
    deflation: Option<Deflation>,
}

/// A grounding spring `s` at one dof, added to the stiffness of [`Epmc`]'s inner harmonic
/// balance on every harmonic and taken out again by the residual (`R = R~ - s E U`, `E`
/// the dof's entry of every harmonic block): it makes the inner Jacobian regular
/// ([`EpmcStructuredSolver`]) without changing the equations.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Deflation {
    dof: usize,
    stiffness: f64,
}

impl Epmc {
    /// EPMC of `model` (its load ignored) with the HB `options`, following mode `mode`
    /// (1-based, [`linear_mode`]) with the amplitude measured by `measure`.
    pub fn new(
        model: &StructuralModel,
        options: &HbOptions,
        mode: usize,
        measure: AmplitudeMeasure,
    ) -> Result<Self, ModesError> {
        Self::build(model, options, mode, measure, false)
    }

    /// The same problem for [`EpmcStructuredSolver`]: its inner harmonic balance carries a
    /// grounding spring of the stiffness scale at the largest entry `d` of the mode's
    /// shape, which the residual and [`EpmcJacobian`]'s dense form take out again
    /// (`R = R~ - s E U`). Same equations, same solutions; the inner Jacobian `J~ = J + s E`
    /// is regular where `J` is not (the time shift `U'` and, at small amplitude, the linear
    /// mode itself, on which `J~` adds `s phi_d^2`).
    pub fn deflated(
        model: &StructuralModel,
        options: &HbOptions,
        mode: usize,
        measure: AmplitudeMeasure,
    ) -> Result<Self, ModesError> {
        Self::build(model, options, mode, measure, true)
    }

    fn build(
        model: &StructuralModel,
        options: &HbOptions,
        mode: usize,
        measure: AmplitudeMeasure,
        deflate: bool,
    ) -> Result<Self, ModesError> {
        let mut free = model.clone();
        free.load = crate::model::HarmonicLoad::zero(model.dofs());
        let linear = linear_mode(&free, mode)?;
        let n = model.dofs();
        let row_scale = (0..n)
            .map(|i| crate::model::diagonal_entry(&model.stiffness, i).abs())
            .fold(0.0f64, f64::max)
            .max(f64::MIN_POSITIVE);
        let deflation = deflate.then(|| Deflation {
            dof: (0..n)
                .max_by(|&i, &j| linear.shape[i].abs().total_cmp(&linear.shape[j].abs()))
                .unwrap_or(0),
            stiffness: row_scale,
        });
        let mut options = *options;
        if let Some(spring) = deflation {
            // The model's own c: its default reads the stiffness the spring changes.
            options.c = options.c.or(Some(free.default_complementarity_constant()));
            free.stiffness = grounded(&model.stiffness, spring)?;
        }
        let hb = SsnHb::new(&free, linear.omega, &options)?;
        let energy_matrices = sector::harmonic_stiffness_and_mass(model, options.harmonics)?;
        let weights = match measure {
            AmplitudeMeasure::ModalCoordinate => {
                let mut w = vec![0.0; n];
                let mass = &energy_matrices[1.min(energy_matrices.len() - 1)].1;
                sparse_mul_add(mass.as_ref(), 1.0, &linear.shape, &mut w);
                w
            }
            AmplitudeMeasure::Dof(dof) => {
                crate::hb::check_index("dof", dof, n)?;
                let mut w = vec![0.0; n];
                w[dof] = 1.0;
                w
            }
        };
        let seen: f64 = weights.iter().zip(&linear.shape).map(|(a, b)| a * b).sum();
        let largest = linear.shape.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if seen.abs() <= 1e-10 * largest * weights.iter().fold(0.0f64, |m, v| m.max(v.abs())) {
            return Err(ModesError::AmplitudeNotSeen { mode });
        }
        Ok(Self {
            hb,
            weights,
            row_scale,
            amplitude: 0.0,
            mode: linear,
            energy_matrices,
            deflation,
        })
    }

    /// True when built by [`Epmc::deflated`] (for [`EpmcStructuredSolver`]).
    pub fn is_deflated(&self) -> bool {
        self.deflation.is_some()
    }

    /// The size of a displacement of the linear start at `amplitude` (its largest entry),
    /// times the stiffness scale: the size of the forces, which the corrector's relative
    /// tolerance multiplies ([`BackboneOptions::relative_tolerance`]).
    pub fn force_scale(&self, amplitude: f64) -> f64 {
        let n = self.hb.dofs();
        let start = self.linear_start(amplitude);
        let largest = start[n..2 * n].iter().fold(0.0f64, |m, v| m.max(v.abs()));
        self.row_scale * largest
    }

    /// The linear mode followed.
    pub fn linear_mode(&self) -> &LinearMode {
        &self.mode
    }

    /// The harmonic balance inside (unknowns `x[..hb_len()]`, at the last `w`, `xi` set).
    pub fn hb(&self) -> &SsnHb {
        &self.hb
    }

    /// Number of HB unknowns `(N + m)(2H + 1)`; `w` and `xi` follow them.
    pub fn hb_len(&self) -> usize {
        self.hb.dim()
    }

    /// The linear mode at amplitude `amplitude` as a starting point: `U_c1 = A phi / (a .
    /// phi)`, no contact force, `w = omega_n`, `xi = 2 zeta omega_n`.
    pub fn linear_start(&self, amplitude: f64) -> Vec<f64> {
        let n = self.hb.dofs();
        let seen: f64 = self
            .weights
            .iter()
            .zip(&self.mode.shape)
            .map(|(a, b)| a * b)
            .sum();
        let mut x = vec![0.0; self.hb_len() + 2];
        for (u, phi) in x[n..2 * n].iter_mut().zip(&self.mode.shape) {
            *u = amplitude * phi / seen;
        }
        let last = x.len();
        x[last - 2] = self.mode.omega;
        x[last - 1] = 2.0 * self.mode.damping_ratio * self.mode.omega;
        x
    }

    /// `w` of the unknowns `x`.
    pub fn omega(&self, x: &[f64]) -> f64 {
        x[self.hb_len()]
    }

    /// The modal damping `xi` of the unknowns `x`.
    pub fn modal_damping(&self, x: &[f64]) -> f64 {
        x[self.hb_len() + 1]
    }

    /// NLvib's modal damping ratio `zeta = xi / (2 w)`.
    pub fn damping_ratio(&self, x: &[f64]) -> f64 {
        self.modal_damping(x) / (2.0 * self.omega(x))
    }

    /// The period mean of the mechanical energy `u^T K u / 2 + u'^T M u' / 2` (exact by
    /// Parseval): `U_0^T K U_0 / 2 + sum_k (|U_k|_K^2 + (k w)^2 |U_k|_M^2) / 4`,
    /// `|U_k|_A^2 = a_k^T A a_k + b_k^T A b_k`. Constant along the motion of a conservative
    /// system (rigid stops store no energy). For a reduced cyclic sector harmonic `k` takes
    /// its own `K`, `M` (with the couplings at its phase): the energy of one sector, the
    /// disk's divided by `N`.
    pub fn energy(&self, x: &[f64]) -> f64 {
        let n = self.hb.dofs();
        let omega = self.omega(x);
        let quadratic = |a: &SparseMatrix, u: &[f64]| {
            let mut y = vec![0.0; n];
            sparse_mul_add(a.as_ref(), 1.0, u, &mut y);
            y.iter().zip(u).map(|(p, q)| p * q).sum::<f64>()
        };
        let of_harmonic = |k: usize| &self.energy_matrices[k.min(self.energy_matrices.len() - 1)];
        let mut energy = 0.5 * quadratic(&of_harmonic(0).0, &x[..n]);
        for j in 1..self.hb.basis().basis_size() {
            let u = &x[j * n..(j + 1) * n];
            let k = j.div_ceil(2);
            let (stiffness, mass) = of_harmonic(k);
            let kw = k as f64 * omega;
            energy += 0.25 * (quadratic(stiffness, u) + kw * kw * quadratic(mass, u));
        }
        energy
    }

    /// Sets `w` and `xi` of the harmonic balance from the unknowns (`w > 0` and finite
    /// `xi`, else outside the domain).
    fn set_operator(&mut self, x: &[f64]) -> Result<(), EvaluationError> {
        let (omega, xi) = (self.omega(x), self.modal_damping(x));
        self.hb
            .set_omega(omega)
            .map_err(|_| EvaluationError::OutsideDomain {
                what: "mode frequency",
                value: omega,
            })?;
        self.hb
            .set_modal_damping(xi)
            .map_err(|_| EvaluationError::OutsideDomain {
                what: "modal damping",
                value: xi,
            })
    }

    /// `a . U_j` for the coefficient block `j` of the displacements.
    fn measure(&self, x: &[f64], j: usize) -> f64 {
        let n = self.hb.dofs();
        self.weights
            .iter()
            .zip(&x[j * n..(j + 1) * n])
            .map(|(a, u)| a * u)
            .sum()
    }
}

impl Residual for Epmc {
    fn dim(&self) -> usize {
        self.hb_len() + 2
    }

    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        let len = self.hb_len();
        self.set_operator(x)?;
        self.hb.residual(&x[..len], &mut out[..len])?;
        if let Some(spring) = self.deflation {
            let n = self.hb.dofs();
            for j in 0..self.hb.basis().basis_size() {
                out[j * n + spring.dof] -= spring.stiffness * x[j * n + spring.dof];
            }
        }
        out[len] = self.row_scale * self.measure(x, 2);
        out[len + 1] = self.row_scale * (self.measure(x, 1) - self.amplitude);
        Ok(())
    }

    fn problem_counters(&self) -> semismooth::ProblemCounters {
        self.hb.problem_counters()
    }
}

/// The Jacobian of [`Epmc`]: the HB Jacobian bordered by the columns `dR/dw`, `dR/dxi`
/// and the phase and amplitude rows (constant: `row_scale a` on `U_s1` and on `U_c1`).
#[derive(Debug, Clone)]
pub struct EpmcJacobian {
    inner: HbJacobian,
    /// `dR/dw` then `dR/dxi` (each of the HB length).
    columns: Vec<f64>,
    /// `row_scale a` (length `N`).
    row: Vec<f64>,
    /// The grounding spring `inner` carries ([`Epmc::deflated`]).
    deflation: Option<Deflation>,
}

impl DenseAssemble for EpmcJacobian {
    fn dim(&self) -> usize {
        self.columns.len() / 2 + 2
    }

    fn assemble_dense(&self, mut out: MatMut<'_, f64>) {
        let len = self.columns.len() / 2;
        let n = self.row.len();
        out.fill(0.0);
        self.inner
            .assemble_dense(out.as_mut().submatrix_mut(0, 0, len, len));
        for (c, column) in self.columns.chunks_exact(len).enumerate() {
            for (i, v) in column.iter().enumerate() {
                out[(i, len + c)] = *v;
            }
        }
        for (dof, a) in self.row.iter().enumerate() {
            out[(len, 2 * n + dof)] = *a;
            out[(len + 1, n + dof)] = *a;
        }
        if let Some(spring) = self.deflation {
            for j in 0..self.inner.harmonics() * 2 + 1 {
                out[(j * n + spring.dof, j * n + spring.dof)] -= spring.stiffness;
            }
        }
    }
}

impl GeneralizedJacobian for Epmc {
    type Jacobian = EpmcJacobian;

    fn new_jacobian(&self) -> EpmcJacobian {
        EpmcJacobian {
            inner: self.hb.new_jacobian(),
            columns: vec![0.0; 2 * self.hb_len()],
            row: self.weights.iter().map(|a| self.row_scale * a).collect(),
            deflation: self.deflation,
        }
    }

    fn jacobian(&mut self, x: &[f64], jac: &mut EpmcJacobian) -> Result<(), EvaluationError> {
        let len = self.hb_len();
        self.set_operator(x)?;
        self.hb.jacobian(&x[..len], &mut jac.inner)?;
        let (omega, xi) = jac.columns.split_at_mut(len);
        let parts = [
            (OperatorParameter::Omega, omega),
            (OperatorParameter::ModalDamping, xi),
        ];
        for (parameter, column) in parts {
            self.hb
                .residual_operator_derivative(parameter, &x[..len], column)
                .map_err(EvaluationError::problem)?;
        }
        Ok(())
    }
}

impl ParameterDependent for Epmc {
    fn parameter(&self) -> f64 {
        self.amplitude
    }

    fn set_parameter(&mut self, p: f64) {
        self.amplitude = p;
    }

    fn residual_parameter_derivative(
        &mut self,
        _x: &[f64],
        out: &mut [f64],
        _scratch: &mut [f64],
    ) -> Result<(), EvaluationError> {
        out.fill(0.0);
        out[self.hb_len() + 1] = -self.row_scale;
        Ok(())
    }
}

/// `K + s e_d e_d^T` of the grounding spring `spring`.
fn grounded(stiffness: &SparseMatrix, spring: Deflation) -> Result<SparseMatrix, ModesError> {
    let n = stiffness.nrows();
    let mut entries: Vec<(usize, usize, f64)> = Vec::with_capacity(stiffness.compute_nnz() + 1);
    let symbolic = stiffness.symbolic();
    for j in 0..n {
        for q in symbolic.col_range(j) {
            entries.push((symbolic.row_idx()[q], j, stiffness.val()[q]));
        }
    }
    entries.push((spring.dof, spring.dof, spring.stiffness));
    crate::builder::sparse_matrix(n, &entries).map_err(|e| ModesError::Hb(HbError::from(e)))
}
