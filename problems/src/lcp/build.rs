//! Construction of the periodic LCP: the bin receptances by sparse complex LU, the Nyquist
//! limit, the circulant kernel by FFT, and `A` and `q` (module documentation of [`super`]).

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, Triplet};
use faer::{c64, Mat};

use super::dft::Dft;
use super::{FrequencyDerivative, LcpError, PeriodicLcp, PeriodicLcpOptions};
use crate::model::{SparseMatrix, StructuralModel};

/// Relative residual `|Z x - b| / (|Z| |x| + |b|)` above which a bin solve is rejected
/// (a forcing-free resonance: `Z_k` numerically singular).
const BIN_RESIDUAL_TOLERANCE: f64 = 1e-8;

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
}

/// `(2/dt) tan(pi k / Nt)`, infinite at the Nyquist bin.
pub(super) fn bin_frequency(nt: usize, dt: f64, k: usize) -> f64 {
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
