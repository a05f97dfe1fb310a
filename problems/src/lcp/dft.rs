//! A small complex discrete Fourier transform for the periodic LCP (plans built once).
//!
//! `X_k = sum_n x_n e^{-2 pi i k n / N}` (forward, unnormalised) and its conjugate
//! (`backward`, also unnormalised: `backward(forward(x)) = N x`). Radix-2 for powers of two,
//! a direct `O(N^2)` sum with a twiddle table otherwise (the LCP sizes are at most a few
//! thousand, and the LCP solve itself is `O(N^2)` or worse).

use faer::c64;

/// A DFT plan of one length: twiddle factors and, for powers of two, the bit-reversal
/// permutation.
#[derive(Debug, Clone)]
pub(crate) struct Dft {
    n: usize,
    /// `e^{-2 pi i j / n}`, `j < n`.
    twiddles: Vec<c64>,
    /// Bit-reversed index of each position (powers of two only).
    bit_reverse: Option<Vec<usize>>,
    /// Scratch for the direct sum.
    scratch: Vec<c64>,
}

impl Dft {
    /// A plan for length `n >= 1`.
    pub(crate) fn new(n: usize) -> Self {
        let twiddles = (0..n)
            .map(|j| {
                let angle = -2.0 * std::f64::consts::PI * j as f64 / n as f64;
                c64::new(angle.cos(), angle.sin())
            })
            .collect();
        let bit_reverse = n.is_power_of_two().then(|| {
            let bits = n.trailing_zeros();
            (0..n)
                .map(|i| {
                    if bits == 0 {
                        0
                    } else {
                        i.reverse_bits() >> (usize::BITS - bits)
                    }
                })
                .collect()
        });
        Self {
            n,
            twiddles,
            bit_reverse,
            scratch: vec![c64::new(0.0, 0.0); n],
        }
    }

    /// In place `X_k = sum_n x_n e^{-2 pi i k n / N}`.
    pub(crate) fn forward(&mut self, x: &mut [c64]) {
        assert_eq!(x.len(), self.n, "DFT length");
        match &self.bit_reverse {
            Some(rev) => {
                for (i, &j) in rev.iter().enumerate() {
                    if i < j {
                        x.swap(i, j);
                    }
                }
                let mut len = 2;
                while len <= self.n {
                    let half = len / 2;
                    let stride = self.n / len;
                    for start in (0..self.n).step_by(len) {
                        for j in 0..half {
                            let t = self.twiddles[j * stride] * x[start + j + half];
                            let u = x[start + j];
                            x[start + j] = u + t;
                            x[start + j + half] = u - t;
                        }
                    }
                    len *= 2;
                }
            }
            None => {
                for (k, out) in self.scratch.iter_mut().enumerate() {
                    let mut sum = c64::new(0.0, 0.0);
                    for (j, v) in x.iter().enumerate() {
                        sum += *v * self.twiddles[(j * k) % self.n];
                    }
                    *out = sum;
                }
                x.copy_from_slice(&self.scratch);
            }
        }
    }

    /// In place `x_n = sum_k X_k e^{+2 pi i k n / N}` (unnormalised inverse).
    pub(crate) fn backward(&mut self, x: &mut [c64]) {
        for v in x.iter_mut() {
            *v = v.conj();
        }
        self.forward(x);
        for v in x.iter_mut() {
            *v = v.conj();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn direct(x: &[c64]) -> Vec<c64> {
        let n = x.len();
        (0..n)
            .map(|k| {
                x.iter()
                    .enumerate()
                    .map(|(j, v)| {
                        let a = -2.0 * std::f64::consts::PI * (j * k) as f64 / n as f64;
                        *v * c64::new(a.cos(), a.sin())
                    })
                    .sum()
            })
            .collect()
    }

    #[test]
    fn radix2_and_direct_paths_match_the_defining_sum() {
        for n in [1usize, 2, 8, 12, 64, 100, 256] {
            let x: Vec<c64> = (0..n)
                .map(|j| c64::new((0.37 * j as f64).sin(), (1.3 * j as f64).cos() - 0.2))
                .collect();
            let mut y = x.clone();
            let mut dft = Dft::new(n);
            dft.forward(&mut y);
            let reference = direct(&x);
            // Round-off of an n-term sum of O(1) values: a few 1e-15 * n.
            for (a, b) in y.iter().zip(&reference) {
                assert!((a - b).norm() < 1e-12 * n as f64, "n = {n}");
            }
            dft.backward(&mut y);
            for (a, b) in y.iter().zip(&x) {
                assert!((a / n as f64 - b).norm() < 1e-13 * n as f64, "n = {n}");
            }
        }
    }
}
