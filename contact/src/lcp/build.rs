//! Construction of the periodic LCP (module documentation of [`super`]): the bin
//! receptances `H_k = G Z_k^{-1} G^T` by one sparse complex LU per bin (one column
//! ordering for all bins), the Nyquist limit, the circulant kernel by FFT, `A` and `q`.

use faer::sparse::{SparseColMat, Triplet};
use faer::{c64, Mat};
use semismooth::linalg::{FaerSparseLu, LinearSolveError};
use semismooth::{Factorize, LinearSolve};

use super::{FftPlans, FrequencyDerivative, LcpError, LcpScheme, PeriodicLcp, PeriodicLcpOptions};
use crate::dynamic::DynamicStiffness;
use crate::model::{check_omega, ContactDirection, SparseMatrix, StructuralModel};

/// `true` when column `j` of `m` has no non-zero entry.
fn column_is_zero(m: &SparseMatrix, j: usize) -> bool {
    m.as_ref().val_of_col(j).iter().all(|v| *v == 0.0)
}

/// What the bins give: per bin `k = 0..=Nt/2` the transfer `(Z_k^{-1} G^T)[r, c]` on the
/// rows `r` (contact dofs, then observed dofs), the linear amplitude `X_r` of harmonic 1,
/// and the frequency derivatives when asked for.
struct Bins {
    transfer: Vec<c64>,
    linear_amplitude: Vec<c64>,
    derivative: Option<FrequencyDerivative>,
}

impl PeriodicLcp {
    /// Builds `A` and `q` for `model` forced at `omega` (finite, `> 0`:
    /// [`LcpError::InvalidOption`] otherwise) with `options.time_samples` steps per period.
    ///
    /// Cost: `Nt/2 + 1` sparse complex LU factorizations of size `N` (one column ordering),
    /// `m` solves each, and `m^2` FFTs of length `Nt` for the kernel. A dynamic stiffness
    /// whose LU breaks down (a zero pivot: a warped bin frequency on a natural frequency of
    /// an undamped model) is [`LcpError::SingularBin`].
    pub fn new(
        model: &StructuralModel,
        omega: f64,
        options: PeriodicLcpOptions,
    ) -> Result<Self, LcpError> {
        Self::build(model, omega, options, false)
    }

    /// [`PeriodicLcp::new`] that also computes the derivatives with respect to `omega` of
    /// `q` and `A` ([`PeriodicLcp::frequency_derivative`]). The Tustin frequency
    /// `sigma_k = omega tau_k`, `tau_k = (Nt/pi) tan(pi k/Nt)`, is linear in `omega`, so
    /// `dZ_k/domega = i tau_k D - 2 omega tau_k^2 M` and
    /// `dZ_k^{-1}/domega = -Z_k^{-1} (dZ_k/domega) Z_k^{-1}`: one more solve per bin and
    /// column with the same LU (the Nyquist limit does not depend on `omega`).
    pub fn with_frequency_derivative(
        model: &StructuralModel,
        omega: f64,
        options: PeriodicLcpOptions,
    ) -> Result<Self, LcpError> {
        Self::build(model, omega, options, true)
    }

    fn build(
        model: &StructuralModel,
        omega: f64,
        options: PeriodicLcpOptions,
        with_derivative: bool,
    ) -> Result<Self, LcpError> {
        model.validate()?;
        model.refuse_cyclic("the periodic LCP")?;
        check_omega(omega)?;
        if model.contacts.is_empty() {
            return Err(LcpError::NoContacts);
        }
        if model.has_friction() {
            return Err(LcpError::Friction {
                points: model.friction.len() + model.frictional_contacts.len(),
            });
        }
        for (contact, c) in model.contacts.iter().enumerate() {
            match c.direction() {
                Some(ContactDirection::Positive) => {}
                Some(ContactDirection::Negative) => {
                    return Err(LcpError::NegativeDirection {
                        contact,
                        dof: c.dof(),
                    })
                }
                None => {
                    return Err(LcpError::GeneralRow {
                        contact,
                        dof: c.dof(),
                    })
                }
            }
        }
        let n = model.dofs();
        let m = model.contact_count();
        options.validate(m, n)?;
        let nt = options.time_samples;
        let contact_dofs: Vec<usize> = model.contacts.iter().map(|c| c.dof()).collect();
        let gaps: Vec<f64> = model.contacts.iter().map(|c| c.gap).collect();
        let rows: Vec<usize> = contact_dofs
            .iter()
            .chain(&options.observed_dofs)
            .copied()
            .collect();
        let nr = rows.len();
        let bins = nt / 2 + 1;
        let Bins {
            mut transfer,
            linear_amplitude,
            derivative,
        } = bin_transfers(model, omega, nt, options.scheme, &rows, with_derivative)?;

        // Nyquist limit: static receptance of the dofs with neither mass nor damping.
        let static_set: Vec<usize> = (0..n)
            .filter(|&j| {
                column_is_zero(&model.mass, j)
                    && model.damping.as_ref().is_none_or(|d| column_is_zero(d, j))
            })
            .collect();
        if options.scheme == LcpScheme::Trapezoidal && nt % 2 == 0 && !static_set.is_empty() {
            let k = nt / 2;
            let nv = static_set.len();
            let columns = nyquist_static_receptance(model, &static_set, &contact_dofs, k)?;
            for (r, &dof) in rows.iter().enumerate() {
                if let Ok(v) = static_set.binary_search(&dof) {
                    for c in 0..m {
                        transfer[(k * nr + r) * m + c] = c64::new(columns[c * nv + v], 0.0);
                    }
                }
            }
        }

        let plans = FftPlans::new(nt);
        let matrix = circulant(&plans, &transfer, nr, m);
        let mut q = vec![0.0; m * nt];
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
            scheme: options.scheme,
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
            plans,
        })
    }
}

/// The transfers `Z_k^{-1} G^T` on `rows` for the bins `k = 0..=Nt/2` below Nyquist (the
/// Nyquist bin is left zero), the linear amplitude `Z_1^{-1} f` and, when asked, their
/// frequency derivatives.
fn bin_transfers(
    model: &StructuralModel,
    omega: f64,
    nt: usize,
    scheme: LcpScheme,
    rows: &[usize],
    with_derivative: bool,
) -> Result<Bins, LcpError> {
    let (n, m, nr) = (model.dofs(), model.contact_count(), rows.len());
    let load = lcp_load(model)?;
    let dt = 2.0 * std::f64::consts::PI / omega / nt as f64;
    let bins = nt / 2 + 1;
    let zero = c64::new(0.0, 0.0);
    let mut out = Bins {
        transfer: vec![zero; bins * nr * m],
        linear_amplitude: vec![zero; nr],
        derivative: with_derivative.then(|| FrequencyDerivative {
            transfer: vec![zero; bins * m * m],
            linear_amplitude: vec![zero; m],
        }),
    };
    let mut dynamic = DynamicStiffness::new(
        &model.stiffness,
        &model.mass,
        model.damping.as_ref(),
        1,
        m + 1,
    )
    .map_err(|source| LcpError::Factorization { bin: 0, source })?;
    // Columns: the contact unit vectors G^T, then the load (bin 1 only).
    let mut x = Mat::<c64>::zeros(n, m + 1);
    let mut y = Mat::<c64>::zeros(n, m + 1);
    let mut values = Vec::new();
    for k in 0..bins {
        // The symbol s_k of d/dt; Z_k = K + s_k D + s_k^2 M. The trapezoidal Nyquist bin is
        // the limit problem.
        let Some(symbol) = bin_symbol(scheme, nt, dt, k) else {
            continue;
        };
        let (mass_factor, damping_factor) = match scheme {
            // Written out so that the trapezoidal LCP is bit for bit what it always was.
            LcpScheme::Trapezoidal => (c64::new(-symbol.im * symbol.im, 0.0), symbol),
            LcpScheme::Bdf2 => (symbol * symbol, symbol),
        };
        dynamic
            .factor(0, mass_factor, damping_factor)
            .map_err(|source| match source {
                LinearSolveError::Singular { .. } => LcpError::SingularBin {
                    bin: k,
                    frequency: symbol.im,
                    source,
                },
                other => LcpError::Factorization {
                    bin: k,
                    source: other,
                },
            })?;
        let with_forcing = k == 1;
        let ncols = m + usize::from(with_forcing);
        x.fill(zero);
        for (c, dof) in model.contacts.iter().map(|c| c.dof()).enumerate() {
            x[(dof, c)] = c64::new(1.0, 0.0);
        }
        if with_forcing {
            for (i, a) in load.iter().enumerate() {
                x[(i, m)] = c64::new(*a, 0.0);
            }
        }
        let solve_failed = |source| LcpError::Factorization { bin: k, source };
        dynamic
            .solve_in_place(0, x.as_mut().subcols_mut(0, ncols))
            .map_err(solve_failed)?;
        for (r, &dof) in rows.iter().enumerate() {
            for c in 0..m {
                out.transfer[(k * nr + r) * m + c] = x[(dof, c)];
            }
            if with_forcing {
                out.linear_amplitude[r] = x[(dof, m)];
            }
        }
        if let Some(d) = out.derivative.as_mut() {
            // Y = Z_k^{-1} (dZ_k/domega) X, X = Z_k^{-1} [G^T, f]; dX/domega = -Y. Both
            // symbols are s_k = omega tau_k (dt = 2 pi / (omega Nt)), so
            // dZ_k/domega = tau_k D + 2 omega tau_k^2 M.
            let dz = match scheme {
                LcpScheme::Trapezoidal => {
                    let tau = symbol.im / omega;
                    [
                        zero,
                        c64::new(-2.0 * omega * tau * tau, 0.0),
                        c64::new(0.0, tau),
                    ]
                }
                LcpScheme::Bdf2 => {
                    let tau = symbol / omega;
                    [zero, tau * tau * (2.0 * omega), tau]
                }
            };
            for col in 0..ncols {
                let yc = y.col_as_slice_mut(col);
                yc.fill(zero);
                dynamic.mul_add(dz, &mut values, x.col_as_slice(col), yc);
            }
            dynamic
                .solve_in_place(0, y.as_mut().subcols_mut(0, ncols))
                .map_err(solve_failed)?;
            for (r, c) in model.contacts.iter().enumerate() {
                for c2 in 0..m {
                    d.transfer[(k * m + r) * m + c2] = -y[(c.dof(), c2)];
                }
                if with_forcing {
                    d.linear_amplitude[r] = -y[(c.dof(), m)];
                }
            }
        }
    }
    Ok(out)
}

/// The LCP matrix `A[(ni, ci), (nj, cj)] = a_{ni - nj}[ci, cj]` from the bin receptances:
/// kernel `a_p = (1/Nt) sum_k H_k e^{2 pi i k p / Nt}` for every contact pair by FFT, then
/// column `(nj, cj)` is the column `cj` of the kernel blocks rotated down by `nj` nodes.
fn circulant(plans: &FftPlans, transfer: &[c64], nr: usize, m: usize) -> Mat<f64> {
    let nt = plans.len();
    let mut spectrum = vec![c64::new(0.0, 0.0); nt];
    let mut scratch = plans.scratch();
    let mut kernel = vec![0.0; nt * m * m];
    for c in 0..m {
        for c2 in 0..m {
            fill_spectrum(&mut spectrum, |k| transfer[(k * nr + c) * m + c2]);
            plans.inverse(&mut spectrum, &mut scratch);
            for (p, v) in spectrum.iter().enumerate() {
                kernel[(p * m + c) * m + c2] = v.re / nt as f64;
            }
        }
    }
    let size = m * nt;
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
            let col = matrix.col_as_slice_mut(nj * m + cj);
            col[shift..].copy_from_slice(&column0[..size - shift]);
            col[..shift].copy_from_slice(&column0[size - shift..]);
        }
    }
    matrix
}

/// The symbol `s_k` of `d/dt` on bin `k`:
/// - trapezoidal: `(2/dt) i tan(pi k / Nt)`, `None` (infinite) at the Nyquist bin;
/// - BDF2: `(3 - 4 e^{-i theta} + e^{-2 i theta}) / (2 dt)`, `theta = 2 pi k / Nt`, i.e.
///   `i theta / dt (1 + theta^2 / 3) + theta^4 / (4 dt) + ...`, real and `4 / dt` at Nyquist.
pub(super) fn bin_symbol(scheme: LcpScheme, nt: usize, dt: f64, k: usize) -> Option<c64> {
    match scheme {
        LcpScheme::Trapezoidal if 2 * k == nt => None,
        LcpScheme::Trapezoidal => Some(c64::new(
            0.0,
            2.0 / dt * (std::f64::consts::PI * k as f64 / nt as f64).tan(),
        )),
        LcpScheme::Bdf2 => {
            let theta = 2.0 * std::f64::consts::PI * k as f64 / nt as f64;
            let back = c64::new(theta.cos(), -theta.sin());
            Some((c64::new(3.0, 0.0) - back * 4.0 + back * back) / (2.0 * dt))
        }
    }
}

/// The amplitude `f` of the model's load `f cos(w t)`; any other load is
/// [`LcpError::Unsupported`] (the LCP's forcing is bin 1 only).
fn lcp_load(model: &StructuralModel) -> Result<Vec<f64>, LcpError> {
    model.load.as_cosine().ok_or(LcpError::Unsupported {
        formulation: "the periodic LCP",
        what: "a load other than f cos(w t) (a sine part, a constant or another harmonic)",
    })
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

/// `K_VV^{-1}` applied to the contact columns restricted to `V` (columns of contacts
/// outside `V` are zero), as a dense `|V| x m` matrix (column-major, `|V|` rows), by the
/// core's sparse LU (pivots checked).
fn nyquist_static_receptance(
    model: &StructuralModel,
    static_set: &[usize],
    contact_dofs: &[usize],
    bin: usize,
) -> Result<Vec<f64>, LcpError> {
    let failed = |source| LcpError::Factorization { bin, source };
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
    let kvv = SparseColMat::<usize, f64>::try_new_from_triplets(nv, nv, &triplets)
        .map_err(|e| failed(LinearSolveError::from_creation(e, "assembling K_VV")))?;
    let mut lu = FaerSparseLu::new();
    lu.factor(&kvv).map_err(failed)?;
    let mut columns = vec![0.0; nv * contact_dofs.len()];
    for (column, dof) in columns.chunks_exact_mut(nv).zip(contact_dofs) {
        if let Ok(v) = static_set.binary_search(dof) {
            column[v] = 1.0;
            lu.solve_in_place(column).map_err(failed)?;
        }
    }
    Ok(columns)
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
