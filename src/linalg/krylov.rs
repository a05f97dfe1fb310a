//! Matrix-free restarted GMRES with right preconditioning.
//!
//! For a square system `A x = b` given only by products `v -> A v` and a preconditioner
//! `v -> M^{-1} v` (an approximation of `A^{-1}`), GMRES(k) builds an orthonormal basis
//! `V_j` of the Krylov space of `A M^{-1}` from the initial residual `r_0 = b - A x_0` by
//! modified Gram–Schmidt (Arnoldi: `A M^{-1} V_j = V_{j+1} H_j`), and picks
//! `x = x_0 + M^{-1} V_j y` minimising the true residual `|b - A x|_2 = |beta e_1 - H_j y|_2`,
//! which Givens rotations keep available at every step without forming `x`. With right
//! preconditioning the monitored residual is the residual of the original system, so the
//! stopping test is on `|b - A x|`, not on a preconditioned norm. After `k` steps the
//! method restarts from the current `x` (memory at most `2 (k + 1) n` numbers: the basis
//! and the preconditioned basis vectors, so that the preconditioner is applied once per
//! step; they are allocated as the steps reach them and kept for the next solve).
//!
//! The stopping test is `|b - A x| <= max(relative |b|, absolute)`; after each restart the
//! residual is recomputed from `A x` (not the recurrence) and the test repeated on it.
//! A run that exhausts its iteration budget is [`LinearSolveError::NotConverged`], with the
//! residual reached.

use super::LinearSolveError;

/// A square linear operator given by products, with an optional preconditioner.
///
/// ```
/// use semismooth::linalg::{Gmres, GmresOptions, KrylovOperator, LinearSolveError};
/// /// tridiag(-1, 4, -1) on R^n, applied without a matrix; Jacobi preconditioner.
/// struct Chain(usize);
/// impl KrylovOperator for Chain {
///     fn dim(&self) -> usize { self.0 }
///     fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), LinearSolveError> {
///         for i in 0..self.0 {
///             let left = if i > 0 { x[i - 1] } else { 0.0 };
///             let right = if i + 1 < self.0 { x[i + 1] } else { 0.0 };
///             y[i] = 4.0 * x[i] - left - right;
///         }
///         Ok(())
///     }
///     fn precondition(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), LinearSolveError> {
///         for (yi, xi) in y.iter_mut().zip(x) {
///             *yi = xi / 4.0;
///         }
///         Ok(())
///     }
/// }
/// let b = vec![1.0; 50];
/// let mut x = vec![0.0; 50];
/// let report = Gmres::new().solve(&mut Chain(50), &b, &mut x, &GmresOptions::default()).unwrap();
/// assert!(report.residual_norm <= report.tolerance && report.iterations < 50);
/// ```
pub trait KrylovOperator {
    /// Dimension `n` of the operator.
    fn dim(&self) -> usize;

    /// `y = A x` (`x`, `y` of length [`KrylovOperator::dim`]).
    fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), LinearSolveError>;

    /// `y = M^{-1} x` for a preconditioner `M` (an approximation of `A` that is cheap to
    /// invert); the default is the identity.
    fn precondition(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), LinearSolveError> {
        y.copy_from_slice(x);
        Ok(())
    }
}

/// Stopping rule and memory of [`Gmres`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GmresOptions {
    /// Stop when `|b - A x| <= relative_tolerance |b|` ...
    pub relative_tolerance: f64,
    /// ... or when `|b - A x| <= absolute_tolerance`.
    pub absolute_tolerance: f64,
    /// Krylov vectors kept before a restart (`k` of GMRES(k), at least 1).
    pub restart: usize,
    /// Total operator products allowed (over all restarts).
    pub max_iterations: usize,
}

impl Default for GmresOptions {
    /// Relative tolerance `1e-10`, no absolute tolerance, restart 40, 400 iterations.
    fn default() -> Self {
        Self {
            relative_tolerance: 1e-10,
            absolute_tolerance: 0.0,
            restart: 40,
            max_iterations: 400,
        }
    }
}

/// What one [`Gmres::solve`] did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GmresReport {
    /// Operator products (Arnoldi steps), all restarts together.
    pub iterations: usize,
    /// `|b - A x|_2` at the end (recomputed from `A x`).
    pub residual_norm: f64,
    /// The tolerance `max(relative |b|, absolute)` it was judged against.
    pub tolerance: f64,
}

/// Restarted GMRES with right preconditioning (module documentation). Its workspaces are
/// kept between solves of one size.
#[derive(Debug, Default, Clone)]
pub struct Gmres {
    /// `restart + 1` basis vectors of length `n`, one after the other.
    basis: Vec<f64>,
    /// `M^{-1} v_j` for the first `restart` basis vectors.
    preconditioned: Vec<f64>,
    /// Hessenberg matrix, column-major, `(restart + 1) x restart`.
    hessenberg: Vec<f64>,
    /// Givens rotations `(cos, sin)` per column.
    rotations: Vec<(f64, f64)>,
    /// Right-hand side of the small least-squares problem.
    g: Vec<f64>,
    work: Vec<f64>,
}

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.iter().zip(y).map(|(a, b)| a * b).sum()
}

impl Gmres {
    /// An empty solver (workspaces sized at the first solve).
    pub fn new() -> Self {
        Self::default()
    }

    /// Sizes the small arrays and the first basis vector; the other basis vectors are
    /// added as the iteration reaches them (memory follows the steps actually taken).
    fn size(&mut self, n: usize, restart: usize) {
        if self.basis.len() < n {
            self.basis.resize(n, 0.0);
        }
        self.hessenberg.resize((restart + 1) * restart, 0.0);
        self.rotations.resize(restart, (1.0, 0.0));
        self.g.resize(restart + 1, 0.0);
        self.work.resize(n, 0.0);
    }

    /// Solves `A x = b`, starting from the `x` given (e.g. zeros), `x` overwritten with the
    /// answer. [`LinearSolveError::NotConverged`] when the tolerance is not met within
    /// `options.max_iterations` products (then `x` holds the last iterate);
    /// [`LinearSolveError::NonFiniteEntry`] if a product or the preconditioner gives a
    /// non-finite number.
    pub fn solve<A: KrylovOperator + ?Sized>(
        &mut self,
        a: &mut A,
        b: &[f64],
        x: &mut [f64],
        options: &GmresOptions,
    ) -> Result<GmresReport, LinearSolveError> {
        let n = a.dim();
        for found in [b.len(), x.len()] {
            if found != n {
                return Err(LinearSolveError::DimensionMismatch { expected: n, found });
            }
        }
        let restart = options.restart.max(1);
        self.size(n, restart);
        let tolerance = (options.relative_tolerance * norm(b)).max(options.absolute_tolerance);
        let mut iterations = 0;
        loop {
            // r = b - A x into v_0.
            let (v0, _) = self.basis.split_at_mut(n);
            a.apply(x, v0)?;
            for (r, bi) in v0.iter_mut().zip(b) {
                *r = bi - *r;
            }
            let beta = norm(v0);
            if !beta.is_finite() {
                return Err(LinearSolveError::NonFiniteEntry {
                    row: 0,
                    col: 0,
                    value: beta,
                });
            }
            if beta <= tolerance || n == 0 {
                return Ok(GmresReport {
                    iterations,
                    residual_norm: beta,
                    tolerance,
                });
            }
            if iterations >= options.max_iterations {
                return Err(LinearSolveError::NotConverged {
                    iterations,
                    residual: beta,
                    tolerance,
                });
            }
            v0.iter_mut().for_each(|v| *v /= beta);
            self.g.fill(0.0);
            self.g[0] = beta;
            let mut steps = 0;
            while steps < restart && iterations < options.max_iterations {
                let j = steps;
                let h_next = self.arnoldi(a, j, (n, restart))?;
                iterations += 1;
                self.rotate(j, restart);
                steps += 1;
                // Lucky breakdown: the Krylov space is invariant, the solution is in it.
                if self.g[j + 1].abs() <= tolerance || h_next == 0.0 {
                    break;
                }
            }
            self.correct(x, steps, (n, restart));
        }
    }

    /// Arnoldi step `j`: `w = A M^-1 v_j` (`M^-1 v_j` kept for the correction)
    /// orthogonalised against `v_0..v_j` into `v_{j+1}`, its coefficients into column `j`
    /// of the Hessenberg matrix; `|w|` before the normalisation.
    fn arnoldi<A: KrylovOperator + ?Sized>(
        &mut self,
        a: &mut A,
        j: usize,
        (n, restart): (usize, usize),
    ) -> Result<f64, LinearSolveError> {
        if self.basis.len() < (j + 2) * n {
            self.basis.resize((j + 2) * n, 0.0);
        }
        if self.preconditioned.len() < (j + 1) * n {
            self.preconditioned.resize((j + 1) * n, 0.0);
        }
        let (done, next) = self.basis.split_at_mut((j + 1) * n);
        let vj = &done[j * n..];
        let zj = &mut self.preconditioned[j * n..(j + 1) * n];
        a.precondition(vj, zj)?;
        let w = &mut next[..n];
        a.apply(zj, w)?;
        let column = &mut self.hessenberg[j * (restart + 1)..(j + 1) * (restart + 1)];
        for (i, h) in column.iter_mut().enumerate().take(j + 1) {
            let vi = &done[i * n..(i + 1) * n];
            *h = dot(w, vi);
            for (wk, vk) in w.iter_mut().zip(vi) {
                *wk -= *h * vk;
            }
        }
        let h_next = norm(w);
        if !h_next.is_finite() {
            return Err(LinearSolveError::NonFiniteEntry {
                row: 0,
                col: j,
                value: h_next,
            });
        }
        column[j + 1] = h_next;
        if h_next > 0.0 {
            w.iter_mut().for_each(|v| *v /= h_next);
        }
        Ok(h_next)
    }

    /// The previous Givens rotations on column `j` of the Hessenberg matrix, then a new one
    /// zeroing `column[j + 1]`, applied to `g` too.
    fn rotate(&mut self, j: usize, restart: usize) {
        let column = &mut self.hessenberg[j * (restart + 1)..(j + 1) * (restart + 1)];
        for (i, &(c, s)) in self.rotations.iter().enumerate().take(j) {
            let (hi, hk) = (column[i], column[i + 1]);
            column[i] = c * hi + s * hk;
            column[i + 1] = -s * hi + c * hk;
        }
        let r = column[j].hypot(column[j + 1]);
        let (c, s) = if r == 0.0 {
            (1.0, 0.0)
        } else {
            (column[j] / r, column[j + 1] / r)
        };
        self.rotations[j] = (c, s);
        column[j] = r;
        column[j + 1] = 0.0;
        let gj = self.g[j];
        self.g[j] = c * gj;
        self.g[j + 1] = -s * gj;
    }

    /// The correction of a cycle of `steps` steps: `y = H^-1 g` (upper triangular), then
    /// `x += Z y`.
    fn correct(&mut self, x: &mut [f64], steps: usize, (n, restart): (usize, usize)) {
        for i in (0..steps).rev() {
            let mut v = self.g[i];
            for k in i + 1..steps {
                v -= self.hessenberg[k * (restart + 1) + i] * self.work[k];
            }
            let diag = self.hessenberg[i * (restart + 1) + i];
            self.work[i] = if diag == 0.0 { 0.0 } else { v / diag };
        }
        for k in 0..steps {
            let yk = self.work[k];
            let zk = &self.preconditioned[k * n..(k + 1) * n];
            for (xi, z) in x.iter_mut().zip(zk) {
                *xi += yk * z;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tridiagonal non-symmetric `A` (`2 + shift` on the diagonal, `-1` below, `-0.5` above).
    struct Tridiagonal {
        n: usize,
        shift: f64,
        jacobi: bool,
    }

    impl KrylovOperator for Tridiagonal {
        fn dim(&self) -> usize {
            self.n
        }
        fn apply(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), LinearSolveError> {
            for i in 0..self.n {
                let mut v = (2.0 + self.shift) * x[i];
                if i > 0 {
                    v -= x[i - 1];
                }
                if i + 1 < self.n {
                    v -= 0.5 * x[i + 1];
                }
                y[i] = v;
            }
            Ok(())
        }
        fn precondition(&mut self, x: &[f64], y: &mut [f64]) -> Result<(), LinearSolveError> {
            let d = if self.jacobi { 2.0 + self.shift } else { 1.0 };
            for (yi, xi) in y.iter_mut().zip(x) {
                *yi = xi / d;
            }
            Ok(())
        }
    }

    fn residual(a: &mut Tridiagonal, x: &[f64], b: &[f64]) -> f64 {
        let mut y = vec![0.0; b.len()];
        a.apply(x, &mut y).unwrap();
        norm(&y.iter().zip(b).map(|(p, q)| p - q).collect::<Vec<_>>())
    }

    #[test]
    fn gmres_meets_its_tolerance_with_and_without_restarts() {
        let n = 200;
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        for (restart, jacobi) in [(250, false), (10, true), (5, false)] {
            let mut a = Tridiagonal {
                n,
                shift: 0.3,
                jacobi,
            };
            let mut x = vec![0.0; n];
            let options = GmresOptions {
                relative_tolerance: 1e-11,
                restart,
                max_iterations: 2000,
                ..GmresOptions::default()
            };
            let report = Gmres::new().solve(&mut a, &b, &mut x, &options).unwrap();
            let r = residual(&mut a, &x, &b);
            // The reported residual is the recomputed one, and it meets the tolerance.
            assert!(
                (r - report.residual_norm).abs() <= 1e-14 * norm(&b),
                "{r:e}"
            );
            assert!(r <= 1e-11 * norm(&b), "{r:e}");
        }
    }

    #[test]
    fn an_exhausted_budget_is_a_typed_error_with_the_residual_reached() {
        let n = 100;
        let b = vec![1.0; n];
        let mut a = Tridiagonal {
            n,
            shift: 0.0,
            jacobi: false,
        };
        let mut x = vec![0.0; n];
        let options = GmresOptions {
            relative_tolerance: 1e-14,
            restart: 3,
            max_iterations: 6,
            ..GmresOptions::default()
        };
        match Gmres::new().solve(&mut a, &b, &mut x, &options) {
            Err(LinearSolveError::NotConverged {
                iterations,
                residual,
                tolerance,
            }) => {
                assert_eq!(iterations, 6);
                assert!(residual > tolerance && residual < norm(&b));
            }
            other => panic!("{other:?}"),
        }
    }
}
