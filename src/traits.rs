//! The core traits: a residual, one element of its generalized Jacobian, a scalar
//! parameter for continuation, and linear solvers split into a factorization and the
//! solves that reuse it.

use std::sync::Arc;

use crate::linalg::{LinearSolveError, SolveAccuracy};

/// Why a problem could not evaluate its residual, Jacobian or parameter derivative at `x`.
///
/// Two kinds, treated differently by the drivers:
/// - [`EvaluationError::OutsideDomain`]: `x` lies where the problem is not defined. The
///   drivers treat it like an infinite merit: a line search shortens the step, a
///   continuation corrector rejects the attempt (and the step is halved); a Newton run that
///   cannot evaluate its initial guess stops with
///   [`Termination::Evaluation`](crate::newton::Termination::Evaluation).
/// - [`EvaluationError::Problem`]: the problem itself failed (an inner solve, a time step
///   that could not be taken). The run stops at once and hands the error back in its
///   termination ([`Termination::Evaluation`](crate::newton::Termination::Evaluation),
///   [`ContinuationTermination::ProblemFailed`](crate::continuation::ContinuationTermination::ProblemFailed)),
///   where [`EvaluationError::downcast_ref`] reads the problem's own error type back.
///
/// ```
/// use semismooth::EvaluationError;
/// #[derive(Debug, thiserror::Error)]
/// #[error("the inner solve diverged after {0} steps")]
/// struct Diverged(usize);
///
/// let e = EvaluationError::problem(Diverged(7));
/// assert_eq!(e.downcast_ref::<Diverged>().map(|d| d.0), Some(7));
/// assert_eq!(e.to_string(), "the inner solve diverged after 7 steps");
/// assert_eq!(e.kind(), "problem-error");
/// ```
#[derive(Clone, Debug, thiserror::Error)]
#[non_exhaustive]
pub enum EvaluationError {
    /// `x` (or the problem's parameter) lies outside the set where the problem is defined.
    #[error("outside the problem's domain: {what} = {value:e}")]
    OutsideDomain {
        /// The quantity that is out of range, in words.
        what: &'static str,
        /// Its value.
        value: f64,
    },
    /// The problem's own error, built by [`EvaluationError::problem`].
    #[error(transparent)]
    Problem(Arc<dyn std::error::Error + Send + Sync>),
}

impl EvaluationError {
    /// The problem's own `error`, handed back to the caller in the run's termination.
    pub fn problem(error: impl std::error::Error + Send + Sync + 'static) -> Self {
        Self::Problem(Arc::new(error))
    }

    /// The problem's error as its own type `E` (`None` for another type or kind).
    pub fn downcast_ref<E: std::error::Error + 'static>(&self) -> Option<&E> {
        match self {
            Self::Problem(error) => error.downcast_ref::<E>(),
            Self::OutsideDomain { .. } => None,
        }
    }

    /// A short name of the kind: `outside-domain` or `problem-error`.
    pub fn kind(&self) -> &'static str {
        match self {
            Self::OutsideDomain { .. } => "outside-domain",
            Self::Problem(_) => "problem-error",
        }
    }

    /// Whether the error ends the run ([`EvaluationError::Problem`]) rather than a step.
    pub(crate) fn ends_run(&self) -> bool {
        matches!(self, Self::Problem(_))
    }
}

/// Two domain errors are equal when they name the same quantity and value; two problem
/// errors when they are the same error (one `Arc`).
impl PartialEq for EvaluationError {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (
                Self::OutsideDomain { what, value },
                Self::OutsideDomain {
                    what: other_what,
                    value: other_value,
                },
            ) => what == other_what && value == other_value,
            (Self::Problem(a), Self::Problem(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

/// Capacity of [`ProblemCounters`].
pub const MAX_PROBLEM_COUNTERS: usize = 4;

/// Work a problem counts in its own units (the transforms of a harmonic-balance residual,
/// the matrices a parametrised problem rebuilds, ...): up to [`MAX_PROBLEM_COUNTERS`] named
/// totals. The drivers report the difference over a run next to their own counters.
///
/// ```
/// use semismooth::ProblemCounters;
/// let before = ProblemCounters::new().with("transforms", 3);
/// let after = ProblemCounters::new().with("transforms", 10);
/// assert_eq!(after.since(&before).get("transforms"), 7);
/// assert_eq!(after.get("something else"), 0);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ProblemCounters {
    names: [&'static str; MAX_PROBLEM_COUNTERS],
    values: [u64; MAX_PROBLEM_COUNTERS],
    len: usize,
}

impl ProblemCounters {
    /// No counter.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `value` to the counter `name` (created if new; a name beyond
    /// [`MAX_PROBLEM_COUNTERS`] distinct ones is ignored).
    pub fn add(&mut self, name: &'static str, value: u64) {
        if let Some(i) = self.names[..self.len].iter().position(|n| *n == name) {
            self.values[i] += value;
        } else if self.len < MAX_PROBLEM_COUNTERS {
            self.names[self.len] = name;
            self.values[self.len] = value;
            self.len += 1;
        }
    }

    /// `self` with `value` added to `name` (builder form of [`ProblemCounters::add`]).
    pub fn with(mut self, name: &'static str, value: u64) -> Self {
        self.add(name, value);
        self
    }

    /// The counter `name` (0 when absent).
    pub fn get(&self, name: &str) -> u64 {
        self.iter().find(|(n, _)| *n == name).map_or(0, |(_, v)| v)
    }

    /// `(name, value)` pairs in the order they were first added.
    pub fn iter(&self) -> impl Iterator<Item = (&'static str, u64)> + '_ {
        self.names[..self.len]
            .iter()
            .copied()
            .zip(self.values[..self.len].iter().copied())
    }

    /// The work done since `earlier` (counter by counter, saturating at 0).
    pub fn since(&self, earlier: &ProblemCounters) -> ProblemCounters {
        let mut out = ProblemCounters::new();
        for (name, value) in self.iter() {
            out.add(name, value.saturating_sub(earlier.get(name)));
        }
        out
    }
}

impl std::ops::AddAssign for ProblemCounters {
    fn add_assign(&mut self, rhs: Self) {
        for (name, value) in rhs.iter() {
            self.add(name, value);
        }
    }
}

/// A square system `F(x) = 0`, `F: R^n -> R^n`, Lipschitz continuous.
///
/// Evaluation fills a caller-owned buffer and may use problem-owned workspace (hence
/// `&mut self`), so that repeated evaluations allocate nothing.
///
/// ```
/// use semismooth::{EvaluationError, Residual};
/// /// F(x) = x^2 - 2 on R^1.
/// struct Sqrt2;
/// impl Residual for Sqrt2 {
///     fn dim(&self) -> usize { 1 }
///     fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
///         out[0] = x[0] * x[0] - 2.0;
///         Ok(())
///     }
/// }
/// let mut f = [0.0];
/// Sqrt2.residual(&[1.0], &mut f).unwrap();
/// assert_eq!(f[0], -1.0);
/// ```
pub trait Residual {
    /// Number of unknowns `n` (and of equations).
    fn dim(&self) -> usize;

    /// Writes `F(x)` into `out` (both of length [`Residual::dim`]); an `x` where `F` is not
    /// defined is an [`EvaluationError`], never a NaN.
    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError>;

    /// The problem's own work counters (totals since it was built); none by default.
    fn problem_counters(&self) -> ProblemCounters {
        ProblemCounters::new()
    }
}

/// A smoothing of a problem's nonsmooth terms by a parameter `mu >= 0`: `F_mu` is
/// continuously differentiable for `mu > 0` and `F_0 = F`; typically each `max(0, s)` is
/// replaced by the Chen–Harker–Kanzow–Smale function `(s + sqrt(s^2 + 4 mu^2)) / 2`, which
/// lies within `mu` of it. While `mu > 0` is set, [`Residual::residual`] evaluates `F_mu`
/// and [`GeneralizedJacobian::jacobian`] its Jacobian.
///
/// A capability known from the problem's type: the polyalgorithm follows the smoothing path
/// `F_mu(x) = 0` from a large `mu` (where the problem is nearly affine) to `mu = 0` when it
/// is called through [`polyalgorithm::solve_smoothing`](crate::polyalgorithm::solve_smoothing)
/// ([`crate::polyalgorithm`], attempt 2).
///
/// ```
/// use semismooth::{EvaluationError, Residual, Smoothing};
/// /// F(x) = x - max(0, 2 - x) (root x = 1), smoothed by the CHKS function.
/// struct Ramp { mu: f64 }
/// fn phi(s: f64, mu: f64) -> f64 { (s + (s * s + 4.0 * mu * mu).sqrt()) / 2.0 }
/// impl Residual for Ramp {
///     fn dim(&self) -> usize { 1 }
///     fn residual(&mut self, x: &[f64], f: &mut [f64]) -> Result<(), EvaluationError> {
///         f[0] = x[0] - phi(2.0 - x[0], self.mu);
///         Ok(())
///     }
/// }
/// impl Smoothing for Ramp {
///     fn smoothing_scale(&self) -> f64 { 2.0 } // |2 - x| at the guess x = 0
///     fn set_smoothing(&mut self, mu: f64) { self.mu = mu; }
///     fn residual_smoothing_derivative(&mut self, x: &[f64], d: &mut [f64]) -> Result<(), EvaluationError> {
///         let s = 2.0 - x[0];
///         d[0] = -2.0 * self.mu / (s * s + 4.0 * self.mu * self.mu).sqrt();
///         Ok(())
///     }
/// }
/// let mut ramp = Ramp { mu: 0.0 };
/// let mut f = [0.0];
/// ramp.residual(&[1.0], &mut f).unwrap();
/// assert_eq!(f[0], 0.0);
/// ramp.set_smoothing(0.5);
/// ramp.residual(&[1.0], &mut f).unwrap();
/// assert!(f[0] < 0.0 && f[0] > -0.5); // within mu of F
/// ```
pub trait Smoothing: Residual {
    /// The scale of `mu` at which the smoothing blurs the problem's switching quantities
    /// over their whole range at the initial guess (e.g. `c |g|` for `max(0, c (u - g))`).
    fn smoothing_scale(&self) -> f64;

    /// Sets `mu >= 0` (0: the problem itself).
    fn set_smoothing(&mut self, mu: f64);

    /// Writes `dF_mu(x)/dmu` into `out`.
    fn residual_smoothing_derivative(
        &mut self,
        x: &[f64],
        out: &mut [f64],
    ) -> Result<(), EvaluationError>;
}

/// One element `J` of the generalized Jacobian `∂F(x)` (Clarke or Bouligand), written
/// into the problem's own matrix type [`GeneralizedJacobian::Jacobian`] (dense, sparse or
/// structured), so that the linear solver can be chosen without touching the problem.
///
/// Where `F` is differentiable at `x`, `J` must be the ordinary Jacobian.
///
/// ```
/// use semismooth::faer::Mat;
/// use semismooth::{EvaluationError, GeneralizedJacobian, Residual};
/// /// F(x) = max(x, 0) - 1 on R^1: J = 1 for x > 0, 0 for x < 0; at the kink either is an
/// /// element of the B-subdifferential (this one takes 0).
/// struct Hinge;
/// impl Residual for Hinge {
///     fn dim(&self) -> usize { 1 }
///     fn residual(&mut self, x: &[f64], f: &mut [f64]) -> Result<(), EvaluationError> {
///         f[0] = x[0].max(0.0) - 1.0;
///         Ok(())
///     }
/// }
/// impl GeneralizedJacobian for Hinge {
///     type Jacobian = Mat<f64>;
///     fn new_jacobian(&self) -> Mat<f64> { Mat::zeros(1, 1) }
///     fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
///         jac[(0, 0)] = if x[0] > 0.0 { 1.0 } else { 0.0 };
///         Ok(())
///     }
/// }
/// let mut j = Hinge.new_jacobian();
/// Hinge.jacobian(&[2.0], &mut j).unwrap();
/// assert_eq!(j[(0, 0)], 1.0);
/// Hinge.jacobian(&[-2.0], &mut j).unwrap();
/// assert_eq!(j[(0, 0)], 0.0);
/// ```
pub trait GeneralizedJacobian: Residual {
    /// The matrix type the Jacobian is written into.
    type Jacobian;

    /// Allocates a Jacobian of the right shape (called once per solve, not per iteration).
    fn new_jacobian(&self) -> Self::Jacobian;

    /// Writes an element of `∂F(x)` into `jac`.
    fn jacobian(&mut self, x: &[f64], jac: &mut Self::Jacobian) -> Result<(), EvaluationError>;
}

/// A residual that depends on a scalar parameter `p` (a forcing frequency, a load
/// factor): `F(x, p)`. Needed by continuation.
///
/// ```
/// use semismooth::{EvaluationError, ParameterDependent, Residual};
/// /// F(x, p) = x^2 - p.
/// struct Root { p: f64 }
/// impl Residual for Root {
///     fn dim(&self) -> usize { 1 }
///     fn residual(&mut self, x: &[f64], f: &mut [f64]) -> Result<(), EvaluationError> {
///         f[0] = x[0] * x[0] - self.p;
///         Ok(())
///     }
/// }
/// impl ParameterDependent for Root {
///     fn parameter(&self) -> f64 { self.p }
///     fn set_parameter(&mut self, p: f64) { self.p = p; }
/// }
/// // dF/dp = -1 by the default central difference, the parameter left as it was.
/// let mut root = Root { p: 2.0 };
/// let (mut dfdp, mut scratch) = ([0.0], [0.0]);
/// root.residual_parameter_derivative(&[1.5], &mut dfdp, &mut scratch).unwrap();
/// assert!((dfdp[0] + 1.0).abs() < 1e-8 && root.parameter() == 2.0);
/// ```
pub trait ParameterDependent: Residual {
    /// Current value of the parameter.
    fn parameter(&self) -> f64;

    /// Sets the parameter used by subsequent evaluations.
    fn set_parameter(&mut self, p: f64);

    /// The scale of `|F|` that counts as small at the parameter `p`, relative to the
    /// continuation's `corrector_tolerance` (which it multiplies). Default 1: one tolerance
    /// along the whole branch. A path whose solutions sharpen as it goes (a smoothing
    /// parameter `mu -> 0`, whose Newton basin shrinks like `mu`) returns a scale that
    /// shrinks with them.
    fn tolerance_scale(&self, p: f64) -> f64 {
        let _ = p;
        1.0
    }

    /// Writes `∂F/∂p (x, p)` into `out`; `scratch` (of the length of `out`) is workspace
    /// the caller owns, so that no call allocates.
    ///
    /// The default is a central finite difference with step `1e-7 (1 + |p|)`, which uses
    /// `scratch` (and leaves the parameter at `p`); problems with an analytic derivative
    /// should override it and may ignore `scratch`.
    fn residual_parameter_derivative(
        &mut self,
        x: &[f64],
        out: &mut [f64],
        scratch: &mut [f64],
    ) -> Result<(), EvaluationError> {
        let p = self.parameter();
        let h = PARAMETER_STEP * (1.0 + p.abs());
        self.set_parameter(p + h);
        let plus = self.residual(x, out);
        self.set_parameter(p - h);
        let below = self.residual(x, scratch);
        self.set_parameter(p);
        plus?;
        below?;
        for (o, m) in out.iter_mut().zip(scratch.iter()) {
            *o = (*o - m) / (2.0 * h);
        }
        Ok(())
    }
}

/// Relative step of the default central difference of
/// [`ParameterDependent::residual_parameter_derivative`].
const PARAMETER_STEP: f64 = 1e-7;

/// The solve half of a linear solver: `rhs <- J^{-1} rhs` with the factorization made by
/// the last successful [`Factorize::factor`] (Newton step, continuation tangent and
/// bordered solves all reuse one factorization).
///
/// ```
/// use semismooth::linalg::LinearSolveError;
/// use semismooth::{Factorize, LinearSolve};
/// /// A solver for diagonal Jacobians stored as their diagonal.
/// #[derive(Default)]
/// struct Diagonal(Vec<f64>);
/// impl LinearSolve for Diagonal {
///     fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
///         for (r, d) in rhs.iter_mut().zip(&self.0) {
///             *r /= d;
///         }
///         Ok(())
///     }
/// }
/// impl Factorize<Vec<f64>> for Diagonal {
///     fn factor(&mut self, jac: &Vec<f64>) -> Result<(), LinearSolveError> {
///         if let Some(index) = jac.iter().position(|d| *d == 0.0) {
///             self.0.clear();
///             return Err(LinearSolveError::Singular { index, pivot: 0.0, max_pivot: f64::NAN });
///         }
///         self.0.clone_from(jac);
///         Ok(())
///     }
/// }
/// let mut solver = Diagonal::default();
/// solver.factor(&vec![2.0, 4.0]).unwrap();
/// let mut rhs = [1.0, 1.0];
/// solver.solve_in_place(&mut rhs).unwrap(); // one factorization, many solves
/// assert_eq!(rhs, [0.5, 0.25]);
/// assert!(solver.factor(&vec![1.0, 0.0]).is_err());
/// ```
pub trait LinearSolve {
    /// Solves `J x = rhs` in place with the last factorization.
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError>;

    /// Solves `J x = rhs` in place as accurately as `accuracy` asks (an inexact Newton
    /// step: an iterative solver may stop at `|J x - rhs| <= max(accuracy.relative |rhs|,
    /// accuracy.absolute)`, or earlier by its own rule). The default, for direct solvers,
    /// solves exactly ([`LinearSolve::solve_in_place`]).
    fn solve_in_place_to(
        &mut self,
        rhs: &mut [f64],
        accuracy: SolveAccuracy,
    ) -> Result<(), LinearSolveError> {
        let _ = accuracy;
        self.solve_in_place(rhs)
    }

    /// Solves `J X = R` in place for `ncols` right-hand sides stored one after the other
    /// (column-major, `columns.len() = n * ncols`) with the last factorization. The default
    /// solves them column by column; direct solvers override it with one blocked solve.
    /// A length that `ncols` does not divide is [`LinearSolveError::DimensionMismatch`].
    fn solve_columns_in_place(
        &mut self,
        columns: &mut [f64],
        ncols: usize,
    ) -> Result<(), LinearSolveError> {
        let n = column_length(columns.len(), ncols)?;
        if n > 0 {
            for column in columns.chunks_exact_mut(n) {
                self.solve_in_place(column)?;
            }
        }
        Ok(())
    }

    /// Krylov iterations (operator products) of the solves so far, over the solver's
    /// life; 0 for a direct solver. Drivers report the difference over a run in
    /// [`WorkCounters::krylov_iterations`](crate::newton::WorkCounters::krylov_iterations).
    fn krylov_iterations(&self) -> u64 {
        0
    }
}

/// The length `n` of each of `ncols` columns stored in `len` numbers
/// ([`LinearSolveError::DimensionMismatch`] when `ncols` does not divide `len`).
pub(crate) fn column_length(len: usize, ncols: usize) -> Result<usize, LinearSolveError> {
    match ncols {
        0 if len == 0 => Ok(0),
        0 => Err(LinearSolveError::DimensionMismatch {
            expected: 0,
            found: len,
        }),
        _ if len % ncols != 0 => Err(LinearSolveError::DimensionMismatch {
            expected: len / ncols * ncols,
            found: len,
        }),
        _ => Ok(len / ncols),
    }
}

/// The factorization half of a linear solver for Jacobians of type `J` (an example with
/// [`LinearSolve`]).
///
/// `factor` may be called again with a new matrix of the same shape; implementations
/// reuse their storage (and any symbolic analysis of a sparsity pattern).
///
/// ```
/// use semismooth::faer::Mat;
/// use semismooth::linalg::FaerDenseLu;
/// use semismooth::{Factorize, LinearSolve};
/// let mut lu = FaerDenseLu::new();
/// lu.factor(&Mat::from_fn(2, 2, |i, j| if i == j { 2.0 } else { 1.0 })).unwrap();
/// let mut x = [3.0, 3.0];
/// lu.solve_in_place(&mut x).unwrap();
/// assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
/// ```
pub trait Factorize<J: ?Sized>: LinearSolve {
    /// Factors `jac`. A singular or non-finite matrix is a typed error, after which the
    /// solver holds no factorization.
    fn factor(&mut self, jac: &J) -> Result<(), LinearSolveError>;
}
