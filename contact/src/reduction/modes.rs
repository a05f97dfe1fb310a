//! The lowest modes of a sparse symmetric pencil `(K, M)`, `K` positive definite and `M`
//! positive semi-definite: shift-invert block Lanczos at shift 0 with full
//! reorthogonalisation. The Krylov space of the operator `K^{-1} M` (self-adjoint in the
//! `M` inner product) is grown block by block from a fixed pseudo-random start, its basis
//! `Q` kept `M`-orthonormal (Gram–Schmidt twice); Rayleigh–Ritz on
//! `H = (M Q)^T K^{-1} M Q` gives `theta = 1 / omega^2` and `x = Q s`. A pair is converged
//! when its residual `|K^{-1} M x - theta x|_M <= MODE_TOLERANCE theta`. Blocks of
//! [`BLOCK`] vectors find repeated frequencies (a symmetric section's bending pairs) that a
//! single-vector Lanczos misses. One factorization of `K` serves every step.
//!
//! References: Ericsson & Ruhe (1980), the spectral transformation Lanczos method; Grimes,
//! Lewis & Simon (1994), a shifted block Lanczos algorithm for generalized symmetric
//! eigenproblems.

use faer::{Mat, Side};
use semismooth::LinearSolve;

use crate::model::{sparse_mul_add, SparseMatrix};

use super::ReductionError;

/// Vectors added to the Krylov basis per step.
pub const BLOCK: usize = 4;

/// Relative residual below which a Ritz pair is accepted.
pub const MODE_TOLERANCE: f64 = 1e-10;

/// Which modes: the lowest `Count(n)`, or every mode with `omega <= Below(omega_max)`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum ModeCount {
    /// The lowest `n` modes.
    Count(usize),
    /// Every mode of angular frequency at most this one (rad per unit time).
    Below(f64),
}

/// Natural frequencies (ascending, rad per unit time) and their `M`-normalised mode shapes.
#[derive(Debug, Clone)]
pub struct Modes {
    /// `omega_k`, ascending.
    pub omegas: Vec<f64>,
    /// `x_k` with `x_k^T M x_k = 1`, one per frequency.
    pub shapes: Vec<Vec<f64>>,
}

/// The `M`-orthonormal Krylov basis and what the operator made of each vector.
struct Krylov<'a, S> {
    mass: &'a SparseMatrix,
    solve: &'a mut S,
    q: Vec<Vec<f64>>,
    mq: Vec<Vec<f64>>,
    /// `K^{-1} M q` of each basis vector.
    w: Vec<Vec<f64>>,
    seed: u64,
}

/// `A x` (the model's sparse product).
pub(super) fn times(a: &SparseMatrix, x: &[f64]) -> Vec<f64> {
    let mut y = vec![0.0; a.nrows()];
    sparse_mul_add(a.as_ref(), 1.0, x, &mut y);
    y
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl<S: LinearSolve> Krylov<'_, S> {
    fn apply(&mut self, x: &[f64]) -> Result<Vec<f64>, ReductionError> {
        let mut y = times(self.mass, x);
        self.solve
            .solve_in_place(&mut y)
            .map_err(|e| ReductionError::Factorization {
                reason: e.to_string(),
            })?;
        Ok(y)
    }

    /// A deterministic pseudo-random vector (xorshift).
    fn random(&mut self, n: usize) -> Vec<f64> {
        (0..n)
            .map(|_| {
                self.seed ^= self.seed << 13;
                self.seed ^= self.seed >> 7;
                self.seed ^= self.seed << 17;
                (self.seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            })
            .collect()
    }

    /// Appends `v` orthogonalised against the basis (twice), unless it lies in it.
    fn append(&mut self, mut v: Vec<f64>) -> Result<bool, ReductionError> {
        let before = dot(&v, &times(self.mass, &v)).max(0.0).sqrt();
        if before == 0.0 {
            return Ok(false);
        }
        for _ in 0..2 {
            for (q, mq) in self.q.iter().zip(&self.mq) {
                let c = dot(mq, &v);
                v.iter_mut().zip(q).for_each(|(x, y)| *x -= c * y);
            }
        }
        let mv = times(self.mass, &v);
        let norm = dot(&v, &mv).max(0.0).sqrt();
        if norm <= 1e-10 * before {
            return Ok(false);
        }
        v.iter_mut().for_each(|x| *x /= norm);
        let mq = mv.into_iter().map(|x| x / norm).collect();
        let w = self.apply(&v)?;
        self.q.push(v);
        self.mq.push(mq);
        self.w.push(w);
        Ok(true)
    }

    /// Grows the basis by up to [`BLOCK`] vectors: the operator's images of the last
    /// block, or fresh random ones when those lie in the basis (an invariant subspace).
    fn grow(&mut self, n: usize) -> Result<(), ReductionError> {
        let last = self.w.len().saturating_sub(BLOCK);
        let candidates: Vec<Vec<f64>> = self.w[last..].to_vec();
        let mut added = 0;
        for v in candidates {
            added += usize::from(self.append(v)?);
        }
        let mut attempts = 0;
        while added < BLOCK && self.q.len() < n && attempts < 4 * BLOCK {
            let r = self.random(n);
            let v = self.apply(&r)?;
            added += usize::from(self.append(v)?);
            attempts += 1;
        }
        Ok(())
    }

    /// Ritz pairs `(theta, x, relative residual)`, largest `theta` first.
    fn ritz(&self) -> Result<Vec<(f64, Vec<f64>, f64)>, ReductionError> {
        let m = self.q.len();
        let h = Mat::from_fn(m, m, |a, b| {
            0.5 * (dot(&self.mq[a], &self.w[b]) + dot(&self.mq[b], &self.w[a]))
        });
        let eigen = h
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| ReductionError::Eigen {
                reason: format!("{e:?}"),
            })?;
        let (s, u) = (eigen.S().column_vector(), eigen.U());
        let n = self.q[0].len();
        let mut pairs = Vec::with_capacity(m);
        for k in (0..m).rev() {
            let theta = s[k];
            let (mut x, mut wx) = (vec![0.0; n], vec![0.0; n]);
            for a in 0..m {
                let c = u[(a, k)];
                x.iter_mut().zip(&self.q[a]).for_each(|(t, q)| *t += c * q);
                wx.iter_mut().zip(&self.w[a]).for_each(|(t, w)| *t += c * w);
            }
            let r: Vec<f64> = wx.iter().zip(&x).map(|(w, x)| w - theta * x).collect();
            let residual = dot(&r, &times(self.mass, &r)).max(0.0).sqrt();
            pairs.push((theta, x, residual / theta.abs().max(f64::MIN_POSITIVE)));
        }
        Ok(pairs)
    }
}

/// The lowest modes of `(K, M)` (module documentation): `solve` holds the factorization
/// of `K` (`n x n`), `mass` is `M`. Massless directions have no finite frequency and are
/// not counted. `Count(k)` with fewer than `k` finite frequencies is an error.
pub fn lowest_modes(
    solve: &mut impl LinearSolve,
    mass: &SparseMatrix,
    wanted: ModeCount,
) -> Result<Modes, ReductionError> {
    let n = mass.nrows();
    let mut krylov = Krylov {
        mass,
        solve,
        q: Vec::new(),
        mq: Vec::new(),
        w: Vec::new(),
        seed: 0x9E37_79B9_7F4A_7C15,
    };
    let target = match wanted {
        ModeCount::Count(k) => k.min(n),
        ModeCount::Below(_) => 8.min(n),
    };
    let mut size = (2 * target + 2 * BLOCK).max(target + 20).min(n);
    loop {
        while krylov.q.len() < size {
            let before = krylov.q.len();
            krylov.grow(n)?;
            if krylov.q.len() == before {
                break;
            }
        }
        let pairs = krylov.ritz()?;
        let exhausted = krylov.q.len() >= n || krylov.q.len() < size;
        if let Some(modes) = accepted(&pairs, wanted, exhausted)? {
            return Ok(modes);
        }
        size = (2 * size).min(n);
    }
}

/// The wanted modes of `pairs` (largest `theta` first) once they are converged, `None`
/// while more basis vectors are needed; with an `exhausted` basis the pairs are final.
fn accepted(
    pairs: &[(f64, Vec<f64>, f64)],
    wanted: ModeCount,
    exhausted: bool,
) -> Result<Option<Modes>, ReductionError> {
    let theta_max = pairs.first().map_or(0.0, |p| p.0);
    // Massless directions: theta = 0 to round-off.
    let finite = |theta: f64| theta > 1e-13 * theta_max;
    let ok = |p: &(f64, Vec<f64>, f64)| exhausted || p.2 <= MODE_TOLERANCE;
    let mut modes = Modes {
        omegas: Vec::new(),
        shapes: Vec::new(),
    };
    for p in pairs.iter().filter(|p| finite(p.0)) {
        let omega = 1.0 / p.0.sqrt();
        let more = match wanted {
            ModeCount::Count(k) => modes.omegas.len() < k,
            ModeCount::Below(limit) => omega <= limit,
        };
        if !more {
            return Ok(Some(modes));
        }
        if !ok(p) {
            return Ok(None);
        }
        modes.omegas.push(omega);
        modes.shapes.push(p.1.clone());
    }
    match wanted {
        ModeCount::Count(k) if modes.omegas.len() < k && exhausted => {
            Err(ReductionError::TooFewModes {
                requested: k,
                available: modes.omegas.len(),
            })
        }
        _ if exhausted => Ok(Some(modes)),
        _ => Ok(None),
    }
}
