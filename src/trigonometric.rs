//! Where a trigonometric polynomial is positive over one period.
//!
//! For `s(θ) = a_0 + Σ_{k=1}^{H} (a_k cos kθ + b_k sin kθ)` (the coefficient layout of
//! [`FourierBasis`]) the set `{θ : s(θ) > 0}` of one period is a union of intervals whose
//! ends are roots of `s`. [`positive_intervals`] samples `s` on a grid, brackets every
//! sign change between neighbouring samples and refines the root in the bracket by the
//! Illinois variant of regula falsi to round-off. Two roots closer than the grid spacing
//! (an interval shorter than one sample spacing that starts and ends between the same two
//! samples) are not seen: the grid is the resolution, as for the `Nt`-point quadrature of a
//! harmonic-balance contact law.

use std::f64::consts::PI;

use crate::harmonic::{FourierBasis, HarmonicError};

/// Root refinement stops when the bracket is below this fraction of a period.
const ROOT_TOLERANCE: f64 = 1e-13;

/// Largest number of regula-falsi iterations per root.
const MAX_ROOT_ITERATIONS: usize = 100;

/// The intervals of one period where `s(θ) > 0`, as fractions of the period
/// `(start, end)` with `0 <= start < 1` and `start < end <= start + 1` (an interval that
/// wraps past the period's end has `end > 1`), in increasing order of `start`; `[(0, 1)]`
/// when `s > 0` at every sample, `[]` when at none. `samples` (`>= 2H + 1`) is the grid
/// on which sign changes are bracketed.
pub fn positive_intervals(
    basis: &FourierBasis,
    coeffs: &[f64],
    samples: usize,
) -> Result<Vec<(f64, f64)>, HarmonicError> {
    let grid = FourierBasis::new(basis.harmonics(), samples)?;
    if coeffs.len() != grid.basis_size() {
        // The basis's own error for a wrong length.
        grid.evaluate_at_phase(coeffs, 0.0)?;
    }
    let value = |fraction: f64| -> Result<f64, HarmonicError> {
        Ok(sum_by_rotation(coeffs, 2.0 * PI * fraction))
    };
    let values: Vec<f64> = (0..samples)
        .map(|n| sum_by_rotation(coeffs, 2.0 * PI * n as f64 / samples as f64))
        .collect();
    let positive = |v: f64| v > 0.0;
    if values.iter().all(|&v| positive(v)) {
        return Ok(vec![(0.0, 1.0)]);
    }
    if !values.iter().any(|&v| positive(v)) {
        return Ok(Vec::new());
    }
    // Sign changes between samples n and n + 1 (cyclically): (root, rising).
    let mut crossings = Vec::new();
    for n in 0..samples {
        let (a, b) = (values[n], values[(n + 1) % samples]);
        if positive(a) != positive(b) {
            let (lo, hi) = (n as f64 / samples as f64, (n + 1) as f64 / samples as f64);
            let root = refine_root(&value, lo, hi, a, b)?;
            crossings.push((root, positive(b)));
        }
    }
    let first_rise = crossings
        .iter()
        .position(|c| c.1)
        .expect("a sign change both ways exists");
    crossings.rotate_left(first_rise);
    let mut intervals = Vec::with_capacity(crossings.len() / 2);
    for pair in crossings.chunks(2) {
        let start = pair[0].0.rem_euclid(1.0);
        let mut end = pair[1].0;
        while end <= start {
            end += 1.0;
        }
        intervals.push((start, end));
    }
    intervals.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(intervals)
}

/// `a_0 + sum_k (a_k cos k theta + b_k sin k theta)` for `coeffs = (a_0, a_1, b_1, ...)`,
/// with `(cos k theta, sin k theta)` by rotation from `(cos theta, sin theta)`: one `sin_cos`
/// per evaluation (round-off grows like `k` times the machine epsilon).
fn sum_by_rotation(coeffs: &[f64], theta: f64) -> f64 {
    let (s1, c1) = theta.sin_cos();
    let (mut s, mut c) = (s1, c1);
    let mut value = coeffs[0];
    for pair in coeffs[1..].chunks_exact(2) {
        value += pair[0] * c + pair[1] * s;
        (c, s) = (c * c1 - s * s1, s * c1 + c * s1);
    }
    value
}

/// The root of `f` in `[lo, hi]` with `f(lo) = fa`, `f(hi) = fb` of opposite signs
/// (Illinois regula falsi).
fn refine_root(
    f: &dyn Fn(f64) -> Result<f64, HarmonicError>,
    mut lo: f64,
    mut hi: f64,
    mut fa: f64,
    mut fb: f64,
) -> Result<f64, HarmonicError> {
    let mut side = 0i8;
    for _ in 0..MAX_ROOT_ITERATIONS {
        if hi - lo <= ROOT_TOLERANCE {
            break;
        }
        let mut x = (lo * fb - hi * fa) / (fb - fa);
        if !(x > lo && x < hi) {
            x = 0.5 * (lo + hi);
        }
        let fx = f(x)?;
        if fx == 0.0 {
            return Ok(x);
        }
        if (fx > 0.0) == (fb > 0.0) {
            hi = x;
            fb = fx;
            if side == 1 {
                fa *= 0.5;
            }
            side = 1;
        } else {
            lo = x;
            fa = fx;
            if side == -1 {
                fb *= 0.5;
            }
            side = -1;
        }
    }
    Ok((lo * fb - hi * fa) / (fb - fa))
}

/// Total length of `intervals` as a fraction of the period.
pub fn covered_fraction(intervals: &[(f64, f64)]) -> f64 {
    intervals.iter().map(|(a, b)| b - a).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `cos θ - cos θ_0` is positive on `(-θ_0, θ_0)`: one interval wrapping past the
    /// period's end, `(1 - θ_0 / 2π, 1 + θ_0 / 2π)`, found to round-off.
    #[test]
    fn the_positive_part_of_a_shifted_cosine_is_one_wrapping_interval() {
        let basis = FourierBasis::new(1, 8).unwrap();
        let theta0 = 0.3f64;
        let coeffs = [-theta0.cos(), 1.0, 0.0];
        let iv = positive_intervals(&basis, &coeffs, 16).unwrap();
        let half = theta0 / (2.0 * PI);
        assert_eq!(iv.len(), 1);
        assert!((iv[0].0 - (1.0 - half)).abs() < 1e-12, "{iv:?}");
        assert!((iv[0].1 - (1.0 + half)).abs() < 1e-12, "{iv:?}");
        assert!((covered_fraction(&iv) - 2.0 * half).abs() < 1e-12);
    }

    /// `sin 3θ` is positive on three intervals of a sixth of the period each, starting at
    /// 0, 1/3 and 2/3.
    #[test]
    fn three_intervals_of_sin_three_theta() {
        let basis = FourierBasis::new(3, 16).unwrap();
        let coeffs = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
        // Shift the grid off the roots: evaluate a slightly raised sine.
        let raised: Vec<f64> = coeffs
            .iter()
            .enumerate()
            .map(|(i, c)| if i == 0 { 1e-3 } else { *c })
            .collect();
        let iv = positive_intervals(&basis, &raised, 64).unwrap();
        assert_eq!(iv.len(), 3, "{iv:?}");
        let shift = (1e-3f64).asin() / (2.0 * PI * 3.0);
        // Starts in increasing order: 1/3 - shift, 2/3 - shift, 1 - shift.
        for (k, (a, b)) in iv.iter().enumerate() {
            let start = ((k + 1) as f64 / 3.0 - shift).rem_euclid(1.0);
            assert!((a - start).abs() < 1e-12, "{iv:?}");
            assert!((b - a - (1.0 / 6.0 + 2.0 * shift)).abs() < 1e-12, "{iv:?}");
        }
    }

    #[test]
    fn all_positive_and_never_positive() {
        let basis = FourierBasis::new(1, 8).unwrap();
        assert_eq!(
            positive_intervals(&basis, &[2.0, 1.0, 0.0], 8).unwrap(),
            [(0.0, 1.0)]
        );
        assert!(positive_intervals(&basis, &[-2.0, 1.0, 0.0], 8)
            .unwrap()
            .is_empty());
        assert!(matches!(
            positive_intervals(&basis, &[1.0, 0.0], 8),
            Err(HarmonicError::DimensionMismatch { .. })
        ));
    }
}
