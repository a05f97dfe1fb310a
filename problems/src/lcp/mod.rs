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
//!
//! # Measured on the canonical rod (20 elements, `zeta = 0.01`, `omega = omega_1`, gap 0.5)
//!
//! Modified mass (massless tip): Lemke solves at every `Nt` (61 / 172 / 529 / 1894 / 7118
//! pivots at `Nt` = 128 / 256 / 512 / 1024 / 2048, 0.37 s of CPU at 2048), tip minimum
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
//! use semismooth_problems::lcp::{PeriodicLcp, PeriodicLcpOptions};
//! use semismooth_problems::rod::{build_rod, MassModel, RodSpec};
//! let mut spec = RodSpec::canonical();
//! spec.mass = MassModel::Modified;
//! let rod = build_rod(&spec).unwrap();
//! let options = PeriodicLcpOptions { time_samples: 128, ..Default::default() };
//! let lcp = PeriodicLcp::new(&rod.model, options).unwrap();
//! let mut lemke = Lemke::new(lcp.dim());
//! let report = lcp.solve_with_lemke(&mut lemke, &LemkeOptions::default()).unwrap();
//! let report = lcp.check_lemke(report).unwrap(); // a ray or pivot limit would be an Err
//! let tip = &lcp.contact_displacements(&report.z).unwrap()[0];
//! let lowest = tip.iter().cloned().fold(f64::INFINITY, f64::min);
//! let highest = tip.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
//! assert!((lowest + 0.5234851).abs() < 1e-6);
//! assert!((highest - 0.5).abs() < 1e-12); // the tip reaches the obstacle
//! ```

mod dft;
mod frequency;
mod min_map;

pub use frequency::{FrequencyLcp, FrequencyLcpJacobian, FrequencyLcpSolver};
pub use min_map::{ActiveSetSolver, MinMapJacobian, MinMapLcp};

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, Triplet};
use faer::{c64, Mat, MatRef};
use semismooth::lemke::{Lemke, LemkeError, LemkeOptions, LemkeReport, LemkeTermination};
use semismooth::newton::{self, NewtonError, NewtonOptions, NewtonReport};

use crate::model::{InvalidModel, SparseMatrix, StructuralModel};
use dft::Dft;

/// Default number of time steps per period `Nt` of the periodic LCP.
pub const DEFAULT_LCP_TIME_SAMPLES: usize = 256;
/// Smallest accepted `Nt`.
pub const MIN_LCP_TIME_SAMPLES: usize = 8;
/// Largest accepted LCP size `contacts * Nt` (the dense matrix holds its square: 512 MB).
pub const MAX_LCP_SIZE: usize = 8192;

/// Relative residual `|Z x - b| / (|Z| |x| + |b|)` above which a bin solve is rejected
/// (a forcing-free resonance: `Z_k` numerically singular).
const BIN_RESIDUAL_TOLERANCE: f64 = 1e-8;

/// Options of [`PeriodicLcp::new`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PeriodicLcpOptions {
    /// Number of time steps per period `Nt` (default [`DEFAULT_LCP_TIME_SAMPLES`]);
    /// `Nt >= 8` and `contacts * Nt <= MAX_LCP_SIZE`. Powers of two use a radix-2 FFT.
    pub time_samples: usize,
    /// Degrees of freedom whose displacement history [`PeriodicLcp::displacements`]
    /// returns (default none; the contact dofs are always available through
    /// [`PeriodicLcp::contact_displacements`]).
    pub observed_dofs: Vec<usize>,
}

impl Default for PeriodicLcpOptions {
    fn default() -> Self {
        Self {
            time_samples: DEFAULT_LCP_TIME_SAMPLES,
            observed_dofs: Vec::new(),
        }
    }
}

impl PeriodicLcpOptions {
    /// Checks `time_samples` for a model with `contacts` contacts and `dofs` dofs, and the
    /// observed dofs.
    pub fn validate(&self, contacts: usize, dofs: usize) -> Result<(), LcpError> {
        let nt = self.time_samples;
        if nt < MIN_LCP_TIME_SAMPLES || contacts.saturating_mul(nt) > MAX_LCP_SIZE {
            return Err(LcpError::InvalidOption {
                name: "time_samples",
                value: nt as f64,
                allowed: "an integer >= 8 with contacts * time_samples <= 8192",
            });
        }
        if let Some(&dof) = self.observed_dofs.iter().find(|&&d| d >= dofs) {
            return Err(LcpError::ObservedDofOutOfRange { dof, dofs });
        }
        Ok(())
    }
}

/// Why a periodic LCP could not be built, or a result could not be produced.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LcpError {
    /// An option is out of range.
    #[error("invalid option {name} = {value}: allowed {allowed}")]
    InvalidOption {
        /// Which option.
        name: &'static str,
        /// The value received.
        value: f64,
        /// What is allowed.
        allowed: &'static str,
    },
    /// The model has no contact: there is no complementarity problem.
    #[error("the model has no contact: the periodic LCP needs at least one")]
    NoContacts,
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
    /// An observed dof does not exist.
    #[error("observed dof {dof} is out of range: the model has {dofs} dofs")]
    ObservedDofOutOfRange {
        /// The dof requested.
        dof: usize,
        /// Number of dofs.
        dofs: usize,
    },
    /// The sparse factorization of a dynamic stiffness failed.
    #[error("factorization of the dynamic stiffness of bin {bin} failed: {reason}")]
    Factorization {
        /// DFT bin (`Nt/2` is the Nyquist limit problem).
        bin: usize,
        /// Backend's description.
        reason: String,
    },
    /// `Z_k` is numerically singular (a warped bin frequency on a natural frequency of an
    /// undamped model).
    #[error(
        "dynamic stiffness of bin {bin} (warped frequency {frequency}) is singular: \
         relative residual {relative_residual:e}"
    )]
    SingularBin {
        /// DFT bin.
        bin: usize,
        /// Warped angular frequency `(2/dt) tan(pi k / Nt)`.
        frequency: f64,
        /// Relative residual of the solve.
        relative_residual: f64,
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
    nt: usize,
    m: usize,
    transfer: &[c64],
    rows_total: usize,
    linear_amplitude: &[c64],
    z: &[f64],
    rows: &[usize],
) -> Vec<Vec<f64>> {
    let zero = c64::new(0.0, 0.0);
    let mut plan = Dft::new(nt);
    // Spectra of the contact forces z_c.
    let spectra: Vec<Vec<c64>> = (0..m)
        .map(|c| {
            let mut s: Vec<c64> = (0..nt).map(|n| c64::new(z[n * m + c], 0.0)).collect();
            plan.forward(&mut s);
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
            plan.backward(&mut buffer);
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

/// Column-compressed union pattern of `K`, `M`, `D` with, for each source matrix, the
/// position of each of its stored entries in the union.
struct UnionPattern {
    pattern: SparseColMat<usize, c64>,
    stiffness: Vec<usize>,
    mass: Vec<usize>,
    damping: Vec<usize>,
}

fn union_pattern(model: &StructuralModel) -> Result<UnionPattern, LcpError> {
    let n = model.dofs();
    let mut triplets = Vec::new();
    let mut sources: Vec<&SparseMatrix> = vec![&model.stiffness, &model.mass];
    if let Some(d) = &model.damping {
        sources.push(d);
    }
    for m in &sources {
        let r = m.as_ref();
        for j in 0..n {
            for i in r.row_idx_of_col(j) {
                triplets.push(Triplet::new(i, j, c64::new(0.0, 0.0)));
            }
        }
    }
    // The diagonal is always present so that the symbolic LU can pivot on it.
    for j in 0..n {
        triplets.push(Triplet::new(j, j, c64::new(0.0, 0.0)));
    }
    let pattern =
        SparseColMat::<usize, c64>::try_new_from_triplets(n, n, &triplets).map_err(|e| {
            LcpError::Factorization {
                bin: 0,
                reason: format!("pattern assembly failed: {e:?}"),
            }
        })?;
    let positions = |m: &SparseMatrix| -> Vec<usize> {
        let symbolic = pattern.symbolic();
        let rows = symbolic.row_idx();
        let r = m.as_ref();
        let mut out = Vec::with_capacity(r.compute_nnz());
        for j in 0..n {
            let range = symbolic.col_range(j);
            let col_rows = &rows[range.clone()];
            for i in r.row_idx_of_col(j) {
                let offset = col_rows
                    .binary_search(&i)
                    .expect("every entry is in the union pattern");
                out.push(range.start + offset);
            }
        }
        out
    };
    let stiffness = positions(&model.stiffness);
    let mass = positions(&model.mass);
    let damping = model.damping.as_ref().map(positions).unwrap_or_default();
    Ok(UnionPattern {
        pattern,
        stiffness,
        mass,
        damping,
    })
}

/// `true` when column `j` of `m` has no non-zero entry.
fn column_is_zero(m: &SparseMatrix, j: usize) -> bool {
    m.as_ref().val_of_col(j).iter().all(|v| *v == 0.0)
}

impl PeriodicLcp {
    /// Builds `A` and `q` for `model` with `options.time_samples` steps per period.
    ///
    /// Cost: `Nt/2 + 1` sparse complex LU factorizations of size `N` (one symbolic
    /// analysis), `m` solves each, and `m^2` FFTs of length `Nt` for the kernel.
    pub fn new(model: &StructuralModel, options: PeriodicLcpOptions) -> Result<Self, LcpError> {
        Self::build(model, options, false)
    }

    /// [`PeriodicLcp::new`] that also computes the derivatives with respect to `omega` of
    /// `q` and `A` ([`PeriodicLcp::frequency_derivative`]). The Tustin frequency
    /// `sigma_k = omega tau_k`, `tau_k = (Nt/pi) tan(pi k/Nt)`, is linear in `omega`, so
    /// `dZ_k/domega = i tau_k D - 2 omega tau_k^2 M` and
    /// `dZ_k^{-1}/domega = -Z_k^{-1} (dZ_k/domega) Z_k^{-1}`: one more solve per bin and
    /// column with the same LU (the Nyquist limit does not depend on `omega`).
    pub fn with_frequency_derivative(
        model: &StructuralModel,
        options: PeriodicLcpOptions,
    ) -> Result<Self, LcpError> {
        Self::build(model, options, true)
    }

    fn build(
        model: &StructuralModel,
        options: PeriodicLcpOptions,
        with_derivative: bool,
    ) -> Result<Self, LcpError> {
        model.validate()?;
        if model.contacts.is_empty() {
            return Err(LcpError::NoContacts);
        }
        let n = model.dofs();
        let m = model.contact_count();
        options.validate(m, n)?;
        let nt = options.time_samples;
        let omega = model.forcing.omega;
        let dt = 2.0 * std::f64::consts::PI / omega / nt as f64;
        let contact_dofs: Vec<usize> = model.contacts.iter().map(|c| c.dof).collect();
        let gaps: Vec<f64> = model.contacts.iter().map(|c| c.gap).collect();
        let rows: Vec<usize> = contact_dofs
            .iter()
            .chain(&options.observed_dofs)
            .copied()
            .collect();
        let nr = rows.len();
        let bins = nt / 2 + 1;
        let zero = c64::new(0.0, 0.0);
        let mut transfer = vec![zero; bins * nr * m];
        let mut linear_amplitude = vec![zero; nr];
        let mut derivative = with_derivative.then(|| FrequencyDerivative {
            transfer: vec![zero; bins * m * m],
            linear_amplitude: vec![zero; m],
        });

        let mut union = union_pattern(model)?;
        let symbolic =
            SymbolicLu::try_new(union.pattern.symbolic()).map_err(|e| LcpError::Factorization {
                bin: 0,
                reason: format!("symbolic analysis failed: {e:?}"),
            })?;
        let stiffness_max = model
            .stiffness
            .val()
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()));
        for k in 0..bins {
            if 2 * k == nt {
                continue; // Nyquist: the limit problem below.
            }
            let sigma = bin_frequency(nt, dt, k);
            let values = union.pattern.val_mut();
            values.fill(zero);
            for (p, v) in union.stiffness.iter().zip(model.stiffness.val()) {
                values[*p] += c64::new(*v, 0.0);
            }
            for (p, v) in union.mass.iter().zip(model.mass.val()) {
                values[*p] += c64::new(-sigma * sigma * v, 0.0);
            }
            if let Some(d) = &model.damping {
                for (p, v) in union.damping.iter().zip(d.val()) {
                    values[*p] += c64::new(0.0, sigma * v);
                }
            }
            let lu = Lu::try_new_with_symbolic(symbolic.clone(), union.pattern.as_ref()).map_err(
                |e| LcpError::Factorization {
                    bin: k,
                    reason: format!("{e:?}"),
                },
            )?;
            let with_forcing = k == 1;
            let ncols = m + usize::from(with_forcing);
            let mut rhs = Mat::<c64>::zeros(n, ncols);
            for (c, &dof) in contact_dofs.iter().enumerate() {
                rhs[(dof, c)] = c64::new(1.0, 0.0);
            }
            if with_forcing {
                for (i, a) in model.forcing.amplitude.iter().enumerate() {
                    rhs[(i, m)] = c64::new(*a, 0.0);
                }
            }
            let b = rhs.clone();
            lu.solve_in_place(rhs.as_mut());
            let relative_residual = bin_residual(&union.pattern, &rhs, &b, stiffness_max);
            if relative_residual.is_nan() || relative_residual > BIN_RESIDUAL_TOLERANCE {
                return Err(LcpError::SingularBin {
                    bin: k,
                    frequency: sigma,
                    relative_residual,
                });
            }
            for (r, &dof) in rows.iter().enumerate() {
                for c in 0..m {
                    transfer[(k * nr + r) * m + c] = rhs[(dof, c)];
                }
                if with_forcing {
                    linear_amplitude[r] = rhs[(dof, m)];
                }
            }
            if let Some(d) = derivative.as_mut() {
                // Y = Z_k^{-1} (dZ_k/domega) X, X = Z_k^{-1} [G^T, f]; dX/domega = -Y.
                let tau = sigma / omega;
                let mut y = Mat::<c64>::zeros(n, ncols);
                let mut apply = |matrix: &SparseMatrix, coefficient: c64| {
                    let a = matrix.as_ref();
                    for j in 0..n {
                        for (i, v) in a.row_idx_of_col(j).zip(a.val_of_col(j)) {
                            let f = coefficient * *v;
                            for col in 0..ncols {
                                y[(i, col)] += f * rhs[(j, col)];
                            }
                        }
                    }
                };
                apply(&model.mass, c64::new(-2.0 * omega * tau * tau, 0.0));
                if let Some(damping) = &model.damping {
                    apply(damping, c64::new(0.0, tau));
                }
                lu.solve_in_place(y.as_mut());
                for (r, &dof) in contact_dofs.iter().enumerate() {
                    for c in 0..m {
                        d.transfer[(k * m + r) * m + c] = -y[(dof, c)];
                    }
                    if with_forcing {
                        d.linear_amplitude[r] = -y[(dof, m)];
                    }
                }
            }
        }

        // Nyquist limit: static receptance of the dofs with neither mass nor damping.
        let static_set: Vec<usize> = (0..n)
            .filter(|&j| {
                column_is_zero(&model.mass, j)
                    && model.damping.as_ref().is_none_or(|d| column_is_zero(d, j))
            })
            .collect();
        if nt % 2 == 0 && !static_set.is_empty() {
            let k = nt / 2;
            let columns = nyquist_static_receptance(model, &static_set, &contact_dofs, k)?;
            for (r, &dof) in rows.iter().enumerate() {
                if let Ok(v) = static_set.binary_search(&dof) {
                    for c in 0..m {
                        transfer[(k * nr + r) * m + c] = c64::new(columns[(v, c)], 0.0);
                    }
                }
            }
        }

        // Kernel a_p = (1/Nt) sum_k H_k e^{2 pi i k p / Nt} for every contact pair, by FFT.
        let mut plan = Dft::new(nt);
        let mut spectrum = vec![zero; nt];
        let mut kernel = vec![0.0; nt * m * m];
        for c in 0..m {
            for c2 in 0..m {
                fill_spectrum(&mut spectrum, |k| transfer[(k * nr + c) * m + c2]);
                plan.backward(&mut spectrum);
                for (p, v) in spectrum.iter().enumerate() {
                    kernel[(p * m + c) * m + c2] = v.re / nt as f64;
                }
            }
        }
        let size = m * nt;
        // A[(ni, ci), (nj, cj)] = a_{ni - nj}[ci, cj]: column (nj, cj) is the column cj of
        // the kernel blocks, rotated down by nj nodes (filled by contiguous copies).
        let mut matrix = Mat::<f64>::zeros(size, size);
        let mut column0 = vec![0.0; size];
        for cj in 0..m {
            for p in 0..nt {
                for ci in 0..m {
                    column0[p * m + ci] = kernel[(p * m + ci) * m + cj];
                }
            }
            for nj in 0..nt {
                let shift = nj * m;
                let col = matrix.col_mut(nj * m + cj).try_as_col_major_mut();
                let col = col
                    .expect("a freshly allocated Mat is column-major")
                    .as_slice_mut();
                col[shift..].copy_from_slice(&column0[..size - shift]);
                col[..shift].copy_from_slice(&column0[size - shift..]);
            }
        }
        let mut q = vec![0.0; size];
        for node in 0..nt {
            let phase = 2.0 * std::f64::consts::PI * node as f64 / nt as f64;
            let e = c64::new(phase.cos(), phase.sin());
            for c in 0..m {
                q[node * m + c] = gaps[c] - (linear_amplitude[c] * e).re;
            }
        }
        let symmetric_spectrum = hermitian_part_range(&transfer, bins, nr, m);
        Ok(Self {
            nt,
            contacts: m,
            omega,
            gaps,
            contact_dofs,
            observed_dofs: options.observed_dofs,
            matrix,
            q,
            transfer,
            linear_amplitude,
            symmetric_spectrum,
            static_dofs: static_set.len(),
            derivative,
        })
    }

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
        let du = kernel_response(self.nt, m, &d.transfer, m, &d.linear_amplitude, z, &rows);
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

    /// The warped angular frequency of bin `k`, `(2/dt) tan(pi k / Nt)` (infinite at the
    /// Nyquist bin `k = Nt/2`).
    pub fn bin_frequency(&self, k: usize) -> f64 {
        bin_frequency(self.nt, self.time_step(), k)
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
            self.nt,
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

    /// Periodic linear interpolation of a contact-force history `z_other` of another
    /// discretisation (time-major, `m Nt'` entries for any `Nt' >= 1`) onto this LCP's
    /// nodes: a warm start for semismooth Newton (mesh sequencing). On the canonical rod
    /// with the modified mass, Newton from `z = 0` needs 13 / 64 / 126 / 282 iterations at
    /// `Nt` = 128 / 256 / 512 / 1024 (the active set creeps), from the interpolated coarser
    /// solution 5 to 8 up to `Nt = 1024`.
    pub fn interpolate_forces(&self, z_other: &[f64]) -> Result<Vec<f64>, LcpError> {
        let m = self.contacts;
        if z_other.is_empty() || z_other.len() % m != 0 {
            return Err(LcpError::WrongLength {
                what: "z_other (a positive multiple of the contact count)",
                expected: self.dim(),
                found: z_other.len(),
            });
        }
        let other = z_other.len() / m;
        let mut z = vec![0.0; self.dim()];
        for n in 0..self.nt {
            let position = n as f64 * other as f64 / self.nt as f64;
            let left = (position.floor() as usize).min(other - 1);
            let fraction = position - left as f64;
            let right = (left + 1) % other;
            for c in 0..m {
                z[n * m + c] =
                    (1.0 - fraction) * z_other[left * m + c] + fraction * z_other[right * m + c];
            }
        }
        Ok(z)
    }

    /// The semismooth equation `min(z, q + A z) = 0` of this LCP (method `"lcp-ssn"`).
    pub fn min_map(&self) -> MinMapLcp<'_> {
        MinMapLcp::new(self.matrix.as_ref(), &self.q).expect("A and q have matching sizes")
    }
}

/// Coarsest `Nt` of [`solve_min_map_sequenced`]'s level sequence.
pub const SEQUENCING_COARSEST_TIME_SAMPLES: usize = 128;

/// One level of [`solve_min_map_sequenced`].
#[derive(Debug, Clone, PartialEq)]
pub struct SequencingLevel {
    /// `Nt` of the level.
    pub time_samples: usize,
    /// The Newton run on that level.
    pub report: NewtonReport,
}

/// Result of [`solve_min_map_sequenced`]: the finest LCP, its solution and every level.
#[derive(Debug, Clone)]
pub struct SequencedSolution {
    /// The LCP at the requested `Nt`.
    pub lcp: PeriodicLcp,
    /// Best iterate on the finest level (the solution when its report converged).
    pub z: Vec<f64>,
    /// Levels from coarsest to finest; the last one is the requested `Nt`.
    pub levels: Vec<SequencingLevel>,
}

impl SequencedSolution {
    /// `true` when Newton converged on the finest level.
    pub fn converged(&self) -> bool {
        self.levels.last().is_some_and(|l| l.report.converged())
    }

    /// Newton iterations summed over the levels.
    pub fn total_iterations(&self) -> usize {
        self.levels.iter().map(|l| l.report.iterations).sum()
    }
}

/// Semismooth Newton on `min(z, q + A z) = 0` by mesh sequencing (method `"lcp-ssn"`
/// at large `Nt`): the LCP is solved at `Nt / 2^j` (halving while even and not below
/// [`SEQUENCING_COARSEST_TIME_SAMPLES`]) from `z = 0`, then each finer level starts from
/// the previous solution interpolated in time ([`PeriodicLcp::interpolate_forces`]), with
/// the [`ActiveSetSolver`]. A level that does not converge still passes its best iterate
/// on; `Ok` whenever every level ran (check [`SequencedSolution::converged`]).
///
/// Why: with a damped massless contact node the high-frequency receptances tend to 0, so
/// `A` is ill-conditioned and from `z = 0` the active set creeps one node at a time (on
/// the canonical rod with the modified mass: 13 / 64 / 126 / 282 iterations at
/// `Nt = 128 .. 1024` with the default non-monotone line search, no convergence in 300 at
/// 2048); from the interpolated coarser solution 5 / 7 / 8 / 42 iterations.
pub fn solve_min_map_sequenced(
    model: &StructuralModel,
    options: PeriodicLcpOptions,
    newton_options: &NewtonOptions,
) -> Result<SequencedSolution, LcpError> {
    newton_options.validate()?;
    options.validate(model.contact_count(), model.dofs())?;
    let mut sizes = vec![options.time_samples];
    while let Some(&nt) = sizes.last() {
        if nt % 2 != 0 || nt / 2 < SEQUENCING_COARSEST_TIME_SAMPLES.max(MIN_LCP_TIME_SAMPLES) {
            break;
        }
        sizes.push(nt / 2);
    }
    sizes.reverse();
    let mut levels = Vec::with_capacity(sizes.len());
    let mut previous: Option<Vec<f64>> = None;
    let mut finest = None;
    for (index, &nt) in sizes.iter().enumerate() {
        let last = index + 1 == sizes.len();
        let level_options = PeriodicLcpOptions {
            time_samples: nt,
            observed_dofs: if last {
                options.observed_dofs.clone()
            } else {
                Vec::new()
            },
        };
        let lcp = PeriodicLcp::new(model, level_options)?;
        let mut z = match &previous {
            Some(coarse) => lcp.interpolate_forces(coarse)?,
            None => vec![0.0; lcp.dim()],
        };
        let report = {
            let mut problem = lcp.min_map();
            let mut solver = ActiveSetSolver::new();
            newton::solve(&mut problem, &mut solver, &mut z, newton_options)
                .or_else(NewtonError::into_report)?
        };
        levels.push(SequencingLevel {
            time_samples: nt,
            report,
        });
        if last {
            finest = Some(lcp);
        }
        previous = Some(z);
    }
    Ok(SequencedSolution {
        lcp: finest.expect("at least one level"),
        z: previous.expect("at least one level"),
        levels,
    })
}

/// `(2/dt) tan(pi k / Nt)`, infinite at the Nyquist bin.
fn bin_frequency(nt: usize, dt: f64, k: usize) -> f64 {
    if 2 * k == nt {
        return f64::INFINITY;
    }
    2.0 / dt * (std::f64::consts::PI * k as f64 / nt as f64).tan()
}

/// Fills a length-`Nt` spectrum from bins `0..=Nt/2` by conjugate symmetry.
fn fill_spectrum(spectrum: &mut [c64], bin: impl Fn(usize) -> c64) {
    let nt = spectrum.len();
    for (k, s) in spectrum.iter_mut().enumerate() {
        *s = if 2 * k > nt {
            bin(nt - k).conj()
        } else {
            bin(k)
        };
    }
    // Bin 0 (and Nyquist) of a real sequence are real.
    spectrum[0].im = 0.0;
    if nt % 2 == 0 {
        spectrum[nt / 2].im = 0.0;
    }
}

/// `max |Z x - b| / (|K|_max |x|_max + |b|_max)` over all columns (Z in the union pattern).
fn bin_residual(z: &SparseColMat<usize, c64>, x: &Mat<c64>, b: &Mat<c64>, scale: f64) -> f64 {
    let n = z.nrows();
    let zr = z.as_ref();
    // Largest moduli through squared moduli (one square root each, no hypot per entry).
    let max_norm =
        |it: &mut dyn Iterator<Item = c64>| it.fold(0.0f64, |a, v| a.max(v.norm_sqr())).sqrt();
    let z_max = scale.max(max_norm(&mut z.val().iter().copied()));
    let mut worst = 0.0f64;
    for col in 0..x.ncols() {
        let mut r: Vec<c64> = (0..n).map(|i| -b[(i, col)]).collect();
        for j in 0..n {
            let xj = x[(j, col)];
            for (i, v) in zr.row_idx_of_col(j).zip(zr.val_of_col(j)) {
                r[i] += *v * xj;
            }
        }
        let x_max = max_norm(&mut (0..n).map(|i| x[(i, col)]));
        let b_max = max_norm(&mut (0..n).map(|i| b[(i, col)]));
        let r_max = max_norm(&mut r.iter().copied());
        let denominator = z_max * x_max + b_max;
        let rel = if denominator > 0.0 {
            r_max / denominator
        } else {
            0.0
        };
        if !rel.is_finite() || !x_max.is_finite() {
            return f64::INFINITY;
        }
        worst = worst.max(rel);
    }
    worst
}

/// `K_VV^{-1}` applied to the contact columns restricted to `V` (columns of contacts
/// outside `V` are zero), as a dense `|V| x m` matrix.
fn nyquist_static_receptance(
    model: &StructuralModel,
    static_set: &[usize],
    contact_dofs: &[usize],
    bin: usize,
) -> Result<Mat<f64>, LcpError> {
    let nv = static_set.len();
    let k = model.stiffness.as_ref();
    let mut triplets = Vec::new();
    for (jv, &j) in static_set.iter().enumerate() {
        for (i, v) in k.row_idx_of_col(j).zip(k.val_of_col(j)) {
            if let Ok(iv) = static_set.binary_search(&i) {
                triplets.push(Triplet::new(iv, jv, *v));
            }
        }
    }
    let kvv =
        SparseColMat::<usize, f64>::try_new_from_triplets(nv, nv, &triplets).map_err(|e| {
            LcpError::Factorization {
                bin,
                reason: format!("Nyquist static block assembly: {e:?}"),
            }
        })?;
    let symbolic = SymbolicLu::try_new(kvv.symbolic()).map_err(|e| LcpError::Factorization {
        bin,
        reason: format!("Nyquist static block symbolic analysis: {e:?}"),
    })?;
    let lu =
        Lu::try_new_with_symbolic(symbolic, kvv.as_ref()).map_err(|e| LcpError::Factorization {
            bin,
            reason: format!("Nyquist static block: {e:?}"),
        })?;
    let mut rhs = Mat::<f64>::zeros(nv, contact_dofs.len());
    for (c, dof) in contact_dofs.iter().enumerate() {
        if let Ok(v) = static_set.binary_search(dof) {
            rhs[(v, c)] = 1.0;
        }
    }
    lu.solve_in_place(rhs.as_mut());
    if let Some((i, j)) = (0..nv)
        .flat_map(|i| (0..contact_dofs.len()).map(move |j| (i, j)))
        .find(|&(i, j)| !rhs[(i, j)].is_finite())
    {
        return Err(LcpError::Factorization {
            bin,
            reason: format!(
                "Nyquist static block is singular (entry ({i}, {j}) of its inverse is not finite)"
            ),
        });
    }
    Ok(rhs)
}

/// Range of the eigenvalues of the Hermitian parts `(H_k + H_k^*)/2` over all bins.
fn hermitian_part_range(transfer: &[c64], bins: usize, nr: usize, m: usize) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for k in 0..bins {
        let h = |i: usize, j: usize| transfer[(k * nr + i) * m + j];
        if m == 1 {
            let v = h(0, 0).re;
            lo = lo.min(v);
            hi = hi.max(v);
            continue;
        }
        // Real symmetric embedding [[Re S, -Im S], [Im S, Re S]] of the Hermitian
        // S = (H + H^*)/2: same eigenvalues, each twice.
        let s = |i: usize, j: usize| (h(i, j) + h(j, i).conj()) * 0.5;
        let e = nalgebra::DMatrix::from_fn(2 * m, 2 * m, |i, j| {
            let v = s(i % m, j % m);
            match (i < m, j < m) {
                (true, true) | (false, false) => v.re,
                (true, false) => -v.im,
                (false, true) => v.im,
            }
        });
        for v in nalgebra::SymmetricEigen::new(e).eigenvalues.iter() {
            lo = lo.min(*v);
            hi = hi.max(*v);
        }
    }
    (lo, hi)
}
