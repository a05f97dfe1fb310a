//! The periodic time-domain linear complementarity problem (after Meingast, Legrand &
//! Pierre, *A linear complementarity problem formulation for periodic solutions to
//! unilateral contact problems*, IJNLM 66, 2014).
//!
//! # Discretisation
//!
//! One period `T = 2 pi / omega` is split into `Nt` steps `dt = T / Nt`, nodes
//! `t_n = n dt`. The linear dynamics `M u'' + D u' + K u = f + G^T lambda` is discretised by
//! the periodic trapezoidal (energy-conserving) rule. Written with the shift `x_{n+1}`,
//! the trapezoidal rule maps `d/dt` to `(2/dt) (E - 1)/(E + 1)`; on the DFT bin `k`
//! (`E = e^{i theta_k}`, `theta_k = 2 pi k / Nt`) this is the bilinear (Tustin) map
//!
//! ```text
//! s_k = (2/dt) i tan(pi k / Nt),     Z_k = K + s_k D + s_k^2 M,     Z_k U_k = F_k + G^T Lambda_k,
//! ```
//!
//! so the discrete periodic problem is diagonalised by the DFT. Frequencies are warped:
//! `(2/dt) tan(pi k/Nt) = k omega (1 + (pi k / Nt)^2 / 3 + ...)`, a second-order error.
//!
//! **Nyquist bin** (`k = Nt/2`, even `Nt`), where `tan` blows up: the receptance is taken
//! as the limit `s -> i infinity` of `Z(s)^{-1}`. Split the dofs into those with mass,
//! those without mass but with damping, and the set `V` with neither (columns of `M` and
//! `D` both zero). As `s -> infinity`, `Z^{-1}` on the massive dofs behaves like
//! `(s^2 M)^{-1} -> 0`, on the damped massless ones like `(s D)^{-1} -> 0`, and the Schur
//! complement onto `V` tends to `K_VV`: `lim Z(s)^{-1} = P_V K_VV^{-1} P_V^T`, the static
//! receptance of the part of the structure that has neither inertia nor damping, with
//! everything else held fixed. (Derivation: with `M` positive definite on the massive
//! block and `D` positive semi-definite, `D` vanishes on every row of `V`, so the coupling
//! `Z_aV = K_aV` stays bounded while `Z_aa^{-1} = O(s^{-2})`.) This is what the trapezoidal
//! rule with the force balance of `V` collocated at the nodes gives (the massless-node
//! "modified mass" scheme): for an undamped massless tip the Nyquist receptance is
//! `1 / K_tt`; with stiffness-proportional damping `V` is empty and it is `0`, so `A` then
//! has the alternating null vector `(-1)^n` (the familiar contact-force oscillation of the
//! trapezoidal rule, here invisible in the displacements). The limit assumes `ker M` and
//! `ker D` are spanned by coordinate directions (true for the rod's consistent, lumped and
//! modified masses).
//!
//! **BDF2** ([`LcpScheme::Bdf2`], `lcp_scheme = "bdf2"`): the second-order backward
//! differentiation formula `u'_n = (3 u_n - 4 u_{n-1} + u_{n-2}) / (2 dt)`, applied to `u`
//! and to `u'`, has the symbol
//!
//! ```text
//! s_k = (3 - 4 e^{-i theta_k} + e^{-2 i theta_k}) / (2 dt)
//!     = (i theta_k (1 + theta_k^2 / 3) + theta_k^4 / 4 + ...) / dt,     Z_k = K + s_k D + s_k^2 M,
//! ```
//!
//! the same second-order warping as the trapezoidal rule plus a positive real part, a
//! numerical damping that is negligible on the forced harmonics (`theta^3 / 4`: 4e-6 on
//! the first at `Nt = 256`) and strong near Nyquist, where `s = 4 / dt` is real: `Z` is
//! then symmetric positive definite and the Nyquist receptance `G Z^{-1} G^T` is positive,
//! with or without mass and damping on the contact. The alternating force is no longer
//! invisible, so the LCP keeps no null vector. The trapezoidal LCP is the periodic orbit of
//! the energy-conserving march; the BDF2 LCP is that of a dissipative march, a different
//! discretisation of the same continuous problem (both converge at second order in `dt`).
//!
//! # The LCP
//!
//! Eliminating the displacements, the contact displacements at the nodes are
//! `G u = u_lin + R lambda`, `R` block-circulant with `m x m` blocks `a_{n-j}` and kernel
//! `a_p = (1/Nt) sum_k H_k e^{2 pi i k p / Nt}`, `H_k = G Z_k^{-1} G^T` (one complex sparse LU
//! per bin `k = 0..=Nt/2`, the other bins by conjugate symmetry; the kernel by FFT, never
//! by `Nt` solves). With `z = -lambda >= 0` (a compressive force) and the gap
//! `w = g - G u >= 0`:
//!
//! ```text
//! w = q + A z,   q = g - u_lin,   A = R,   w >= 0, z >= 0, w . z = 0.
//! ```
//!
//! A compressive `z > 0` pushes the structure away from the obstacle and opens the gap,
//! so `A` is the (positive at low frequency) receptance circulant. Unknowns are ordered
//! time-major: index `n m + c` for node `n` and contact `c`.
//!
//! `A` is symmetric iff its kernel is even in time, i.e. every `H_k` is real symmetric:
//! true without damping. The symmetric part `(A + A^T)/2` has the eigenvalues of the
//! Hermitian parts `(H_k + H_k^*)/2` ([`PeriodicLcp::symmetric_part_spectrum`]); above a
//! resonance `Re H_k < 0`, so it is generally indefinite and Lemke's method is not
//! guaranteed to succeed (it may end on a ray).
//!
//! Solvers: [`PeriodicLcp::solve_with_lemke`] (method `"lcp-lemke"`) and the semismooth
//! equation `min(z, q + A z) = 0`, [`MinMapLcp`] with the [`ActiveSetSolver`] (method
//! `"lcp-ssn"`), best through [`solve_min_map_sequenced`] at large `Nt`.
//!
//! # Options (defaults)
//! - `time_samples`, the number of steps per period `Nt`: default
//!   [`DEFAULT_LCP_TIME_SAMPLES`] (256); `Nt >= 8`, `contacts * Nt <= 8192`.
//! - `observed_dofs`, the dofs whose histories are kept: default none.
//! - `scheme`, the time discretisation: default [`LcpScheme::Trapezoidal`].
//!
//! # Measured on the canonical rod (20 elements, `zeta = 0.01`, `omega = omega_1`, gap 0.5)
//!
//! Modified mass (massless tip): Lemke solves at every `Nt` (61 / 172 / 529 / 1894 / 7118
//! pivots at `Nt` = 128 / 256 / 512 / 1024 / 2048; `docs/performance.md` for the time), tip minimum
//! -0.5234851 / -0.5232093 / -0.5231566 / -0.5231539 / -0.5231508, identical (to 1e-13)
//! to semismooth Newton and to the steady state of the massless-contact trapezoidal march
//! with the same step. `(A + A^T)/2` is slightly indefinite (smallest eigenvalue about
//! -3.6e-3 against a largest of 1 at `Nt >= 256`). Consistent or lumped mass: more
//! indefinite (-1.6e-2, -8e-2); Lemke solves at `Nt = 128` (491 / 289 pivots), at 256 it
//! needs 25369 / 6651 pivots (the default limit `50 n + 100` stops the consistent case)
//! and at `Nt >= 512` it had not finished after `100 n` pivots; Newton from zero does not
//! converge in 100 iterations.
//!
//! ```
//! use semismooth::lemke::{Lemke, LemkeOptions};
//! use semismooth_contact::lcp::{PeriodicLcp, PeriodicLcpOptions};
//! use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
//! let mut spec = RodSpec::canonical();
//! spec.mass = MassModel::Modified;
//! let rod = build_rod(&spec).unwrap();
//! let options = PeriodicLcpOptions { time_samples: 128, ..Default::default() };
//! let lcp = PeriodicLcp::new(&rod.model, rod.omega(), options).unwrap();
//! let mut lemke = Lemke::new(lcp.dim());
//! let report = lcp.solve_with_lemke(&mut lemke, &LemkeOptions::default()).unwrap();
//! let report = lcp.check_lemke(report).unwrap(); // a ray or pivot limit would be an Err
//! let tip = &lcp.contact_displacements(&report.z).unwrap()[0];
//! let lowest = tip.iter().cloned().fold(f64::INFINITY, f64::min);
//! let highest = tip.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
//! assert!((highest - 0.5).abs() < 1e-12); // the tip reaches the obstacle
//!
//! // Independent check: the LCP is the periodic orbit of the massless-contact trapezoidal
//! // march with the same step, so marching to a steady state gives the same tip. The
//! // march stops at a period-to-period change of 1e-12; the transient left is about 16
//! // times that (decay 0.94 per period): 1.6e-11 bounds the difference (measured 1.4e-12
//! // on the whole tip history).
//! use semismooth_contact::march::{march_to_steady_state, MarchOptions, MarchScheme};
//! let march_options = MarchOptions {
//!     steps_per_period: 128,
//!     max_periods: 5000,
//!     tolerance: 1e-12,
//!     scheme: MarchScheme::MasslessContactTrapezoidal,
//! };
//! let tip_dof = rod.model.dofs() - 1;
//! let march = march_to_steady_state(&rod.model, rod.omega(), &march_options, &[tip_dof]).unwrap();
//! let marched = march.displacements[0][..128].iter().cloned().fold(f64::INFINITY, f64::min);
//! assert!((lowest - marched).abs() < 2e-11);
//! ```

mod build;
mod frequency;
mod min_map;
mod sequencing;

pub use frequency::{FrequencyLcp, FrequencyLcpJacobian, FrequencyLcpSolver};
pub use min_map::{ActiveSetSolver, MinMapJacobian, MinMapLcp, DEFAULT_ACTIVE_SET_REGULARIZATION};
pub(crate) use sequencing::interpolate_periodic;
pub use sequencing::{solve_min_map_sequenced, SequencedSolution, SequencingLevel};

use std::sync::Arc;

use faer::{c64, Mat, MatRef};
use rustfft::{Fft, FftPlanner};
use semismooth::lemke::{Lemke, LemkeError, LemkeOptions, LemkeReport, LemkeTermination};
use semismooth::linalg::LinearSolveError;
use semismooth::newton::NewtonError;
use semismooth::InvalidOption;

use crate::model::InvalidModel;

/// Default number of time steps per period `Nt` of the periodic LCP.
pub const DEFAULT_LCP_TIME_SAMPLES: usize = 256;
/// Smallest accepted `Nt`.
pub const MIN_LCP_TIME_SAMPLES: usize = 8;
/// Largest accepted LCP size `contacts * Nt` (the dense matrix holds its square: 512 MB).
pub const MAX_LCP_SIZE: usize = 8192;

/// The time discretisation of the periodic LCP (module documentation, *Discretisation*):
/// its symbol `s_k`, the image of `d/dt` on DFT bin `k`, gives `Z_k = K + s_k D + s_k^2 M`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum LcpScheme {
    /// The trapezoidal rule, `s_k = (2/dt) i tan(pi k / Nt)`: energy-conserving, the
    /// periodic orbit of the trapezoidal march with the same step; the Nyquist bin is its
    /// limit (default).
    #[default]
    Trapezoidal,
    /// The second-order backward differentiation formula (BDF2),
    /// `s_k = (3 - 4 e^{-i theta_k} + e^{-2 i theta_k}) / (2 dt)`: second order, with
    /// numerical damping at the highest bins (`Re s_k > 0`), so every `Z_k` is invertible
    /// with a damped or massive structure and the Nyquist receptance is not 0.
    Bdf2,
}

impl LcpScheme {
    /// The scene's name of the scheme (`lcp_scheme = "..."`).
    pub fn name(self) -> &'static str {
        match self {
            Self::Trapezoidal => "trapezoidal",
            Self::Bdf2 => "bdf2",
        }
    }
}

/// Options of [`PeriodicLcp::new`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PeriodicLcpOptions {
    /// Number of time steps per period `Nt` (default [`DEFAULT_LCP_TIME_SAMPLES`]);
    /// `Nt >= 8` and `contacts * Nt <= MAX_LCP_SIZE`. Any such `Nt` (FFTs by rustfft).
    pub time_samples: usize,
    /// Degrees of freedom whose displacement history [`PeriodicLcp::displacements`]
    /// returns (default none; the contact dofs are always available through
    /// [`PeriodicLcp::contact_displacements`]).
    pub observed_dofs: Vec<usize>,
    /// The time discretisation (default [`LcpScheme::Trapezoidal`]).
    pub scheme: LcpScheme,
}

impl Default for PeriodicLcpOptions {
    fn default() -> Self {
        Self {
            time_samples: DEFAULT_LCP_TIME_SAMPLES,
            observed_dofs: Vec::new(),
            scheme: LcpScheme::Trapezoidal,
        }
    }
}

impl PeriodicLcpOptions {
    /// Checks `time_samples` for a model with `contacts` contacts and `dofs` dofs, and the
    /// observed dofs.
    pub fn validate(&self, contacts: usize, dofs: usize) -> Result<(), LcpError> {
        let nt = self.time_samples;
        if nt < MIN_LCP_TIME_SAMPLES || contacts.saturating_mul(nt) > MAX_LCP_SIZE {
            return Err(LcpError::InvalidOption(InvalidOption::new(
                "time_samples",
                nt as f64,
                "an integer >= 8 with (number of contacts) * time_samples <= 8192 (a \
                          scene's solver.time_samples; the LCP matrix is dense)",
            )));
        }
        Ok(crate::model::check_observed(&self.observed_dofs, dofs)?)
    }
}

/// Why a periodic LCP could not be built, or a result could not be produced.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LcpError {
    /// An option is out of range.
    #[error("invalid option {0}")]
    InvalidOption(#[from] InvalidOption),
    /// The model has no contact: there is no complementarity problem.
    #[error("the model has no contact: the periodic LCP needs at least one")]
    NoContacts,
    /// The formulation does not model something the model declares.
    #[error("{formulation} does not model {what}")]
    Unsupported {
        /// The formulation.
        formulation: &'static str,
        /// What it does not model.
        what: &'static str,
    },
    /// A contact has its obstacle on the negative side (not formulated here).
    #[error(
        "contact {contact} (dof {}, 1-based) has its obstacle on the negative side: the \
         periodic LCP allows direction = +1 only (solve two-sided stops with ssn-hb, penalty-hb \
         or march)",
        .dof + 1
    )]
    NegativeDirection {
        /// Index of the contact.
        contact: usize,
        /// Its dof (0-based).
        dof: usize,
    },
    /// A contact's row of `G` is not one dof with coefficient `+1`.
    #[error(
        "contact {contact} (first dof {}, 1-based) is a combination of dofs: the periodic LCP \
         allows one dof with direction = +1 per contact (solve it with ssn-hb or march)",
        .dof + 1
    )]
    GeneralRow {
        /// Index of the contact.
        contact: usize,
        /// Its first dof (0-based).
        dof: usize,
    },
    /// The model has friction points.
    #[error(
        "the model has {points} friction points: the periodic LCP has no friction (solve it \
         with ssn-hb or march)"
    )]
    Friction {
        /// How many.
        points: usize,
    },
    /// A model quantity has the wrong size.
    #[error("dimension mismatch in {what}: expected {expected}, found {found}")]
    DimensionMismatch {
        /// Which quantity.
        what: &'static str,
        /// Expected size.
        expected: usize,
        /// Size found.
        found: usize,
    },
    /// The model is not usable (sizes, non-finite data, frequency, contacts).
    #[error(transparent)]
    Model(#[from] InvalidModel),
    /// A dynamic stiffness could not be factored for want of memory or indices, or the
    /// static block of the Nyquist limit is singular.
    #[error("factorization of the dynamic stiffness of bin {bin} failed: {source}")]
    Factorization {
        /// DFT bin (`Nt/2` is the Nyquist limit problem).
        bin: usize,
        /// What the sparse LU reported.
        source: LinearSolveError,
    },
    /// The LU of `Z_k` broke down (a zero pivot: a warped bin frequency on a natural
    /// frequency of an undamped model; with the trapezoidal rule only, since the BDF2
    /// symbol has `Re s_k > 0` for `k >= 1`).
    #[error("dynamic stiffness of bin {bin} (warped frequency {frequency}) is singular: {source}")]
    SingularBin {
        /// DFT bin.
        bin: usize,
        /// Warped angular frequency `(2/dt) tan(pi k / Nt)` (`Im s_k` for BDF2).
        frequency: f64,
        /// The singular pivot ([`LinearSolveError::Singular`]: its dof, value and the
        /// largest pivot).
        source: LinearSolveError,
    },
    /// Lemke's method ran but did not solve the LCP (secondary ray or pivot limit). A ray
    /// is possible when `A` is not copositive-plus: `symmetric_part_min_eigenvalue < 0`
    /// says the symmetric part of `A` is indefinite (e.g. a massive contact node).
    #[error(
        "Lemke's method ended on {termination:?} after {pivots} pivots (complementarity error \
         {complementarity_error:e}; smallest eigenvalue of the symmetric part of A \
         {symmetric_part_min_eigenvalue:e})"
    )]
    LemkeNotSolved {
        /// How Lemke's method ended.
        termination: LemkeTermination,
        /// Pivots made.
        pivots: usize,
        /// A-posteriori `max |min(z, w)|` of the last basic solution.
        complementarity_error: f64,
        /// Smallest eigenvalue of `(A + A^T)/2`.
        symmetric_part_min_eigenvalue: f64,
    },
    /// The Newton driver could not run (invalid options).
    #[error("semismooth Newton could not run: {0}")]
    Newton(#[from] NewtonError),
    /// [`PeriodicLcp::frequency_derivative`] on an LCP built without it (use
    /// [`PeriodicLcp::with_frequency_derivative`]).
    #[error("the LCP was built without its frequency derivative")]
    NoFrequencyDerivative,
    /// The LCP given to [`solve_min_map_sequenced`] was not built for its model.
    #[error("the finest LCP's {what} is {lcp}, the model's {model}")]
    ForeignLcp {
        /// What differs: `"omega"`, `"contact count"`, `"contact dof"` or `"contact gap"`.
        what: &'static str,
        /// The LCP's value.
        lcp: f64,
        /// The model's value.
        model: f64,
    },
    /// A vector passed in has the wrong length.
    #[error("{what} has length {found}, expected {expected}")]
    WrongLength {
        /// Which argument.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Length received.
        found: usize,
    },
}

/// The periodic LCP `w = q + A z, w >= 0, z >= 0, w . z = 0` of a structural model
/// (see the module documentation for the discretisation and the conventions).
#[derive(Debug, Clone)]
pub struct PeriodicLcp {
    nt: usize,
    scheme: LcpScheme,
    contacts: usize,
    omega: f64,
    gaps: Vec<f64>,
    contact_dofs: Vec<usize>,
    observed_dofs: Vec<usize>,
    /// Dense `A`, `(m Nt) x (m Nt)`, time-major.
    matrix: Mat<f64>,
    q: Vec<f64>,
    /// Per bin `k = 0..=Nt/2`, the transfer `(Z_k^{-1} G^T)[r, c]` for the rows
    /// `r` = contact dofs then observed dofs, stored `[(k * rows + r) * m + c]`.
    transfer: Vec<c64>,
    /// Complex amplitude `X_r` of the linear response: `u_lin,r(t_n) = Re(X_r e^{i 2 pi n/Nt})`.
    linear_amplitude: Vec<c64>,
    /// (min, max) eigenvalue of `(A + A^T)/2`.
    symmetric_spectrum: (f64, f64),
    /// Number of dofs without mass and damping (the Nyquist-limit set `V`).
    static_dofs: usize,
    /// `dH_k/domega` and `dX/domega` on the contact rows, when asked for.
    derivative: Option<FrequencyDerivative>,
    /// FFTs of length `Nt`, planned once.
    plans: FftPlans,
}

/// Complex FFT plans of one length `Nt` (any `Nt >= 1`, rustfft), both unnormalised:
/// `forward`: `X_k = sum_n x_n e^{-2 pi i k n / Nt}`, `inverse`: the conjugate sum.
#[derive(Clone)]
struct FftPlans {
    forward: Arc<dyn Fft<f64>>,
    inverse: Arc<dyn Fft<f64>>,
}

impl std::fmt::Debug for FftPlans {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FftPlans")
            .field("len", &self.len())
            .finish_non_exhaustive()
    }
}

impl FftPlans {
    fn new(nt: usize) -> Self {
        let mut planner = FftPlanner::new();
        Self {
            forward: planner.plan_fft_forward(nt),
            inverse: planner.plan_fft_inverse(nt),
        }
    }

    fn len(&self) -> usize {
        self.forward.len()
    }

    /// A scratch buffer for both directions.
    fn scratch(&self) -> Vec<c64> {
        let len = self
            .forward
            .get_inplace_scratch_len()
            .max(self.inverse.get_inplace_scratch_len());
        vec![c64::new(0.0, 0.0); len]
    }

    /// In place forward transform of `x` (length `Nt`).
    fn forward(&self, x: &mut [c64], scratch: &mut [c64]) {
        self.forward.process_with_scratch(x, scratch);
    }

    /// In place inverse (unnormalised) transform of `x` (length `Nt`).
    fn inverse(&self, x: &mut [c64], scratch: &mut [c64]) {
        self.inverse.process_with_scratch(x, scratch);
    }
}

/// Derivatives with respect to `omega` of the bin receptances `H_k` (contact rows only,
/// `[(k * m + c) * m + c2]`, `k = 0..=Nt/2`) and of the linear amplitudes `X_c` at the
/// contact dofs.
#[derive(Debug, Clone)]
struct FrequencyDerivative {
    transfer: Vec<c64>,
    linear_amplitude: Vec<c64>,
}

/// Histories over the `Nt` nodes of the rows `rows` of `u = Re(X_r e^{i omega t}) - R z`:
/// the harmonic-1 linear response with amplitudes `linear_amplitude[r]` minus the
/// circulant response to the compressive forces `z` (time-major, `m` contacts), applied by
/// FFT with the bin kernels `transfer[(k * rows_total + r) * m + c]`, `k = 0..=Nt/2` (the
/// other bins by conjugate symmetry).
fn kernel_response(
    plans: &FftPlans,
    m: usize,
    transfer: &[c64],
    rows_total: usize,
    linear_amplitude: &[c64],
    z: &[f64],
    rows: &[usize],
) -> Vec<Vec<f64>> {
    let zero = c64::new(0.0, 0.0);
    let nt = plans.len();
    let mut scratch = plans.scratch();
    // Spectra of the contact forces z_c.
    let spectra: Vec<Vec<c64>> = (0..m)
        .map(|c| {
            let mut s: Vec<c64> = (0..nt).map(|n| c64::new(z[n * m + c], 0.0)).collect();
            plans.forward(&mut s, &mut scratch);
            s
        })
        .collect();
    let mut buffer = vec![zero; nt];
    rows.iter()
        .map(|&r| {
            for (k, out) in buffer.iter_mut().enumerate() {
                let (bin, conj) = if 2 * k > nt {
                    (nt - k, true)
                } else {
                    (k, false)
                };
                let mut sum = zero;
                for (c, s) in spectra.iter().enumerate() {
                    let t = transfer[(bin * rows_total + r) * m + c];
                    sum += if conj { t.conj() } else { t } * s[k];
                }
                *out = sum;
            }
            plans.inverse(&mut buffer, &mut scratch);
            (0..nt)
                .map(|n| {
                    let phase = 2.0 * std::f64::consts::PI * n as f64 / nt as f64;
                    let linear = (linear_amplitude[r] * c64::new(phase.cos(), phase.sin())).re;
                    linear - buffer[n].re / nt as f64
                })
                .collect()
        })
        .collect()
}

impl PeriodicLcp {
    /// `d(q + A z)/domega` at fixed `z` into `out` (time-major, length `m Nt`): the
    /// derivative of the gap `w = q + A z` along the frequency. `A z` is applied by FFT with
    /// the bin derivatives `dH_k/domega`, `dq_n/domega = -Re(dX/domega e^{2 pi i n/Nt})`.
    /// Needs an LCP built by [`PeriodicLcp::with_frequency_derivative`].
    pub fn frequency_derivative(&self, z: &[f64], out: &mut [f64]) -> Result<(), LcpError> {
        self.check_z(z)?;
        if out.len() != self.dim() {
            return Err(LcpError::WrongLength {
                what: "out",
                expected: self.dim(),
                found: out.len(),
            });
        }
        let d = self
            .derivative
            .as_ref()
            .ok_or(LcpError::NoFrequencyDerivative)?;
        let m = self.contacts;
        let rows: Vec<usize> = (0..m).collect();
        // `w = g - u_c` along the contact rows: dw/domega = -(du_c/domega).
        let du = kernel_response(
            &self.plans,
            m,
            &d.transfer,
            m,
            &d.linear_amplitude,
            z,
            &rows,
        );
        for (c, history) in du.iter().enumerate() {
            for (n, v) in history.iter().enumerate() {
                out[n * m + c] = -v;
            }
        }
        Ok(())
    }

    /// Number of time steps per period `Nt`.
    pub fn time_samples(&self) -> usize {
        self.nt
    }

    /// Number of contacts `m`.
    pub fn contact_count(&self) -> usize {
        self.contacts
    }

    /// Size of the LCP, `m Nt`.
    pub fn dim(&self) -> usize {
        self.contacts * self.nt
    }

    /// Forcing angular frequency `omega` (the period is `2 pi / omega`).
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// The time nodes `t_n = n T / Nt`, `n = 0..Nt`.
    pub fn times(&self) -> Vec<f64> {
        let dt = self.time_step();
        (0..self.nt).map(|n| n as f64 * dt).collect()
    }

    /// Time step `dt = T / Nt`.
    pub fn time_step(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.omega / self.nt as f64
    }

    /// The warped angular frequency of bin `k`: `(2/dt) tan(pi k / Nt)` for the trapezoidal
    /// rule (infinite at the Nyquist bin `k = Nt/2`), `Im s_k` for BDF2.
    pub fn bin_frequency(&self, k: usize) -> f64 {
        build::bin_symbol(self.scheme, self.nt, self.time_step(), k).map_or(f64::INFINITY, |s| s.im)
    }

    /// The time discretisation.
    pub fn scheme(&self) -> LcpScheme {
        self.scheme
    }

    /// Whether the alternating force `(-1)^n` (on every contact) is a null vector of `A`:
    /// the trapezoidal rule at even `Nt` when the Nyquist receptance is exactly 0, i.e.
    /// every contact dof has mass or damping (module documentation, *Nyquist bin*).
    pub fn has_alternating_null_vector(&self) -> bool {
        self.scheme == LcpScheme::Trapezoidal
            && self.nt % 2 == 0
            && self
                .receptance(self.nt / 2)
                .iter()
                .all(|h| h.re == 0.0 && h.im == 0.0)
    }

    /// The contact gaps `g`, in contact order.
    pub fn gaps(&self) -> &[f64] {
        &self.gaps
    }

    /// The contact dofs, in contact order.
    pub fn contact_dofs(&self) -> &[usize] {
        &self.contact_dofs
    }

    /// The observed dofs given in the options.
    pub fn observed_dofs(&self) -> &[usize] {
        &self.observed_dofs
    }

    /// Number of dofs with neither mass nor damping (the set whose static receptance is
    /// the Nyquist-bin limit).
    pub fn static_dof_count(&self) -> usize {
        self.static_dofs
    }

    /// The LCP matrix `A` (`m Nt` square, time-major: index `n m + c`).
    pub fn matrix(&self) -> MatRef<'_, f64> {
        self.matrix.as_ref()
    }

    /// The LCP vector `q = g - u_lin` at the nodes (time-major).
    pub fn q(&self) -> &[f64] {
        &self.q
    }

    /// The receptance `H_k = G Z_k^{-1} G^T` of bin `k` (`m x m`, row-major; bins above
    /// `Nt/2` by conjugate symmetry). These are the eigenvalue blocks of `A`.
    pub fn receptance(&self, k: usize) -> Vec<c64> {
        let k = k % self.nt;
        let (bin, conj) = if 2 * k > self.nt {
            (self.nt - k, true)
        } else {
            (k, false)
        };
        let m = self.contacts;
        let nr = self.rows();
        (0..m * m)
            .map(|i| {
                let v = self.transfer[(bin * nr + i / m) * m + i % m];
                if conj {
                    v.conj()
                } else {
                    v
                }
            })
            .collect()
    }

    /// Smallest and largest eigenvalue of the symmetric part `(A + A^T)/2`, from the
    /// Hermitian parts of the bin receptances (exact, no dense eigensolver). A negative
    /// minimum means `A` is not positive semi-definite, so Lemke's method may end on a ray.
    pub fn symmetric_part_spectrum(&self) -> (f64, f64) {
        self.symmetric_spectrum
    }

    fn rows(&self) -> usize {
        self.contacts + self.observed_dofs.len()
    }

    fn check_z(&self, z: &[f64]) -> Result<(), LcpError> {
        if z.len() != self.dim() {
            return Err(LcpError::WrongLength {
                what: "z",
                expected: self.dim(),
                found: z.len(),
            });
        }
        Ok(())
    }

    /// The gap `w = q + A z` at the nodes (time-major).
    pub fn gap(&self, z: &[f64]) -> Result<Vec<f64>, LcpError> {
        self.check_z(z)?;
        let mut w = self.q.clone();
        min_map::add_mat_vec(self.matrix.as_ref(), z, &mut w);
        Ok(w)
    }

    /// Contact displacements `G u = g - w` at the nodes, one series of length `Nt` per
    /// contact, for the compressive contact forces `z` (time-major, length `m Nt`).
    pub fn contact_displacements(&self, z: &[f64]) -> Result<Vec<Vec<f64>>, LcpError> {
        let w = self.gap(z)?;
        let m = self.contacts;
        Ok((0..m)
            .map(|c| (0..self.nt).map(|n| self.gaps[c] - w[n * m + c]).collect())
            .collect())
    }

    /// Contact forces `lambda = -z` at the nodes, one series of length `Nt` per contact.
    pub fn contact_forces(&self, z: &[f64]) -> Result<Vec<Vec<f64>>, LcpError> {
        self.check_z(z)?;
        let m = self.contacts;
        Ok((0..m)
            .map(|c| (0..self.nt).map(|n| -z[n * m + c]).collect())
            .collect())
    }

    /// Displacements of the observed dofs at the nodes for the contact forces `z`, one
    /// series of length `Nt` per observed dof (options order), by FFT:
    /// `U_k = X_k - sum_c (Z_k^{-1} G^T)[dof, c] Zhat_{c,k}`.
    pub fn displacements(&self, z: &[f64]) -> Result<Vec<Vec<f64>>, LcpError> {
        self.check_z(z)?;
        let rows: Vec<usize> = (self.contacts..self.rows()).collect();
        Ok(self.response_rows(z, &rows))
    }

    /// The same as [`PeriodicLcp::displacements`] for the contact dofs, through the FFT
    /// route (an independent check of `g - q - A z`).
    pub fn contact_displacements_by_fft(&self, z: &[f64]) -> Result<Vec<Vec<f64>>, LcpError> {
        self.check_z(z)?;
        let rows: Vec<usize> = (0..self.contacts).collect();
        Ok(self.response_rows(z, &rows))
    }

    fn response_rows(&self, z: &[f64], rows: &[usize]) -> Vec<Vec<f64>> {
        kernel_response(
            &self.plans,
            self.contacts,
            &self.transfer,
            self.rows(),
            &self.linear_amplitude,
            z,
            rows,
        )
    }

    /// Solves the LCP by Lemke's method (method `"lcp-lemke"`), reusing the workspace
    /// `lemke` (resized once if its size differs from [`PeriodicLcp::dim`]).
    ///
    /// `Ok` whenever Lemke ran, whatever its termination (solved, ray, pivot limit); pass
    /// the report to [`PeriodicLcp::check_lemke`] to turn a ray or pivot limit into an
    /// [`LcpError::LemkeNotSolved`] carrying the pivots and the smallest eigenvalue of the
    /// symmetric part of `A`.
    pub fn solve_with_lemke(
        &self,
        lemke: &mut Lemke,
        options: &LemkeOptions,
    ) -> Result<LemkeReport, LemkeError> {
        lemke.solve(self.matrix.as_ref(), &self.q, options)
    }

    /// `Ok(report)` when Lemke solved the LCP, otherwise [`LcpError::LemkeNotSolved`]
    /// with the numbers (termination, pivots, complementarity error, smallest eigenvalue
    /// of `(A + A^T)/2`).
    pub fn check_lemke(&self, report: LemkeReport) -> Result<LemkeReport, LcpError> {
        if report.solved() {
            return Ok(report);
        }
        Err(LcpError::LemkeNotSolved {
            termination: report.termination,
            pivots: report.pivots,
            complementarity_error: report.complementarity_error,
            symmetric_part_min_eigenvalue: self.symmetric_spectrum.0,
        })
    }

    /// The semismooth equation `min(z, q + A z) = 0` of this LCP (method `"lcp-ssn"`).
    pub fn min_map(&self) -> MinMapLcp<'_> {
        MinMapLcp::of_lcp(self.matrix.as_ref(), &self.q)
    }
}
