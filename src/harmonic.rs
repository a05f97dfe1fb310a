//! Harmonic-balance machinery: a real Fourier basis and alternating frequency/time (AFT)
//! transforms between Fourier coefficients and time samples.
//!
//! A `T = 2 pi / omega` periodic signal is approximated with `H` harmonics,
//!
//! `u(t) = u_0 + sum_{k=1..H} (u_ck cos(k omega t) + u_sk sin(k omega t))`,
//!
//! stored as `2H + 1` coefficients ordered `[u_0, u_c1, u_s1, ..., u_cH, u_sH]`
//! (index 0 the constant, `2k - 1` the cosine and `2k` the sine of harmonic `k`; no 1/2 on
//! `u_0`). A vector of `N` signals (degrees of freedom) is stored *harmonic-major*: entry
//! `j * N + s` is coefficient `j` of signal `s`, so operators acting harmonic by harmonic
//! are block diagonal.
//!
//! AFT: `E` maps coefficients to `Nt` samples at the phases `theta_n = 2 pi n / Nt`
//! (times `t_n = n T / Nt`), `P` maps samples back to coefficients by the discrete Fourier
//! transform, with `P E = I` whenever `Nt > 2H`. A nonlinear term `f(u)` is evaluated as
//! `P f(E u)`: the Galerkin integrals become an `Nt`-point trapezoidal quadrature, exact for
//! trigonometric polynomials of degree `< Nt - H`. Both transforms are real FFTs (realfft),
//! with plans built once and buffers kept, so repeated transforms allocate nothing.
//!
//! [`Aft`] offers each transform twice: on slices passed in (checked, a wrong length is a
//! [`HarmonicError`]) and on buffers it owns, sized by the basis when it is built
//! ([`Aft::coefficients_mut`], [`Aft::samples_mut`], then [`Aft::coefficients_to_samples`],
//! [`Aft::samples_to_coefficients`], [`Aft::samples_multiplication_matrix`]), which cannot
//! fail: a residual evaluated in a hot loop needs no error path for lengths fixed at
//! construction.
//!
//! Reference: Cameron & Griffin (1989), "An alternating frequency/time domain method for
//! calculating the steady-state response of nonlinear dynamic systems", J. Appl. Mech.

use std::f64::consts::PI;
use std::fmt;
use std::sync::Arc;

use faer::{Mat, MatMut};
use realfft::num_complex::Complex;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};

/// Why a Fourier basis or a transform could not be set up or carried out.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum HarmonicError {
    /// `Nt <= 2H`: the samples cannot resolve the highest harmonic (`P E = I` fails).
    #[error(
        "time_samples = {time_samples} is too small for harmonics = {harmonics}: at least {minimum} (> 2H) required"
    )]
    TooFewSamples {
        /// Number of harmonics `H` requested.
        harmonics: usize,
        /// Number of time samples `Nt` requested.
        time_samples: usize,
        /// Smallest admissible `Nt` (`2H + 1`).
        minimum: usize,
    },
    /// A slice has the wrong length.
    #[error("{what}: expected length {expected}, found {found}")]
    DimensionMismatch {
        /// Which argument.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Length received.
        found: usize,
    },
    /// The FFT backend rejected a call (should not happen with consistent lengths).
    #[error("FFT backend error: {reason}")]
    Fft {
        /// Description from realfft.
        reason: String,
    },
}

/// Default number of time samples for `H` harmonics: the next power of two
/// `>= max(64, 4 (2H + 1))`.
///
/// Four samples per basis function keeps the quadrature of a nonsmooth (kinked) integrand
/// reasonably resolved while `P E = I` needs only `Nt > 2H`; the floor of 64 makes small
/// `H` resolve contact intervals, and a power of two is the fastest FFT length.
/// Examples: `H = 5 -> 64`, `H = 20 -> 256`, `H = 40 -> 512`.
pub fn default_time_samples(harmonics: usize) -> usize {
    let wanted = (4 * (2 * harmonics + 1)).max(64);
    wanted.next_power_of_two()
}

/// A real Fourier basis with `H` harmonics (`2H + 1` functions) sampled at `Nt` equally
/// spaced phases per period.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FourierBasis {
    harmonics: usize,
    time_samples: usize,
}

impl FourierBasis {
    /// A basis with `harmonics = H` and `time_samples = Nt`; requires `Nt > 2H`.
    pub fn new(harmonics: usize, time_samples: usize) -> Result<Self, HarmonicError> {
        let minimum = 2 * harmonics + 1;
        if time_samples < minimum {
            return Err(HarmonicError::TooFewSamples {
                harmonics,
                time_samples,
                minimum,
            });
        }
        Ok(Self {
            harmonics,
            time_samples,
        })
    }

    /// A basis with [`default_time_samples`]`(harmonics)` samples.
    pub fn with_default_samples(harmonics: usize) -> Self {
        Self {
            harmonics,
            time_samples: default_time_samples(harmonics),
        }
    }

    /// Number of harmonics `H`.
    pub fn harmonics(&self) -> usize {
        self.harmonics
    }

    /// Number of time samples `Nt` per period.
    pub fn time_samples(&self) -> usize {
        self.time_samples
    }

    /// Number of basis functions `2H + 1`.
    pub fn basis_size(&self) -> usize {
        2 * self.harmonics + 1
    }

    /// Phase `theta_n = 2 pi n / Nt` of sample `n` (time `t_n = theta_n / omega`).
    pub fn phase(&self, n: usize) -> f64 {
        2.0 * PI * n as f64 / self.time_samples as f64
    }

    /// `u(theta)` at phase `theta = omega t` from the coefficients of one signal.
    pub fn evaluate_at_phase(&self, coeffs: &[f64], theta: f64) -> Result<f64, HarmonicError> {
        self.check_len("coefficients", coeffs.len())?;
        Ok(self.sum_at_phase(coeffs, theta))
    }

    /// The trigonometric sum of `coeffs` (length `2H + 1`) at `theta`.
    fn sum_at_phase(&self, coeffs: &[f64], theta: f64) -> f64 {
        let mut value = coeffs[0];
        for k in 1..=self.harmonics {
            let (s, c) = (k as f64 * theta).sin_cos();
            value += coeffs[2 * k - 1] * c + coeffs[2 * k] * s;
        }
        value
    }

    /// `u(t)` at an arbitrary time `t` for angular frequency `omega`.
    pub fn evaluate(&self, coeffs: &[f64], omega: f64, t: f64) -> Result<f64, HarmonicError> {
        self.evaluate_at_phase(coeffs, omega * t)
    }

    /// `u(t_i)` at each of `times` (written into `out`, same length).
    pub fn evaluate_many(
        &self,
        coeffs: &[f64],
        omega: f64,
        times: &[f64],
        out: &mut [f64],
    ) -> Result<(), HarmonicError> {
        if out.len() != times.len() {
            return Err(HarmonicError::DimensionMismatch {
                what: "output values",
                expected: times.len(),
                found: out.len(),
            });
        }
        for (o, &t) in out.iter_mut().zip(times) {
            *o = self.evaluate(coeffs, omega, t)?;
        }
        Ok(())
    }

    /// Time derivative in coefficient space: for each pair `(a_k, b_k)` the derivative has
    /// `(k omega b_k, -k omega a_k)`, and the constant term vanishes.
    pub fn differentiate(
        &self,
        coeffs: &[f64],
        omega: f64,
        out: &mut [f64],
    ) -> Result<(), HarmonicError> {
        self.check_len("coefficients", coeffs.len())?;
        self.check_len("derivative coefficients", out.len())?;
        out[0] = 0.0;
        for k in 1..=self.harmonics {
            let kw = k as f64 * omega;
            let (a, b) = (coeffs[2 * k - 1], coeffs[2 * k]);
            out[2 * k - 1] = kw * b;
            out[2 * k] = -kw * a;
        }
        Ok(())
    }

    /// Mean square over one period by Parseval: `u_0^2 + 1/2 sum_k (a_k^2 + b_k^2)`.
    pub fn mean_square(&self, coeffs: &[f64]) -> Result<f64, HarmonicError> {
        self.check_len("coefficients", coeffs.len())?;
        let oscillating: f64 = coeffs[1..].iter().map(|c| c * c).sum();
        Ok(coeffs[0] * coeffs[0] + 0.5 * oscillating)
    }

    fn check_len(&self, what: &'static str, found: usize) -> Result<(), HarmonicError> {
        check_length(what, self.basis_size(), found)
    }
}

/// Alternating frequency/time transforms for one [`FourierBasis`]: real FFT plans built
/// once, buffers kept, so [`Aft::to_time`] and [`Aft::to_coefficients`] allocate nothing.
/// Counts the FFTs it performs.
///
/// The owned coefficient and sample buffers make the transforms infallible:
///
/// ```
/// use semismooth::harmonic::{Aft, FourierBasis};
/// let mut aft = Aft::new(FourierBasis::new(2, 8).unwrap());
/// aft.coefficients_mut().copy_from_slice(&[1.0, 0.5, 0.0, 0.0, 0.25]);
/// aft.coefficients_to_samples(); // u(theta) = 1 + cos(theta) / 2 + sin(2 theta) / 4
/// let theta = std::f64::consts::PI / 4.0;
/// assert!((aft.samples()[1] - (1.0 + 0.5 * theta.cos() + 0.25)).abs() < 1e-15);
/// aft.samples_mut().iter_mut().for_each(|u| *u *= 2.0);
/// aft.samples_to_coefficients();
/// assert!((aft.coefficients()[4] - 0.5).abs() < 1e-15);
/// ```
pub struct Aft {
    basis: FourierBasis,
    forward: Arc<dyn RealToComplex<f64>>,
    inverse: Arc<dyn ComplexToReal<f64>>,
    /// Input of the forward FFT (realfft uses it as scratch).
    time: Vec<f64>,
    /// Owned buffers of the infallible transforms (`2H + 1` and `Nt` entries).
    coefficients: Vec<f64>,
    samples: Vec<f64>,
    spectrum: Vec<Complex<f64>>,
    forward_scratch: Vec<Complex<f64>>,
    inverse_scratch: Vec<Complex<f64>>,
    ffts: u64,
}

impl fmt::Debug for Aft {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Aft")
            .field("basis", &self.basis)
            .field("ffts", &self.ffts)
            .finish_non_exhaustive()
    }
}

impl Clone for Aft {
    fn clone(&self) -> Self {
        Self::new(self.basis)
    }
}

impl Aft {
    /// Plans the forward and inverse real FFTs of length `Nt` and allocates the buffers
    /// (the owned ones zeroed).
    pub fn new(basis: FourierBasis) -> Self {
        let nt = basis.time_samples();
        let mut planner = RealFftPlanner::<f64>::new();
        let forward = planner.plan_fft_forward(nt);
        let inverse = planner.plan_fft_inverse(nt);
        let forward_scratch = forward.make_scratch_vec();
        let inverse_scratch = inverse.make_scratch_vec();
        let spectrum = forward.make_output_vec();
        Self {
            basis,
            forward,
            inverse,
            time: vec![0.0; nt],
            coefficients: vec![0.0; basis.basis_size()],
            samples: vec![0.0; nt],
            spectrum,
            forward_scratch,
            inverse_scratch,
            ffts: 0,
        }
    }

    /// The basis these transforms are built for.
    pub fn basis(&self) -> &FourierBasis {
        &self.basis
    }

    /// Number of FFTs performed so far (each transform of one signal counts one).
    pub fn fft_count(&self) -> u64 {
        self.ffts
    }

    /// `E`: coefficients of one signal (length `2H + 1`) to its `Nt` samples
    /// `u(theta_n)`, `theta_n = 2 pi n / Nt`.
    pub fn to_time(&mut self, coeffs: &[f64], samples: &mut [f64]) -> Result<(), HarmonicError> {
        self.basis.check_len("coefficients", coeffs.len())?;
        self.check_samples("samples", samples.len())?;
        self.synthesize(coeffs, samples);
        Ok(())
    }

    /// `P`: `Nt` samples of one signal to its `2H + 1` coefficients (discrete Fourier
    /// projection: `u_0 = mean`, `a_k = 2/Nt sum x_n cos k theta_n`, `b_k = 2/Nt sum x_n sin k
    /// theta_n`), with `P E = I`.
    pub fn to_coefficients(
        &mut self,
        samples: &[f64],
        coeffs: &mut [f64],
    ) -> Result<(), HarmonicError> {
        self.check_samples("samples", samples.len())?;
        self.basis.check_len("coefficients", coeffs.len())?;
        self.time.copy_from_slice(samples);
        self.forward_spectrum();
        self.project(coeffs);
        Ok(())
    }

    /// `E` for `signals` signals at once. `coeffs` is harmonic-major (entry `j * signals + s`,
    /// length `(2H + 1) signals`); `samples` is signal-major (entry `s * Nt + n`, length
    /// `signals Nt`). Counts `signals` FFTs.
    pub fn to_time_batch(
        &mut self,
        coeffs: &[f64],
        signals: usize,
        samples: &mut [f64],
    ) -> Result<(), HarmonicError> {
        let nt = self.check_batch(signals, coeffs.len(), samples.len())?;
        let mut gathered = std::mem::take(&mut self.coefficients);
        for s in 0..signals {
            for (j, g) in gathered.iter_mut().enumerate() {
                *g = coeffs[j * signals + s];
            }
            self.synthesize(&gathered, &mut samples[s * nt..(s + 1) * nt]);
        }
        self.coefficients = gathered;
        Ok(())
    }

    /// `P` for `signals` signals at once: `samples` signal-major (`s * Nt + n`), `coeffs`
    /// harmonic-major (`j * signals + s`). Counts `signals` FFTs.
    pub fn to_coefficients_batch(
        &mut self,
        samples: &[f64],
        signals: usize,
        coeffs: &mut [f64],
    ) -> Result<(), HarmonicError> {
        let nt = self.check_batch(signals, coeffs.len(), samples.len())?;
        let mut projected = std::mem::take(&mut self.coefficients);
        for s in 0..signals {
            self.time.copy_from_slice(&samples[s * nt..(s + 1) * nt]);
            self.forward_spectrum();
            self.project(&mut projected);
            for (j, p) in projected.iter().enumerate() {
                coeffs[j * signals + s] = *p;
            }
        }
        self.coefficients = projected;
        Ok(())
    }

    /// `Nt`, once the lengths of the harmonic-major coefficients (`coeffs`) and the
    /// signal-major samples (`samples`) of `signals` signals are checked.
    fn check_batch(
        &self,
        signals: usize,
        coeffs: usize,
        samples: usize,
    ) -> Result<usize, HarmonicError> {
        let size = self.basis.basis_size();
        let nt = self.basis.time_samples();
        check_length("harmonic-major coefficients", size * signals, coeffs)?;
        check_length("signal-major samples", nt * signals, samples)?;
        Ok(nt)
    }

    /// The `(2H + 1) x (2H + 1)` matrix `P diag(w) E` of multiplication by a sampled
    /// function `w(theta_n)` (the AFT Galerkin matrix; for `w = 1` it is the identity).
    ///
    /// Built from one FFT of `w`: with `c_m = 1/Nt sum w_n cos(m theta_n)` and
    /// `s_m = 1/Nt sum w_n sin(m theta_n)`, products of basis functions reduce to sums and
    /// differences of harmonics (e.g. `cos p cos q = (cos(p-q) + cos(p+q)) / 2`), so the
    /// cost is one FFT plus `O(H^2)`.
    pub fn multiplication_matrix(
        &mut self,
        weights: &[f64],
        out: MatMut<'_, f64>,
    ) -> Result<(), HarmonicError> {
        let size = self.basis.basis_size();
        self.check_samples("weights", weights.len())?;
        if out.nrows() != size || out.ncols() != size {
            return Err(HarmonicError::DimensionMismatch {
                what: "multiplication matrix (rows and columns must both be 2H + 1)",
                expected: size,
                found: if out.nrows() != size {
                    out.nrows()
                } else {
                    out.ncols()
                },
            });
        }
        self.time.copy_from_slice(weights);
        self.forward_spectrum();
        self.fill_multiplication_matrix(out);
        Ok(())
    }

    /// The buffer of coefficients (`2H + 1`) of the infallible transforms.
    pub fn coefficients(&self) -> &[f64] {
        &self.coefficients
    }

    /// The buffer of coefficients (`2H + 1`), to be filled before
    /// [`Aft::coefficients_to_samples`].
    pub fn coefficients_mut(&mut self) -> &mut [f64] {
        &mut self.coefficients
    }

    /// The buffer of samples (`Nt`) of the infallible transforms.
    pub fn samples(&self) -> &[f64] {
        &self.samples
    }

    /// The buffer of samples (`Nt`), to be filled before [`Aft::samples_to_coefficients`] or
    /// [`Aft::samples_multiplication_matrix`].
    pub fn samples_mut(&mut self) -> &mut [f64] {
        &mut self.samples
    }

    /// `E` on the owned buffers: [`Aft::samples`] `<-` `E` [`Aft::coefficients`] (one FFT).
    pub fn coefficients_to_samples(&mut self) {
        let coeffs = std::mem::take(&mut self.coefficients);
        let mut samples = std::mem::take(&mut self.samples);
        self.synthesize(&coeffs, &mut samples);
        self.coefficients = coeffs;
        self.samples = samples;
    }

    /// `P` on the owned buffers: [`Aft::coefficients`] `<-` `P` [`Aft::samples`] (one FFT;
    /// the samples are kept).
    pub fn samples_to_coefficients(&mut self) {
        self.time.copy_from_slice(&self.samples);
        self.forward_spectrum();
        let mut coeffs = std::mem::take(&mut self.coefficients);
        self.project(&mut coeffs);
        self.coefficients = coeffs;
    }

    /// [`Aft::multiplication_matrix`] of the owned samples into `out`, which is resized to
    /// `(2H + 1) x (2H + 1)` when its shape differs (no allocation when it has it).
    pub fn samples_multiplication_matrix(&mut self, out: &mut Mat<f64>) {
        let size = self.basis.basis_size();
        if out.nrows() != size || out.ncols() != size {
            out.resize_with(size, size, |_, _| 0.0);
        }
        self.time.copy_from_slice(&self.samples);
        self.forward_spectrum();
        self.fill_multiplication_matrix(out.as_mut());
    }

    /// `P diag(w) E` from the spectrum of `w` in `self.spectrum` (`out` is `2H + 1` square).
    fn fill_multiplication_matrix(&self, mut out: MatMut<'_, f64>) {
        let nt = self.basis.time_samples();
        let h = self.basis.harmonics() as i64;
        let scale = 1.0 / nt as f64;
        let spectrum = &self.spectrum;
        // (c_m, s_m) for any integer m (periodic in m with period Nt; c even, s odd).
        let cs = |m: i64| -> (f64, f64) {
            let r = m.rem_euclid(nt as i64) as usize;
            if r <= nt / 2 {
                (spectrum[r].re * scale, -spectrum[r].im * scale)
            } else {
                let q = nt - r;
                (spectrum[q].re * scale, spectrum[q].im * scale)
            }
        };
        let (c0, _) = cs(0);
        out[(0, 0)] = c0;
        for q in 1..=h {
            let (cq, sq) = cs(q);
            let (ic, is) = (2 * q as usize - 1, 2 * q as usize);
            // Row 0 (weight 1): mean of w cos q, w sin q.
            out[(0, ic)] = cq;
            out[(0, is)] = sq;
            // Column 0 (weight 2): 2 c_q, 2 s_q.
            out[(ic, 0)] = 2.0 * cq;
            out[(is, 0)] = 2.0 * sq;
        }
        for p in 1..=h {
            let (pc, ps) = (2 * p as usize - 1, 2 * p as usize);
            for q in 1..=h {
                let (qc, qs) = (2 * q as usize - 1, 2 * q as usize);
                let (c_minus, s_minus) = cs(p - q);
                let (c_plus, s_plus) = cs(p + q);
                // Row weight 2 times 1/2 from the product formulas.
                out[(pc, qc)] = c_minus + c_plus;
                out[(ps, qs)] = c_minus - c_plus;
                out[(pc, qs)] = s_plus - s_minus;
                out[(ps, qc)] = s_plus + s_minus;
            }
        }
    }

    /// Forward FFT of `self.time` into `self.spectrum` (counts one FFT; `self.time` is
    /// overwritten). realfft refuses only buffers of other lengths than its plan's, and
    /// these are the plan's own; were it to refuse, the bins are summed directly.
    fn forward_spectrum(&mut self) {
        let refused = self
            .forward
            .process_with_scratch(
                &mut self.time,
                &mut self.spectrum,
                &mut self.forward_scratch,
            )
            .is_err();
        if refused {
            direct_spectrum(&self.time, &mut self.spectrum);
        }
        self.ffts += 1;
    }

    /// Coefficients (`2H + 1`) from the spectrum in `self.spectrum` (`P` after the FFT).
    fn project(&self, coeffs: &mut [f64]) {
        let scale = 1.0 / self.basis.time_samples() as f64;
        coeffs[0] = self.spectrum[0].re * scale;
        for k in 1..=self.basis.harmonics() {
            coeffs[2 * k - 1] = 2.0 * self.spectrum[k].re * scale;
            coeffs[2 * k] = -2.0 * self.spectrum[k].im * scale;
        }
    }

    /// `samples <- E coeffs` (lengths `2H + 1` and `Nt`, checked by the callers; one FFT).
    ///
    /// Inverse real DFT `x_n = sum_k X_k e^{+i theta_n k}` (unnormalised, Hermitian
    /// extension): `X_0 = u_0` and `X_k = (a_k - i b_k) / 2` give
    /// `x_n = u_0 + sum_k (a_k cos k theta_n + b_k sin k theta_n)`. `H < Nt / 2`, so bin `H`
    /// is never the Nyquist bin and the bins realfft requires real (0 and `Nt/2`) are real.
    /// realfft refuses only other buffer lengths or such imaginary parts; were it to refuse,
    /// the trigonometric sums are evaluated directly.
    fn synthesize(&mut self, coeffs: &[f64], samples: &mut [f64]) {
        self.spectrum.fill(Complex::new(0.0, 0.0));
        self.spectrum[0] = Complex::new(coeffs[0], 0.0);
        for k in 1..=self.basis.harmonics() {
            self.spectrum[k] = Complex::new(0.5 * coeffs[2 * k - 1], -0.5 * coeffs[2 * k]);
        }
        let refused = self
            .inverse
            .process_with_scratch(&mut self.spectrum, samples, &mut self.inverse_scratch)
            .is_err();
        if refused {
            for (n, x) in samples.iter_mut().enumerate() {
                *x = self.basis.sum_at_phase(coeffs, self.basis.phase(n));
            }
        }
        self.ffts += 1;
    }

    fn check_samples(&self, what: &'static str, found: usize) -> Result<(), HarmonicError> {
        check_length(what, self.basis.time_samples(), found)
    }
}

/// `spectrum[k] = sum_n x_n e^{-2 pi i k n / Nt}` for the bins `k < spectrum.len()`, by
/// direct summation (the reference the FFT path must reproduce).
fn direct_spectrum(x: &[f64], spectrum: &mut [Complex<f64>]) {
    let nt = x.len() as f64;
    for (k, bin) in spectrum.iter_mut().enumerate() {
        *bin = x
            .iter()
            .enumerate()
            .map(|(n, v)| {
                let angle = -2.0 * PI * (k * n) as f64 / nt;
                Complex::new(v * angle.cos(), v * angle.sin())
            })
            .sum();
    }
}

/// `Err(DimensionMismatch { what, expected, found })` unless the lengths agree.
pub fn check_length(
    what: &'static str,
    expected: usize,
    found: usize,
) -> Result<(), HarmonicError> {
    if expected != found {
        return Err(HarmonicError::DimensionMismatch {
            what,
            expected,
            found,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;

    /// Deterministic pseudo-random coefficients in [-1, 1].
    fn coefficients(size: usize, seed: u64) -> Vec<f64> {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (0..size)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((state >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
            })
            .collect()
    }

    #[test]
    fn default_time_samples_is_power_of_two_at_least_four_per_function() {
        assert_eq!(default_time_samples(0), 64);
        assert_eq!(default_time_samples(5), 64);
        assert_eq!(default_time_samples(20), 256);
        assert_eq!(default_time_samples(40), 512);
        for h in 0..100 {
            let nt = default_time_samples(h);
            assert!(nt.is_power_of_two() && nt >= 4 * (2 * h + 1) && nt >= 64);
            assert!(FourierBasis::new(h, nt).is_ok());
        }
    }

    #[test]
    fn too_few_samples_is_rejected_with_the_numbers() {
        assert_eq!(
            FourierBasis::new(5, 10),
            Err(HarmonicError::TooFewSamples {
                harmonics: 5,
                time_samples: 10,
                minimum: 11
            })
        );
        assert!(FourierBasis::new(5, 11).is_ok());
    }

    #[test]
    fn round_trip_is_exact_on_trigonometric_polynomials() {
        // P E = I for Nt > 2H, including odd Nt and the minimal Nt = 2H + 1; the only error
        // is FFT rounding (a few ulps times log Nt).
        for &(h, nt) in &[
            (0, 1),
            (1, 3),
            (3, 7),
            (5, 11),
            (5, 12),
            (20, 64),
            (20, 256),
            (7, 100),
        ] {
            let basis = FourierBasis::new(h, nt).unwrap();
            let mut aft = Aft::new(basis);
            let u = coefficients(2 * h + 1, (h * 1000 + nt) as u64);
            let mut samples = vec![0.0; nt];
            let mut back = vec![0.0; 2 * h + 1];
            aft.to_time(&u, &mut samples).unwrap();
            // Samples against direct evaluation of the series.
            for (n, &x) in samples.iter().enumerate() {
                let direct = basis.evaluate_at_phase(&u, basis.phase(n)).unwrap();
                assert!((x - direct).abs() < 1e-13, "H={h} Nt={nt} n={n}");
            }
            aft.to_coefficients(&samples, &mut back).unwrap();
            for (a, b) in u.iter().zip(&back) {
                assert!((a - b).abs() < 1e-13, "H={h} Nt={nt}: {a} vs {b}");
            }
            assert_eq!(aft.fft_count(), 2);
        }
    }

    #[test]
    fn p_times_e_is_identity_column_by_column() {
        let basis = FourierBasis::new(6, 16).unwrap();
        let mut aft = Aft::new(basis);
        let size = basis.basis_size();
        let mut samples = vec![0.0; 16];
        let mut col = vec![0.0; size];
        for j in 0..size {
            let mut e = vec![0.0; size];
            e[j] = 1.0;
            aft.to_time(&e, &mut samples).unwrap();
            aft.to_coefficients(&samples, &mut col).unwrap();
            for (i, &v) in col.iter().enumerate() {
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!((v - expected).abs() < 1e-14, "(P E)[{i},{j}] = {v}");
            }
        }
    }

    #[test]
    fn parseval_mean_square_matches_samples() {
        let basis = FourierBasis::new(9, 64).unwrap();
        let mut aft = Aft::new(basis);
        let u = coefficients(basis.basis_size(), 7);
        let mut samples = vec![0.0; 64];
        aft.to_time(&u, &mut samples).unwrap();
        // u^2 has degree 2H = 18 < Nt: the sample mean is the exact period mean.
        let sample_mean = samples.iter().map(|x| x * x).sum::<f64>() / 64.0;
        let parseval = basis.mean_square(&u).unwrap();
        assert!((sample_mean - parseval).abs() < 1e-13 * parseval.max(1.0));
    }

    #[test]
    fn derivative_matches_analytic_derivative() {
        let basis = FourierBasis::new(4, 32).unwrap();
        let omega = 1.7;
        let u = coefficients(basis.basis_size(), 11);
        let mut du = vec![0.0; basis.basis_size()];
        basis.differentiate(&u, omega, &mut du).unwrap();
        for &t in &[0.0, 0.3, 1.1, 2.9] {
            let mut analytic = 0.0;
            for k in 1..=4 {
                let kw = k as f64 * omega;
                analytic += -kw * u[2 * k - 1] * (kw * t).sin() + kw * u[2 * k] * (kw * t).cos();
            }
            let from_coeffs = basis.evaluate(&du, omega, t).unwrap();
            assert!((analytic - from_coeffs).abs() < 1e-13, "t={t}");
        }
    }

    #[test]
    fn batch_transforms_match_single_signal_transforms() {
        let basis = FourierBasis::new(3, 16).unwrap();
        let mut aft = Aft::new(basis);
        let signals = 3;
        let size = basis.basis_size();
        let u = coefficients(size * signals, 5);
        let mut samples = vec![0.0; 16 * signals];
        aft.to_time_batch(&u, signals, &mut samples).unwrap();
        let mut single = vec![0.0; 16];
        for s in 0..signals {
            let one: Vec<f64> = (0..size).map(|j| u[j * signals + s]).collect();
            aft.to_time(&one, &mut single).unwrap();
            assert_eq!(&samples[s * 16..(s + 1) * 16], &single[..]);
        }
        let mut back = vec![0.0; size * signals];
        aft.to_coefficients_batch(&samples, signals, &mut back)
            .unwrap();
        for (a, b) in u.iter().zip(&back) {
            assert!((a - b).abs() < 1e-14);
        }
        assert_eq!(aft.fft_count(), 3 + 3 + 3);
    }

    #[test]
    fn multiplication_matrix_equals_p_diag_w_e() {
        // Includes a small Nt (2H + 1 < Nt < 4H + 1) where p + q aliases.
        for &(h, nt) in &[(3, 7), (3, 8), (4, 12), (5, 64)] {
            let basis = FourierBasis::new(h, nt).unwrap();
            let mut aft = Aft::new(basis);
            let size = basis.basis_size();
            let w: Vec<f64> = coefficients(nt, nt as u64)
                .iter()
                .map(|x| x.abs())
                .collect();
            let mut m = Mat::<f64>::zeros(size, size);
            aft.multiplication_matrix(&w, m.as_mut()).unwrap();
            let mut samples = vec![0.0; nt];
            let mut col = vec![0.0; size];
            for j in 0..size {
                let mut e = vec![0.0; size];
                e[j] = 1.0;
                aft.to_time(&e, &mut samples).unwrap();
                for (x, wn) in samples.iter_mut().zip(&w) {
                    *x *= wn;
                }
                aft.to_coefficients(&samples, &mut col).unwrap();
                for i in 0..size {
                    assert!(
                        (m[(i, j)] - col[i]).abs() < 1e-14,
                        "H={h} Nt={nt} ({i},{j}): {} vs {}",
                        m[(i, j)],
                        col[i]
                    );
                }
            }
        }
    }

    #[test]
    fn owned_buffers_give_the_checked_transforms() {
        let basis = FourierBasis::new(7, 40).unwrap();
        let mut aft = Aft::new(basis);
        let coeffs = coefficients(basis.basis_size(), 11);
        let mut samples = vec![0.0; 40];
        aft.to_time(&coeffs, &mut samples).unwrap();
        aft.coefficients_mut().copy_from_slice(&coeffs);
        aft.coefficients_to_samples();
        assert_eq!(aft.samples(), &samples[..]);
        for (n, x) in samples.iter().enumerate() {
            // The direct trigonometric sum (the fallback) agrees with the FFT.
            let direct = basis.sum_at_phase(&coeffs, basis.phase(n));
            assert!((direct - x).abs() < 1e-13, "{direct} vs {x}");
        }
        let weights: Vec<f64> = samples.iter().map(|x| x.max(0.0)).collect();
        let mut projected = vec![0.0; basis.basis_size()];
        aft.to_coefficients(&weights, &mut projected).unwrap();
        let mut m = Mat::zeros(basis.basis_size(), basis.basis_size());
        aft.multiplication_matrix(&weights, m.as_mut()).unwrap();
        aft.samples_mut().copy_from_slice(&weights);
        aft.samples_to_coefficients();
        assert_eq!(aft.coefficients(), &projected[..]);
        assert_eq!(aft.samples(), &weights[..], "the samples are kept");
        let mut owned = Mat::zeros(1, 1); // resized to 2H + 1
        aft.samples_multiplication_matrix(&mut owned);
        assert_eq!(owned, m);
        assert_eq!(aft.fft_count(), 6);
    }

    #[test]
    fn direct_spectrum_matches_the_fft() {
        let basis = FourierBasis::new(3, 24).unwrap();
        let mut aft = Aft::new(basis);
        let x = coefficients(24, 5);
        aft.time.copy_from_slice(&x);
        aft.forward_spectrum();
        let mut direct = vec![Complex::new(0.0, 0.0); aft.spectrum.len()];
        direct_spectrum(&x, &mut direct);
        for (a, b) in aft.spectrum.iter().zip(&direct) {
            assert!((a - b).norm() < 1e-13, "{a} vs {b}");
        }
    }

    #[test]
    fn wrong_lengths_are_typed_errors() {
        let basis = FourierBasis::new(2, 8).unwrap();
        let mut aft = Aft::new(basis);
        let mut samples = vec![0.0; 8];
        assert!(matches!(
            aft.to_time(&[1.0, 2.0], &mut samples),
            Err(HarmonicError::DimensionMismatch {
                expected: 5,
                found: 2,
                ..
            })
        ));
        let mut coeffs = vec![0.0; 5];
        assert!(matches!(
            aft.to_coefficients(&[0.0; 7], &mut coeffs),
            Err(HarmonicError::DimensionMismatch {
                expected: 8,
                found: 7,
                ..
            })
        ));
        assert_eq!(aft.fft_count(), 0);
    }
}
