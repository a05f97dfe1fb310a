//! Lemke's complementary pivoting algorithm for the linear complementarity problem
//!
//! ```text
//! LCP(q, M):  find z such that  w = q + M z,  w >= 0,  z >= 0,  w . z = 0.
//! ```
//!
//! # Algorithm
//!
//! Lemke's method (Lemke 1965; Cottle, Pang & Stone, *The Linear Complementarity
//! Problem*, 1992, §4.4; Murty, *Linear Complementarity, Linear and Nonlinear
//! Programming*, 1988, ch. 2) works on the augmented system
//! `w - M z - d z0 = q` with an artificial variable `z0 >= 0` and a covering vector
//! `d > 0` (all ones by default, [`LemkeOptions::covering`] to change it). Starting from
//! `w = q + d z0`, `z = 0` with the smallest feasible `z0`, it pivots along a path of
//! almost-complementary basic solutions: the complement of the variable that just left
//! the basis enters next. It stops when
//! - `z0` leaves the basis: `z` solves the LCP ([`LemkeTermination::Solved`]);
//! - the entering column has no positive entry, so nothing blocks the entering variable
//!   (a *secondary ray*, [`LemkeTermination::Ray`]). For copositive-plus `M` (e.g.
//!   positive semidefinite) this proves that the LCP has no solution; for other `M` it
//!   means only that Lemke's method did not find one;
//! - the pivot limit is reached ([`LemkeTermination::PivotLimit`]).
//!
//! If `q >= 0`, `z = 0` is a solution and no pivot is made.
//!
//! Degenerate pivots are resolved by the **lexicographic minimum-ratio test**: among the
//! rows `i` tied on the ratio `x_i / t_i` (basic value over entering-column entry), the
//! row minimising `(B^{-1})_{i,:} / t_i` lexicographically leaves. This keeps every row of
//! `[x, B^{-1}]` lexicographically positive, so no basis repeats and the method cannot
//! cycle. Ties are decided with a scale-aware tolerance (see [`LemkeOptions::tolerance`]);
//! when `z0` is among the rows tied on the ratio it leaves at once (termination).
//!
//! # Implementation
//!
//! A *revised* tableau: the workspace keeps the explicit basis inverse `B^{-1}` (dense,
//! column-major, `n x n`, allocated once in [`Lemke::new`]) and the basic values `x`.
//! Column `l` of `B^{-1}` is the unit vector `e_r` while `w_l` is basic in row `r`, so
//! only the `k` columns of non-basic `w` are dense. The entering column `B^{-1} a` and
//! the rank-1 (Gauss–Jordan) update of `B^{-1}` then cost `O(n k)` each, column by
//! column, instead of the `O(n^2)` of a full tableau; no pivot allocates.
//! When `z0` leaves, two steps of iterative refinement with the final basis polish `z`;
//! `w` is then recomputed as `q + M z` from the original data, and the a-posteriori
//! complementarity error `max_i |min(z_i, w_i)|` (which also measures any negativity of
//! `z` or `w`) is reported after every solve, whatever the outcome.
//!
//! ```
//! use faer::Mat;
//! use semismooth::lemke::{Lemke, LemkeOptions, LemkeTermination};
//! // M = [[2, 1], [1, 2]], q = [-5, -6]: solution z = [4/3, 7/3], w = 0.
//! let m = Mat::from_fn(2, 2, |i, j| if i == j { 2.0 } else { 1.0 });
//! let mut lemke = Lemke::new(2);
//! let report = lemke.solve(m.as_ref(), &[-5.0, -6.0], &LemkeOptions::default()).unwrap();
//! assert_eq!(report.termination, LemkeTermination::Solved);
//! assert!((report.z[0] - 4.0 / 3.0).abs() < 1e-14 && (report.z[1] - 7.0 / 3.0).abs() < 1e-14);
//! assert!(report.complementarity_error < 1e-14);
//! ```

use faer::MatRef;

use crate::linalg::{check_finite_dense, LinearSolveError};
use crate::InvalidOption;

/// Marker for "not in the basis" in the row-of-variable map.
const NONBASIC: usize = usize::MAX;

/// Number of iterative-refinement steps applied to a solved basis.
const REFINEMENT_STEPS: usize = 2;

/// Pivots per unknown of the default pivot limit `50 n + 100`.
pub const PIVOTS_PER_UNKNOWN: usize = 50;
/// Pivots on top of [`PIVOTS_PER_UNKNOWN`] `n` in the default pivot limit `50 n + 100`.
pub const EXTRA_PIVOTS: usize = 100;

/// Options of [`Lemke::solve`]. Every field has a default ([`LemkeOptions::default`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LemkeOptions {
    /// Maximum number of pivots, the initial pivot on `z0` included.
    /// `None` (default) means `50 n + 100` ([`PIVOTS_PER_UNKNOWN`], [`EXTRA_PIVOTS`]). Lemke's path is short for P-matrices met in
    /// practice but can be very long otherwise (measured: the periodic LCP of a rod with
    /// a massive contact node, `n = 512`, still running after 5 million pivots while `z0`
    /// decreased slowly and steadily, no cycling); the limit turns that into
    /// [`LemkeTermination::PivotLimit`].
    pub max_pivots: Option<usize>,
    /// Relative tolerance, in `(0, 1)`; default `1e-12`. An entering-column entry `t_i`
    /// can block only if `t_i > tolerance * max_j |t_j|`; two ratios `x_i / t_i` count as
    /// tied when they differ by at most `tolerance * (max_j |x_j| / t_i + |min ratio|)`,
    /// and likewise in the lexicographic tie-break, with the largest entry of the
    /// `B^{-1}` column in place of `max_j |x_j|`.
    pub tolerance: f64,
    /// Covering vector `d` of the artificial variable (`w = q + M z + d z0`); every entry
    /// finite and `> 0`, length `n`. `None` (default) means all ones.
    pub covering: Option<Vec<f64>>,
}

impl Default for LemkeOptions {
    fn default() -> Self {
        Self {
            max_pivots: None,
            tolerance: 1e-12,
            covering: None,
        }
    }
}

impl LemkeOptions {
    /// Checks the options that do not depend on the problem size: `tolerance` in `(0, 1)`,
    /// covering entries finite and `> 0`.
    pub fn validate(&self) -> Result<(), LemkeError> {
        if !(self.tolerance > 0.0 && self.tolerance < 1.0) {
            return Err(LemkeError::InvalidOption(InvalidOption::new(
                "tolerance",
                self.tolerance,
                "finite, in (0, 1)",
            )));
        }
        if let Some(d) = &self.covering {
            if let Some((index, &value)) = d
                .iter()
                .enumerate()
                .find(|(_, v)| !(v.is_finite() && **v > 0.0))
            {
                return Err(LemkeError::InvalidCovering { index, value });
            }
        }
        Ok(())
    }

    /// The pivot limit used for an LCP of size `n`: `max_pivots`, or `50 n + 100`.
    ///
    /// ```
    /// use semismooth::lemke::LemkeOptions;
    /// let default = LemkeOptions::default();
    /// assert_eq!(default.pivot_limit(128), 6500);
    /// assert_eq!(default.pivot_limit_rule(), "50 n + 100");
    /// let set = LemkeOptions { max_pivots: Some(7), ..LemkeOptions::default() };
    /// assert_eq!((set.pivot_limit(128), set.pivot_limit_rule().as_str()), (7, "max_pivots"));
    /// ```
    pub fn pivot_limit(&self, n: usize) -> usize {
        self.max_pivots.unwrap_or_else(|| {
            n.saturating_mul(PIVOTS_PER_UNKNOWN)
                .saturating_add(EXTRA_PIVOTS)
        })
    }

    /// How [`LemkeOptions::pivot_limit`] is set, in words: `50 n + 100` by default,
    /// `max_pivots` when given.
    pub fn pivot_limit_rule(&self) -> String {
        match self.max_pivots {
            None => format!("{PIVOTS_PER_UNKNOWN} n + {EXTRA_PIVOTS}"),
            Some(_) => "max_pivots".to_string(),
        }
    }
}

/// How a run of Lemke's method ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum LemkeTermination {
    /// The artificial variable left the basis (or `q >= 0`): `z` solves the LCP up to the
    /// reported complementarity error.
    Solved,
    /// Secondary ray: the entering variable ([`LemkeReport::ray_entering`]) is not blocked
    /// by any basic variable. For copositive-plus `M` the LCP has no solution.
    Ray,
    /// [`LemkeOptions::max_pivots`] pivots were made without reaching either end.
    PivotLimit,
}

/// A variable of the augmented LCP `w - M z - d z0 = q`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LcpVariable {
    /// The slack `w_i`.
    W(usize),
    /// The unknown `z_i`.
    Z(usize),
    /// The artificial variable `z0`.
    Artificial,
}

/// The outcome of one run of [`Lemke::solve`].
///
/// Whatever the termination, `z` is the `z`-part of the last basic solution (`z0`
/// dropped), `w = q + M z` is recomputed from the original data, and
/// `complementarity_error = max_i |min(z_i, w_i)|`.
#[derive(Clone, Debug, PartialEq)]
pub struct LemkeReport {
    /// Why the pivoting stopped.
    pub termination: LemkeTermination,
    /// The unknowns `z` (length `n`).
    pub z: Vec<f64>,
    /// The slacks `w = q + M z`, recomputed from `q` and `M` (length `n`).
    pub w: Vec<f64>,
    /// Number of pivots made, the initial pivot on `z0` included.
    pub pivots: usize,
    /// A-posteriori error `max_i |min(z_i, w_i)|` (absolute; 0 for an exact solution).
    pub complementarity_error: f64,
    /// Value of the artificial variable `z0` at termination (0 when solved).
    pub artificial: f64,
    /// On [`LemkeTermination::Ray`], the entering variable that nothing blocked.
    pub ray_entering: Option<LcpVariable>,
}

impl LemkeReport {
    /// `true` when the run ended with [`LemkeTermination::Solved`].
    pub fn solved(&self) -> bool {
        self.termination == LemkeTermination::Solved
    }

    /// `Ok(self)` when solved, otherwise [`LemkeError::NotSolved`] with the numbers.
    pub fn into_result(self) -> Result<Self, LemkeError> {
        if self.solved() {
            Ok(self)
        } else {
            Err(LemkeError::NotSolved {
                termination: self.termination,
                pivots: self.pivots,
                complementarity_error: self.complementarity_error,
            })
        }
    }
}

/// Why [`Lemke::solve`] could not run (or, from [`LemkeReport::into_result`], did not
/// solve).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LemkeError {
    /// `M` is not square, or `q` / the covering vector does not have length `n`.
    #[error("dimension mismatch in {what}: expected {expected}, found {found}")]
    DimensionMismatch {
        /// Which input: `"columns of M"`, `"q"` or `"covering"`.
        what: &'static str,
        /// Expected length (the number of rows of `M`).
        expected: usize,
        /// Length received.
        found: usize,
    },
    /// `M` holds a NaN or infinite entry.
    #[error("M[({row}, {col})] is not finite ({value})")]
    NonFiniteMatrixEntry {
        /// Row of the entry.
        row: usize,
        /// Column of the entry.
        col: usize,
        /// The value found.
        value: f64,
    },
    /// `q` holds a NaN or infinite entry.
    #[error("{name}[{index}] is not finite ({value})")]
    NonFiniteVectorEntry {
        /// Which vector (`"q"`).
        name: &'static str,
        /// Index of the entry.
        index: usize,
        /// The value found.
        value: f64,
    },
    /// A scalar option is out of range.
    #[error("invalid option {0}")]
    InvalidOption(#[from] InvalidOption),
    /// An entry of the covering vector is not finite and positive.
    #[error("covering vector entry d[{index}] = {value}: must be finite and > 0")]
    InvalidCovering {
        /// Index of the entry.
        index: usize,
        /// The value given.
        value: f64,
    },
    /// The pivoting produced a non-finite basic value (overflow on a badly scaled
    /// problem); the run was abandoned.
    #[error("numerical breakdown after {pivots} pivots: non-finite value in basis row {row}")]
    NumericalBreakdown {
        /// Pivots made before the breakdown.
        pivots: usize,
        /// Basis row holding the non-finite value.
        row: usize,
    },
    /// From [`LemkeReport::into_result`]: the run ended on a ray or the pivot limit.
    #[error(
        "Lemke's method did not solve the LCP: {termination:?} after {pivots} pivots \
         (complementarity error {complementarity_error:e})"
    )]
    NotSolved {
        /// How the run ended.
        termination: LemkeTermination,
        /// Pivots made.
        pivots: usize,
        /// A-posteriori complementarity error of the last iterate.
        complementarity_error: f64,
    },
}

/// Lemke's method with a reusable workspace (basis inverse and index maps).
///
/// Allocate once with [`Lemke::new`] and call [`Lemke::solve`] as often as needed; a
/// problem of another size resizes the workspace once. The pivot loop allocates nothing.
#[derive(Clone, Debug)]
pub struct Lemke {
    n: usize,
    /// Basis inverse `B^{-1}`, `n x n`, column-major.
    binv: Vec<f64>,
    /// Basic values `x = B^{-1} q` by basis row.
    x: Vec<f64>,
    /// Entering column `B^{-1} a_e`.
    col: Vec<f64>,
    /// A column of `M`.
    mcol: Vec<f64>,
    /// Refinement correction.
    dx: Vec<f64>,
    /// Entering column of the next pivot, when computed during the update.
    next: Vec<f64>,
    /// Covering vector.
    d: Vec<f64>,
    /// Variable basic in each row (`w_i = i`, `z_j = n + j`, `z0 = 2 n`).
    basis: Vec<usize>,
    /// Row of each variable, or `NONBASIC`.
    row_of: Vec<usize>,
    /// Indices `l` with `w_l` non-basic (the dense columns of `B^{-1}`).
    nonbasic_w: Vec<usize>,
    /// Position of `l` in `nonbasic_w`, or `NONBASIC`.
    nonbasic_slot: Vec<usize>,
    /// Candidate rows of the ratio test.
    ties: Vec<usize>,
}

/// `Err` when Lemke's method cannot run on `M`, `q` with `options` ([`Lemke::solve`]).
fn check_input(m: MatRef<'_, f64>, q: &[f64], options: &LemkeOptions) -> Result<(), LemkeError> {
    options.validate()?;
    let n = m.nrows();
    if m.ncols() != n {
        return Err(LemkeError::DimensionMismatch {
            what: "columns of M",
            expected: n,
            found: m.ncols(),
        });
    }
    if q.len() != n {
        return Err(LemkeError::DimensionMismatch {
            what: "q",
            expected: n,
            found: q.len(),
        });
    }
    if let Some(d) = &options.covering {
        if d.len() != n {
            return Err(LemkeError::DimensionMismatch {
                what: "covering",
                expected: n,
                found: d.len(),
            });
        }
    }
    if let Some((index, &value)) = q.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(LemkeError::NonFiniteVectorEntry {
            name: "q",
            index,
            value,
        });
    }
    if let Err(LinearSolveError::NonFiniteEntry { row, col, value }) =
        check_finite_dense(n, n, |i, j| m[(i, j)])
    {
        return Err(LemkeError::NonFiniteMatrixEntry { row, col, value });
    }
    Ok(())
}

impl Lemke {
    /// A workspace for LCPs of size `n` (about `n^2` doubles).
    pub fn new(n: usize) -> Self {
        let mut lemke = Self {
            n: 0,
            binv: Vec::new(),
            x: Vec::new(),
            col: Vec::new(),
            mcol: Vec::new(),
            dx: Vec::new(),
            next: Vec::new(),
            d: Vec::new(),
            basis: Vec::new(),
            row_of: Vec::new(),
            nonbasic_w: Vec::new(),
            nonbasic_slot: Vec::new(),
            ties: Vec::new(),
        };
        lemke.resize(n);
        lemke
    }

    /// The size `n` the workspace is currently allocated for.
    pub fn dim(&self) -> usize {
        self.n
    }

    fn resize(&mut self, n: usize) {
        self.n = n;
        self.binv = vec![0.0; n * n];
        self.x = vec![0.0; n];
        self.col = vec![0.0; n];
        self.mcol = vec![0.0; n];
        self.dx = vec![0.0; n];
        self.next = vec![0.0; n];
        self.d = vec![1.0; n];
        self.basis = vec![0; n];
        self.row_of = vec![NONBASIC; 2 * n + 1];
        self.nonbasic_w = Vec::with_capacity(n);
        self.nonbasic_slot = vec![NONBASIC; n];
        self.ties = Vec::with_capacity(n);
    }

    /// Solves `w = q + M z, w >= 0, z >= 0, w . z = 0` by Lemke's method.
    ///
    /// `Ok` whenever the method ran (solved, ray or pivot limit: see
    /// [`LemkeReport::termination`]); `Err` when it cannot run: `M` not square or `q` of
    /// the wrong length, a non-finite entry in `M` or `q`, invalid options.
    pub fn solve(
        &mut self,
        m: MatRef<'_, f64>,
        q: &[f64],
        options: &LemkeOptions,
    ) -> Result<LemkeReport, LemkeError> {
        check_input(m, q, options)?;
        let n = m.nrows();
        if n != self.n {
            self.resize(n);
        }
        let limit = options.pivot_limit(n);
        let tol = options.tolerance;

        self.start_basis(q, options);

        if q.iter().all(|&v| v >= 0.0) {
            return Ok(self.finish(m, q, LemkeTermination::Solved, 0, None));
        }
        if limit == 0 {
            return Ok(self.finish(m, q, LemkeTermination::PivotLimit, 0, None));
        }

        // Initial pivot: z0 enters with column -d; the row leaving is the lexicographic
        // minimum of [q_i, e_i] / d_i (the most negative q_i / d_i).
        let artificial = 2 * n;
        self.ties.clear();
        self.ties.extend(0..n);
        let r = self.leaving_row(true, tol, NONBASIC);
        for (c, d) in self.col.iter_mut().zip(&self.d) {
            *c = -d;
        }
        let (mut leaving, mut ready) = self.pivot(m, r, artificial);
        let mut pivots = 1;
        if let Some(row) = self.x.iter().position(|v| !v.is_finite()) {
            return Err(LemkeError::NumericalBreakdown { pivots, row });
        }

        loop {
            let entering = complement(leaving, n);
            if pivots >= limit {
                return Ok(self.finish(m, q, LemkeTermination::PivotLimit, pivots, None));
            }
            if ready {
                std::mem::swap(&mut self.col, &mut self.next);
            } else {
                self.entering_column(m, entering);
            }
            let tmax = self.col.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
            let threshold = tol * tmax;
            self.ties.clear();
            for (i, &t) in self.col.iter().enumerate() {
                if t > threshold {
                    self.ties.push(i);
                }
            }
            if self.ties.is_empty() {
                let variable = variable(entering, n);
                return Ok(self.finish(m, q, LemkeTermination::Ray, pivots, Some(variable)));
            }
            let r = self.leaving_row(false, tol, self.row_of[artificial]);
            (leaving, ready) = self.pivot(m, r, entering);
            pivots += 1;
            if let Some(row) = self.x.iter().position(|v| !v.is_finite()) {
                return Err(LemkeError::NumericalBreakdown { pivots, row });
            }
            if leaving == artificial {
                self.refine(m, q);
                return Ok(self.finish(m, q, LemkeTermination::Solved, pivots, None));
            }
        }
    }

    /// The start of a solve: the basis of all `w`, `B^{-1} = I`, `x = q` and the covering
    /// vector of `options` (ones by default).
    fn start_basis(&mut self, q: &[f64], options: &LemkeOptions) {
        let n = self.n;
        self.binv.fill(0.0);
        for i in 0..n {
            self.binv[i * n + i] = 1.0;
            self.basis[i] = i;
        }
        self.x.copy_from_slice(q);
        self.row_of.fill(NONBASIC);
        for i in 0..n {
            self.row_of[i] = i;
        }
        self.nonbasic_w.clear();
        self.nonbasic_slot.fill(NONBASIC);
        match &options.covering {
            Some(d) => self.d.copy_from_slice(d),
            None => self.d.fill(1.0),
        }
    }

    /// The lexicographic minimum-ratio test over the candidate rows in `self.ties`:
    /// for the initial pivot on `z0` (`initial`), divisor `d` and raw `x = q`; otherwise
    /// divisor the entering column and `x` clamped at 0. See [`lex_min_ratio`].
    fn leaving_row(&mut self, initial: bool, tol: f64, prefer: usize) -> usize {
        let ratio = RatioTest {
            x: &self.x,
            binv: &self.binv,
            n: self.n,
            divisor: if initial { &self.d } else { &self.col },
            tol,
            prefer,
            clamp: !initial,
        };
        lex_min_ratio(&mut self.ties, &ratio)
    }

    /// Writes `B^{-1} a_e` into `self.col` for the entering variable `e` (`w_i` or `z_j`).
    fn entering_column(&mut self, m: MatRef<'_, f64>, entering: usize) {
        let n = self.n;
        if entering < n {
            // a = e_i: column i of B^{-1}.
            self.col
                .copy_from_slice(&self.binv[entering * n..(entering + 1) * n]);
            return;
        }
        // a = -M[:, j]: B^{-1} a = -sum_l B^{-1}[:, l] M[l, j]; columns of basic w_l are
        // unit vectors, the others dense.
        let j = entering - n;
        copy_column(m, j, &mut self.mcol);
        self.col.fill(0.0);
        for l in 0..n {
            let row = self.row_of[l];
            if row != NONBASIC {
                self.col[row] -= self.mcol[l];
            }
        }
        for &l in &self.nonbasic_w {
            let s = self.mcol[l];
            if s != 0.0 {
                let b = &self.binv[l * n..(l + 1) * n];
                for (c, bv) in self.col.iter_mut().zip(b) {
                    *c -= s * bv;
                }
            }
        }
    }

    /// Pivots `entering` into basis row `r` (entering column in `self.col`); returns the
    /// variable that left, and whether the entering column of the next pivot is ready in
    /// `self.next`: when `w_j` leaves, `z_j` enters next, and its column
    /// `-B^{-1} M[:, j]` is accumulated while the updated columns of `B^{-1}` are still in
    /// cache (one pass over the dense part of `B^{-1}` per pivot instead of two).
    fn pivot(&mut self, m: MatRef<'_, f64>, r: usize, entering: usize) -> (usize, bool) {
        let n = self.n;
        let leaving = self.basis[r];
        let tr = self.col[r];

        // Basic values: x <- x - theta t, x_r <- theta.
        let theta = self.x[r] / tr;
        for (x, t) in self.x.iter_mut().zip(&self.col) {
            *x -= theta * t;
        }
        self.x[r] = theta;

        let fuse = leaving < n;
        if fuse {
            copy_column(m, leaving, &mut self.mcol);
            self.next.fill(0.0);
        }

        // B^{-1} <- B^{-1} - (t - e_r) (row r of B^{-1}) / t_r, column by column over the
        // columns where row r is non-zero: the non-basic w columns and, if the leaving
        // variable is w_l, its unit column e_r. Fused: next -= M[l, j] * (new column l)
        // for every column that stays dense.
        let Self {
            binv,
            col,
            mcol,
            next,
            nonbasic_w,
            ..
        } = &mut *self;
        let mut update = |l: usize| {
            let b = &mut binv[l * n..(l + 1) * n];
            let s = b[r] / tr;
            let c = if fuse && l != entering { mcol[l] } else { 0.0 };
            if s != 0.0 {
                if c != 0.0 {
                    for ((bv, t), nx) in b.iter_mut().zip(col.iter()).zip(next.iter_mut()) {
                        *bv -= s * t;
                        *nx -= c * *bv;
                    }
                    let after = b[r];
                    b[r] = s;
                    next[r] -= c * (s - after);
                } else {
                    for (bv, t) in b.iter_mut().zip(col.iter()) {
                        *bv -= s * t;
                    }
                    b[r] = s;
                }
            } else if c != 0.0 {
                for (nx, bv) in next.iter_mut().zip(b.iter()) {
                    *nx -= c * bv;
                }
            }
        };
        for &l in nonbasic_w.iter() {
            update(l);
        }
        if leaving < n {
            update(leaving);
        }

        // Index bookkeeping.
        if entering < n {
            // w_i re-enters: its column of B^{-1} is exactly e_r again.
            let b = &mut self.binv[entering * n..(entering + 1) * n];
            b.fill(0.0);
            b[r] = 1.0;
            let slot = self.nonbasic_slot[entering];
            self.nonbasic_w.swap_remove(slot);
            if let Some(&moved) = self.nonbasic_w.get(slot) {
                self.nonbasic_slot[moved] = slot;
            }
            self.nonbasic_slot[entering] = NONBASIC;
        }
        if leaving < n {
            self.nonbasic_slot[leaving] = self.nonbasic_w.len();
            self.nonbasic_w.push(leaving);
        }
        self.basis[r] = entering;
        self.row_of[entering] = r;
        self.row_of[leaving] = NONBASIC;

        if fuse {
            // Unit columns e_row of the basic w_l contribute -M[l, j] in their row.
            for l in 0..n {
                let row = self.row_of[l];
                if row != NONBASIC {
                    self.next[row] -= self.mcol[l];
                }
            }
        }
        (leaving, fuse)
    }

    /// Iterative refinement of a solved basis (`z0` non-basic): with `z` from the basic
    /// values, the residual of `w - M z = q` lives on the rows of non-basic `w`
    /// (`res_l = (q + M z)_l`); the correction is `B^{-1} res`. A step that does not
    /// reduce the residual is undone.
    fn refine(&mut self, m: MatRef<'_, f64>, q: &[f64]) {
        let n = self.n;
        let mut previous = f64::INFINITY;
        for step in 0..=REFINEMENT_STEPS {
            // w = q + M z over the basic z (into self.col).
            self.col.copy_from_slice(q);
            for j in 0..n {
                let row = self.row_of[n + j];
                if row != NONBASIC {
                    let zj = self.x[row];
                    copy_column(m, j, &mut self.mcol);
                    for (w, mv) in self.col.iter_mut().zip(&self.mcol) {
                        *w += zj * mv;
                    }
                }
            }
            let residual = self
                .nonbasic_w
                .iter()
                .fold(0.0_f64, |a, &l| a.max(self.col[l].abs()));
            let better = residual < previous;
            if residual == 0.0 || !better {
                // Nothing to gain, or the last step did not help: undo it.
                if step > 0 && !better {
                    for (x, dx) in self.x.iter_mut().zip(&self.dx) {
                        *x -= dx;
                    }
                }
                return;
            }
            if step == REFINEMENT_STEPS {
                return;
            }
            previous = residual;
            // Basic w take their recomputed values (zero residual in those rows).
            for l in 0..n {
                let row = self.row_of[l];
                if row != NONBASIC {
                    self.x[row] = self.col[l];
                }
            }
            // dx = sum over non-basic w_l of B^{-1}[:, l] res_l.
            self.dx.fill(0.0);
            for &l in &self.nonbasic_w {
                let s = self.col[l];
                if s != 0.0 {
                    let b = &self.binv[l * n..(l + 1) * n];
                    for (dx, bv) in self.dx.iter_mut().zip(b) {
                        *dx += s * bv;
                    }
                }
            }
            for (x, dx) in self.x.iter_mut().zip(&self.dx) {
                *x += dx;
            }
        }
    }

    /// Builds the report: `z` from the basis, `w = q + M z` from the data, the
    /// complementarity error.
    fn finish(
        &self,
        m: MatRef<'_, f64>,
        q: &[f64],
        termination: LemkeTermination,
        pivots: usize,
        ray_entering: Option<LcpVariable>,
    ) -> LemkeReport {
        let n = self.n;
        let mut z = vec![0.0; n];
        for (j, zj) in z.iter_mut().enumerate() {
            let row = self.row_of[n + j];
            if row != NONBASIC {
                *zj = self.x[row];
            }
        }
        let mut w = q.to_vec();
        for (j, &zj) in z.iter().enumerate() {
            if zj != 0.0 {
                let mcol = m.col(j);
                for (i, wi) in w.iter_mut().enumerate() {
                    *wi += zj * mcol[i];
                }
            }
        }
        let mut complementarity_error = complementarity_error(&z, &w);
        if termination == LemkeTermination::Solved {
            let scale = q
                .iter()
                .fold(0.0_f64, |a, v| a.max(v.abs()))
                .max(f64::MIN_POSITIVE);
            if complementarity_error > POLISH_THRESHOLD * scale {
                if let Some((zp, wp, error)) = polish(m, q, &z) {
                    if error < complementarity_error {
                        z = zp;
                        w = wp;
                        complementarity_error = error;
                    }
                }
            }
        }
        let artificial = match self.row_of.get(2 * n) {
            Some(&row) if row != NONBASIC => self.x[row],
            _ => 0.0,
        };
        LemkeReport {
            termination,
            z,
            w,
            pivots,
            complementarity_error,
            artificial,
            ray_entering,
        }
    }
}

/// Relative complementarity error (against `max |q|`) above which a solved LCP is polished.
const POLISH_THRESHOLD: f64 = 1e-12;

/// Active-set polish of a solution found along a long pivot path (where the explicit basis
/// inverse has accumulated rounding): with `A = {j : z_j > 0}`, solve `M_AA z_A = -q_A` by a
/// fresh LU and keep the result if it is feasible (`z_A >= 0`, `w = q + M z >= 0` up to
/// rounding). Returns `(z, w, complementarity error)`; allocates (only on this path).
fn polish(m: MatRef<'_, f64>, q: &[f64], z: &[f64]) -> Option<(Vec<f64>, Vec<f64>, f64)> {
    use faer::linalg::solvers::{PartialPivLu, Solve};
    let active: Vec<usize> = (0..z.len()).filter(|&j| z[j] > 0.0).collect();
    if active.is_empty() {
        return None;
    }
    let k = active.len();
    let block = faer::Mat::from_fn(k, k, |a, b| m[(active[a], active[b])]);
    let mut rhs = faer::Mat::from_fn(k, 1, |a, _| -q[active[a]]);
    let lu = PartialPivLu::new(block.as_ref());
    lu.solve_in_place(rhs.as_mut());
    let mut zp = vec![0.0; z.len()];
    for (a, &j) in active.iter().enumerate() {
        let v = rhs[(a, 0)];
        if !(v.is_finite() && v >= 0.0) {
            return None;
        }
        zp[j] = v;
    }
    let mut w = q.to_vec();
    for &j in &active {
        let mcol = m.col(j);
        for (i, wi) in w.iter_mut().enumerate() {
            *wi += zp[j] * mcol[i];
        }
    }
    let error = complementarity_error(&zp, &w);
    Some((zp, w, error))
}

/// One-shot convenience: `Lemke::new(n).solve(m, q, options)` (allocates a workspace;
/// keep a [`Lemke`] to solve many LCPs).
pub fn solve_lcp(
    m: MatRef<'_, f64>,
    q: &[f64],
    options: &LemkeOptions,
) -> Result<LemkeReport, LemkeError> {
    Lemke::new(m.nrows()).solve(m, q, options)
}

/// `max_i |min(z_i, w_i)|`: zero exactly when `z >= 0`, `w >= 0` and `z_i w_i = 0`; it also
/// measures negativity of either vector. Slices of unequal length are compared on the
/// common prefix.
pub fn complementarity_error(z: &[f64], w: &[f64]) -> f64 {
    z.iter()
        .zip(w)
        .fold(0.0_f64, |a, (&zi, &wi)| a.max(zi.min(wi).abs()))
}

/// The complement of a variable index (`w_i <-> z_i`); never called on `z0`.
fn complement(v: usize, n: usize) -> usize {
    if v < n {
        v + n
    } else {
        v - n
    }
}

fn variable(v: usize, n: usize) -> LcpVariable {
    if v < n {
        LcpVariable::W(v)
    } else if v < 2 * n {
        LcpVariable::Z(v - n)
    } else {
        LcpVariable::Artificial
    }
}

/// Copies column `j` of `m` into `out` (contiguous fast path).
fn copy_column(m: MatRef<'_, f64>, j: usize, out: &mut [f64]) {
    let c = m.col(j);
    match c.try_as_col_major() {
        Some(c) => out.copy_from_slice(c.as_slice()),
        None => {
            for (i, o) in out.iter_mut().enumerate() {
                *o = c[i];
            }
        }
    }
}

/// Data of one lexicographic minimum-ratio test.
struct RatioTest<'a> {
    x: &'a [f64],
    binv: &'a [f64],
    n: usize,
    divisor: &'a [f64],
    tol: f64,
    prefer: usize,
    clamp: bool,
}

/// Lexicographic minimum-ratio test over the candidate rows in `ties` (each with
/// `divisor[i] > 0`): minimise `x_i / divisor_i`, then break ties on
/// `B^{-1}[i, c] / divisor_i` for `c = 0, 1, ...`. A row equal to `prefer` among the rows
/// tied on the ratio wins at once. With `clamp`, a basic value made slightly negative by
/// rounding counts as 0 (a degenerate step, never a step backwards along the path).
/// `ties` is used as scratch.
fn lex_min_ratio(ties: &mut Vec<usize>, test: &RatioTest<'_>) -> usize {
    let RatioTest {
        x,
        binv,
        n,
        divisor,
        tol,
        prefer,
        clamp,
    } = *test;
    debug_assert!(!ties.is_empty());
    let xscale = x.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
    if clamp {
        keep_minimal(ties, |i| x[i].max(0.0) / divisor[i], xscale, divisor, tol);
    } else {
        keep_minimal(ties, |i| x[i] / divisor[i], xscale, divisor, tol);
    }
    if ties.len() == 1 {
        return ties[0];
    }
    if prefer != NONBASIC && ties.contains(&prefer) {
        return prefer;
    }
    for c in 0..n {
        let b = &binv[c * n..(c + 1) * n];
        let bscale = b.iter().fold(0.0_f64, |a, &v| a.max(v.abs()));
        keep_minimal(ties, |i| b[i] / divisor[i], bscale, divisor, tol);
        if ties.len() == 1 {
            return ties[0];
        }
    }
    // Not separated within the tolerance: take the largest pivot.
    ties.iter().copied().fold(
        ties[0],
        |best, i| if divisor[i] > divisor[best] { i } else { best },
    )
}

/// Keeps in `ties` the rows whose `value(i)` is within
/// `tol * (scale / divisor_i + |min|)` of the minimum.
fn keep_minimal(
    ties: &mut Vec<usize>,
    value: impl Fn(usize) -> f64,
    scale: f64,
    divisor: &[f64],
    tol: f64,
) {
    let min = ties.iter().fold(f64::INFINITY, |a, &i| a.min(value(i)));
    ties.retain(|&i| value(i) - min <= tol * (scale / divisor[i] + min.abs()));
}
