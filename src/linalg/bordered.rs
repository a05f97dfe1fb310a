//! A matrix bordered by a few rows and columns, solved by block elimination with one
//! factorization of its inner block.

use super::norm2;
use super::LinearSolveError;
use crate::{Factorize, LinearSolve};

/// Default relative size below which a pivot of the Schur complement is treated as zero
/// (see [`BorderedSolver`]).
pub const DEFAULT_BORDER_PIVOT_THRESHOLD: f64 = 1e-12;

/// Why a bordered factorization or solve could not be carried out.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum BorderedError {
    /// The inner matrix `J` could not be factored.
    #[error("factoring the inner matrix: {0}")]
    Factorization(LinearSolveError),
    /// A solve with the factorization of `J` failed.
    #[error("solving with the inner matrix: {0}")]
    Solve(LinearSolveError),
    /// A pivot of the Schur complement `S = D - C^T J^{-1} B` is negligible against the
    /// size of its terms: the bordered matrix is singular (or nearly) although `J` is not.
    #[error(
        "singular border: Schur complement pivot {pivot:e} at index {index} is negligible against the scale {scale:e} of its terms"
    )]
    SingularBorder {
        /// Position of the pivot in the Schur complement's LU (`0..k`).
        index: usize,
        /// The pivot (signed).
        pivot: f64,
        /// `max_ij |D_ij| + |C_i| |X_j|`, the scale the pivot is measured against.
        scale: f64,
    },
    /// A solution of the inner matrix (`J^{-1} B` or `J^{-1} f`) has an entry that is not
    /// finite.
    #[error("a solve with the inner matrix gave a value that is not finite")]
    NonFinite,
    /// A border or right-hand side does not have the size the solver was built for.
    #[error("{what} has {found} entries, expected {expected}")]
    DimensionMismatch {
        /// Which argument.
        what: &'static str,
        /// Entries expected.
        expected: usize,
        /// Entries received.
        found: usize,
    },
}

/// Work done through a [`BorderedSolver`]: inner factorizations attempted and inner
/// right-hand sides solved (`k` per border, one per bordered solve).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct BorderedCounters {
    /// Factorizations of the inner matrix `J` ([`BorderedSolver::factor`]).
    pub factorizations: u64,
    /// Right-hand sides solved with the factorization of `J`.
    pub solves: u64,
}

/// Block elimination for the bordered system
///
/// ```text
/// [[J,   B], [x]   [f]        J: n x n (any Factorize<J> solver),
///  [C^T, D]] [p] = [g],       B, C: n x k,  D: k x k,  k small (1-3).
/// ```
///
/// With one factorization of `J` and `k + 1` solves: `J X = B` (once per border),
/// the Schur complement `S = D - C^T X` factored by a dense LU with partial pivoting, then
/// per right-hand side `J y = f`, `p = S^{-1} (g - C^T y)`, `x = y - X p`. It needs `J`
/// regular: where `J` is singular or nearly so (a fold) and the bordered matrix is not,
/// its accuracy is that of the inner solves (Govaerts, *Numerical methods for bifurcations
/// of dynamical equilibria*, 2000, ch. 3), and a caller may fall back to a dense LU of the
/// assembled matrix, as the continuation does. A pivot
/// `|u_ii| <= threshold * max_ij (|D_ij| + |C_i| |X_j|)` of the LU of `S` is
/// [`BorderedError::SingularBorder`]. `B`, `C` and the right-hand sides are stored column
/// by column (column-major), `D` column-major too; all storage is allocated by
/// [`BorderedSolver::new`] and reused.
///
/// The inner solver is passed to every call, so that a caller keeps its own (dense,
/// sparse, structured); [`BorderedSolver::solve`] must be given the solver that
/// [`BorderedSolver::factor`] factored.
///
/// ```
/// use faer::Mat;
/// use semismooth::linalg::{BorderedSolver, FaerDenseLu};
/// // [[2, 0, 1], [0, 4, 1], [1, 1, 0]] [x0, x1, p] = [3, 5, 2]: x = (1, 1), p = 1.
/// let j = Mat::from_fn(2, 2, |i, k| if i == k { 2.0 * (i + 1) as f64 } else { 0.0 });
/// let (b, c, d) = ([1.0, 1.0], [1.0, 1.0], [0.0]);
/// let (mut lu, mut bordered) = (FaerDenseLu::new(), BorderedSolver::new(2, 1));
/// bordered.factor(&mut lu, &j, &b, &c, &d).unwrap();
/// let (mut f, mut g) = ([3.0, 5.0], [2.0]);
/// bordered.solve(&mut lu, &mut f, &mut g).unwrap();
/// assert!((f[0] - 1.0).abs() < 1e-15 && (f[1] - 1.0).abs() < 1e-15 && (g[0] - 1.0).abs() < 1e-15);
/// // One factorization of J, k + 1 = 2 solves.
/// assert_eq!((bordered.counters().factorizations, bordered.counters().solves), (1, 2));
/// ```
#[derive(Debug, Clone)]
pub struct BorderedSolver {
    n: usize,
    k: usize,
    /// `X = J^{-1} B`, n x k.
    x: Vec<f64>,
    /// `C`, n x k (a copy: the solves need it).
    c: Vec<f64>,
    /// `S = D - C^T X` as formed, k x k.
    schur: Vec<f64>,
    /// LU factors of `P S` (unit lower part below the diagonal).
    lu: Vec<f64>,
    /// Row `i` of `P S` is row `perm[i]` of `S`.
    perm: Vec<usize>,
    /// `P (g - C^T y)`, then the border unknowns `p`.
    r: Vec<f64>,
    factored: bool,
    pivot_threshold: f64,
    counters: BorderedCounters,
}

impl BorderedSolver {
    /// A solver for an `n x n` inner matrix bordered by `k` rows and columns, with the pivot
    /// threshold [`DEFAULT_BORDER_PIVOT_THRESHOLD`].
    pub fn new(n: usize, k: usize) -> Self {
        Self {
            n,
            k,
            x: vec![0.0; n * k],
            c: vec![0.0; n * k],
            schur: vec![0.0; k * k],
            lu: vec![0.0; k * k],
            perm: (0..k).collect(),
            r: vec![0.0; k],
            factored: false,
            pivot_threshold: DEFAULT_BORDER_PIVOT_THRESHOLD,
            counters: BorderedCounters::default(),
        }
    }

    /// The same solver with the Schur complement's relative pivot threshold `threshold`.
    pub fn with_pivot_threshold(self, threshold: f64) -> Self {
        Self {
            pivot_threshold: threshold,
            ..self
        }
    }

    /// Factors `jac` with `inner`, then the border ([`BorderedSolver::factor_border`]).
    /// After an error the solver holds no factorization.
    pub fn factor<J: ?Sized, S: Factorize<J> + ?Sized>(
        &mut self,
        inner: &mut S,
        jac: &J,
        b: &[f64],
        c: &[f64],
        d: &[f64],
    ) -> Result<(), BorderedError> {
        self.factored = false;
        self.counters.factorizations += 1;
        inner.factor(jac).map_err(BorderedError::Factorization)?;
        self.factor_border(inner, b, c, d)
    }

    /// A new border `(B, C, D)` with the factorization `inner` already holds (of the `J`
    /// last given to [`BorderedSolver::factor`], or factored by the caller): `k` solves
    /// `J X = B` and the LU of `S = D - C^T X`, no factorization of `J`.
    pub fn factor_border<S: LinearSolve + ?Sized>(
        &mut self,
        inner: &mut S,
        b: &[f64],
        c: &[f64],
        d: &[f64],
    ) -> Result<(), BorderedError> {
        self.factored = false;
        let (n, k) = (self.n, self.k);
        check_len("B", n * k, b.len())?;
        check_len("C", n * k, c.len())?;
        check_len("D", k * k, d.len())?;
        self.x.copy_from_slice(b);
        self.c.copy_from_slice(c);
        self.counters.solves += k as u64;
        inner
            .solve_columns_in_place(&mut self.x, k)
            .map_err(BorderedError::Solve)?;
        if !all_finite(&self.x) {
            return Err(BorderedError::NonFinite);
        }
        let mut scale = 0.0_f64;
        for j in 0..k {
            let xj = &self.x[j * n..(j + 1) * n];
            for i in 0..k {
                let ci = &self.c[i * n..(i + 1) * n];
                let entry = d[i + j * k];
                self.schur[i + j * k] = entry - dot(ci, xj);
                scale = scale.max(entry.abs() + norm2(ci) * norm2(xj));
            }
        }
        self.lu.copy_from_slice(&self.schur);
        lu_in_place(&mut self.lu, &mut self.perm, k, self.pivot_threshold, scale)?;
        self.factored = true;
        Ok(())
    }

    /// Solves the bordered system in place: `f` (n entries) becomes `x`, `g` (k entries)
    /// becomes `p`, with one solve of `inner` (which must hold the factorization of `J`).
    pub fn solve<S: LinearSolve + ?Sized>(
        &mut self,
        inner: &mut S,
        f: &mut [f64],
        g: &mut [f64],
    ) -> Result<(), BorderedError> {
        let (n, k) = (self.n, self.k);
        if !self.factored {
            return Err(BorderedError::Solve(LinearSolveError::NotFactored));
        }
        check_len("f", n, f.len())?;
        check_len("g", k, g.len())?;
        self.counters.solves += 1;
        inner.solve_in_place(f).map_err(BorderedError::Solve)?;
        if !all_finite(f) {
            return Err(BorderedError::NonFinite);
        }
        // r = P (g - C^T y), then p = U^{-1} L^{-1} r.
        for (ri, &row) in self.r.iter_mut().zip(&self.perm) {
            *ri = g[row] - dot(&self.c[row * n..(row + 1) * n], f);
        }
        substitute(&self.lu, k, &mut self.r);
        g.copy_from_slice(&self.r);
        for (j, pj) in g.iter().enumerate() {
            for (fi, xi) in f.iter_mut().zip(&self.x[j * n..(j + 1) * n]) {
                *fi -= xi * pj;
            }
        }
        Ok(())
    }

    /// `X = J^{-1} B` of the last border (n x k, column-major); its columns, with `-I`
    /// below, span the kernel of `[J, B]`.
    pub fn inner_solution(&self) -> &[f64] {
        &self.x
    }

    /// The Schur complement `S = D - C^T J^{-1} B` of the last border (k x k,
    /// column-major), as formed before its factorization.
    pub fn schur_complement(&self) -> &[f64] {
        &self.schur
    }

    /// The work done so far.
    pub fn counters(&self) -> BorderedCounters {
        self.counters
    }

    /// `(n, k)`: the inner dimension and the width of the border.
    pub fn dims(&self) -> (usize, usize) {
        (self.n, self.k)
    }
}

fn check_len(what: &'static str, expected: usize, found: usize) -> Result<(), BorderedError> {
    if expected == found {
        Ok(())
    } else {
        Err(BorderedError::DimensionMismatch {
            what,
            expected,
            found,
        })
    }
}

fn all_finite(v: &[f64]) -> bool {
    v.iter().all(|u| u.is_finite())
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(u, v)| u * v).sum()
}

/// LU with partial pivoting of the k x k column-major `a` in place (`P a = L U`); a pivot
/// `|u_jj| <= threshold * scale` (or not finite) is [`BorderedError::SingularBorder`].
fn lu_in_place(
    a: &mut [f64],
    perm: &mut [usize],
    k: usize,
    threshold: f64,
    scale: f64,
) -> Result<(), BorderedError> {
    for (i, p) in perm.iter_mut().enumerate() {
        *p = i;
    }
    for j in 0..k {
        let row = (j..k)
            .max_by(|&s, &t| a[s + j * k].abs().total_cmp(&a[t + j * k].abs()))
            .unwrap_or(j);
        if row != j {
            perm.swap(row, j);
            for col in 0..k {
                a.swap(row + col * k, j + col * k);
            }
        }
        let pivot = a[j + j * k];
        if !pivot.is_finite() || pivot.abs() <= threshold * scale {
            return Err(BorderedError::SingularBorder {
                index: j,
                pivot,
                scale,
            });
        }
        for i in j + 1..k {
            a[i + j * k] /= pivot;
            let l = a[i + j * k];
            for col in j + 1..k {
                a[i + col * k] -= l * a[j + col * k];
            }
        }
    }
    Ok(())
}

/// `r <- U^{-1} L^{-1} r` with the factors of [`lu_in_place`] (`r` already permuted).
fn substitute(lu: &[f64], k: usize, r: &mut [f64]) {
    for i in 0..k {
        for j in 0..i {
            r[i] -= lu[i + j * k] * r[j];
        }
    }
    for i in (0..k).rev() {
        for j in i + 1..k {
            r[i] -= lu[i + j * k] * r[j];
        }
        r[i] /= lu[i + i * k];
    }
}
