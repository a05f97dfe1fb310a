//! Solving from a poor guess: a polyalgorithm of Newton runs and continuation paths, each
//! from the initial guess, within one iteration budget.
//!
//! Semismooth Newton on a complementarity system with full steps behaves like a primal-dual
//! active-set method: from a reasonable guess it finds the active set in a few iterations,
//! but it may cycle between active sets or creep one switch per iteration; a line search on
//! `|F|^2 / 2` cannot repair this, because the merit has kinks wherever the active set
//! changes and backtracking stalls on them. The polyalgorithm therefore tries, within one
//! budget of `max_iterations`:
//!
//! 1. `full_steps` full Newton steps (the fast path: most solves end here). When the
//!    problem offers a [`Smoothing`] they stop earlier once they stagnate
//!    ([`Termination::Stagnated`]: after 8 steps, `|F|` did not fall tenfold over the last 6
//!    against the smallest before them, the first iterate excluded);
//! 2. when the problem offers a [`Smoothing`] ([`solve_smoothing`]): the smoothing path
//!    `F_mu(x) = 0` from the initial guess, `mu` from the problem's smoothing scale down three
//!    decades (Newton with an Armijo search on the smooth merit at the start, then the
//!    crate's pseudo-arclength continuation in `log10 mu` with the tangent predictor), then
//!    full Newton steps on `F`; a path that stops after two decades hands its last point to
//!    those steps too (stopped when they stagnate: after 15 steps, `|F|` did not fall
//!    tenfold over the last 10). When this fails, the path is followed once more with its
//!    points corrected to a tolerance shrinking like `mu` (`|F_mu| <= beta mu`, the
//!    neighbourhood of smoothing Newton methods;
//!    [`ParameterDependent::tolerance_scale`](crate::ParameterDependent::tolerance_scale)):
//!    late on the path the Newton basin of `F_mu` shrinks like `mu`, and points corrected
//!    to one tolerance can lie outside it;
//! 3. the non-monotone line search from the initial guess, on at most half of the
//!    iterations left;
//! 4. the Newton homotopy `H(x, t) = F(x) - (1 - t) F(x_0)` from `(x_0, 0)` to `t = 1`,
//!    followed by the continuation (the state weighted 0.99 in the arclength so that
//!    corners where `t` turns back are passed), then full Newton steps on `F` at `t = 1`.
//!    It needs nothing from the problem but `F` and `J`; for a forced structure whose
//!    contacts are open at `x_0 = 0` it is the load homotopy.
//!
//! The report ([`NewtonReport`], as for plain Newton) names the strategy that converged
//! ([`NewtonReport::strategy`]) and every attempt ([`NewtonReport::attempts`]); the best
//! iterate of all attempts is returned. `Err` only when it could not run (invalid options,
//! a guess of the wrong length); the problem's own error
//! ([`EvaluationError::Problem`]) ends the whole run.
//!
//! # Entry points
//!
//! Whether the smoothing path is offered is known from the problem's type: [`solve`] for
//! any problem, [`solve_smoothing`] for a problem that implements [`Smoothing`] (and the
//! same two methods on the reusable [`Polyalgorithm`]). Code generic over the problem
//! passes the capability along as a value, `Option<`[`SmoothingOf<P>`]`>`, built where the
//! type is known ([`Polyalgorithm::solve_with`], [`SolveOptions::solve`]).
//!
//! # Options and defaults ([`PolyalgorithmOptions`])
//!
//! | field | default | meaning |
//! |---|---|---|
//! | `tolerances` | [`Tolerances::default`]: `1e-10`, `0`, `0`, `0`, `1e-15` | as for [`NewtonOptions`] |
//! | `max_iterations` | `200` | the budget of every attempt together (Newton and corrector iterations) |
//! | `full_steps` | `30` | iterations of the first attempt (and of each finish on `F` after a path) |
//! | `memory` | `10` | memory of the non-monotone line search (attempt 3) |
//! | `line_search` | [`LineSearchOptions::default`] | backtracking of attempt 3 and of the smoothing path's start |
//!
//! [`SolveOptions`] chooses at run time between one plain Newton run and the polyalgorithm
//! (a settings file's `globalization`).
//!
//! ```
//! use faer::Mat;
//! use semismooth::linalg::FaerDenseLu;
//! use semismooth::polyalgorithm::{solve, solve_smoothing, PolyalgorithmOptions};
//! use semismooth::newton::Strategy;
//! use semismooth::{EvaluationError, GeneralizedJacobian, Residual, Smoothing};
//!
//! /// F(x) = min(x, A x + q) for the LCP with A = [[2, 1], [1, 2]], q = [-1, 1]
//! /// (solution x = [0.5, 0]), smoothed as x - phi_mu(x - A x - q) with
//! /// phi_mu(s) = (s + sqrt(s^2 + 4 mu^2)) / 2.
//! struct Lcp { mu: f64 }
//! const A: [[f64; 2]; 2] = [[2.0, 1.0], [1.0, 2.0]];
//! const Q: [f64; 2] = [-1.0, 1.0];
//! fn s(x: &[f64], i: usize) -> f64 { x[i] - A[i][0] * x[0] - A[i][1] * x[1] - Q[i] }
//! fn root(s: f64, mu: f64) -> f64 { (s * s + 4.0 * mu * mu).sqrt() }
//! impl Residual for Lcp {
//!     fn dim(&self) -> usize { 2 }
//!     fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
//!         for i in 0..2 {
//!             let s = s(x, i);
//!             out[i] = x[i] - if self.mu > 0.0 { (s + root(s, self.mu)) / 2.0 } else { s.max(0.0) };
//!         }
//!         Ok(())
//!     }
//! }
//! impl GeneralizedJacobian for Lcp {
//!     type Jacobian = Mat<f64>;
//!     fn new_jacobian(&self) -> Mat<f64> { Mat::zeros(2, 2) }
//!     fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
//!         for i in 0..2 {
//!             let s = s(x, i);
//!             // Slope t of phi_mu (of max(0, s) at mu = 0): row e_i - t (e_i - A_i).
//!             let t = if self.mu > 0.0 { (1.0 + s / root(s, self.mu)) / 2.0 } else { (s > 0.0) as u8 as f64 };
//!             for j in 0..2 {
//!                 let e = (i == j) as u8 as f64;
//!                 jac[(i, j)] = e - t * (e - A[i][j]);
//!             }
//!         }
//!         Ok(())
//!     }
//! }
//! impl Smoothing for Lcp {
//!     fn smoothing_scale(&self) -> f64 { 1.0 }
//!     fn set_smoothing(&mut self, mu: f64) { self.mu = mu; }
//!     fn residual_smoothing_derivative(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
//!         for i in 0..2 {
//!             out[i] = -2.0 * self.mu / root(s(x, i), self.mu);
//!         }
//!         Ok(())
//!     }
//! }
//!
//! let options = PolyalgorithmOptions::default();
//! let mut x = [1.0, 1.0];
//! let report = solve(&mut Lcp { mu: 0.0 }, &mut FaerDenseLu::new(), &mut x, &options).unwrap();
//! assert!(report.converged() && report.strategy == Strategy::FullSteps);
//! assert!((x[0] - 0.5).abs() < 1e-12 && x[1].abs() < 1e-12);
//! // The same with the smoothing path offered (not needed here: the full steps converge).
//! let mut x = [1.0, 1.0];
//! let report = solve_smoothing(&mut Lcp { mu: 0.0 }, &mut FaerDenseLu::new(), &mut x, &options)
//!     .unwrap();
//! assert!(report.converged() && report.attempts.len() == 1);
//! ```

mod attempts;
mod path;

use crate::iteration::kernel::{KernelRules, StepRule};
use crate::linesearch::LineSearchOptions;
use crate::newton::{
    self, validate_line_search, NewtonError, NewtonOptions, NewtonReport, StateFloor, Termination,
    Tolerances, Workspace, DEFAULT_FULL_STEPS, DEFAULT_MAX_ITERATIONS, DEFAULT_MEMORY,
};
use crate::{EvaluationError, Factorize, GeneralizedJacobian, Smoothing};

/// Options of the polyalgorithm (defaults in the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PolyalgorithmOptions {
    /// When an attempt has converged or stalled (as for [`NewtonOptions`]).
    pub tolerances: Tolerances,
    /// Iterations of every attempt together (Newton iterations, corrector iterations of
    /// the paths).
    pub max_iterations: usize,
    /// Iterations of the full-step attempt (and of the full steps that finish a path).
    pub full_steps: usize,
    /// Memory of the non-monotone line search (`>= 1`).
    pub memory: usize,
    /// Backtracking of the line-search attempt and of the smoothing path's start.
    pub line_search: LineSearchOptions,
}

impl Default for PolyalgorithmOptions {
    fn default() -> Self {
        Self {
            tolerances: Tolerances::default(),
            max_iterations: DEFAULT_MAX_ITERATIONS,
            full_steps: DEFAULT_FULL_STEPS,
            memory: DEFAULT_MEMORY,
            line_search: LineSearchOptions::default(),
        }
    }
}

impl PolyalgorithmOptions {
    /// Checks every field; the error names the field, the value and the allowed range.
    pub fn validate(&self) -> Result<(), NewtonError> {
        self.tolerances.validate()?;
        validate_line_search("memory", self.memory, &self.line_search)
    }

    /// The kernel's rules of an attempt with the step rule `step`.
    fn rules(&self, step: StepRule) -> KernelRules {
        KernelRules::new(self.tolerances, self.max_iterations, step)
    }
}

/// The smoothing a problem type `P` offers, as a value: built by [`SmoothingOf::new`] only
/// for types that implement [`Smoothing`], and passed (as `Option<SmoothingOf<P>>`) by
/// code generic over the problem to [`Polyalgorithm::solve_with`] or
/// [`SolveOptions::solve`].
///
/// ```
/// use semismooth::polyalgorithm::SmoothingOf;
/// use semismooth::{EvaluationError, Residual, Smoothing};
/// struct Smoothed(f64);
/// impl Residual for Smoothed {
///     fn dim(&self) -> usize { 1 }
///     fn residual(&mut self, x: &[f64], f: &mut [f64]) -> Result<(), EvaluationError> {
///         f[0] = x[0] - self.0;
///         Ok(())
///     }
/// }
/// impl Smoothing for Smoothed {
///     fn smoothing_scale(&self) -> f64 { 1.0 }
///     fn set_smoothing(&mut self, mu: f64) { self.0 = mu; }
///     fn residual_smoothing_derivative(&mut self, _: &[f64], d: &mut [f64]) -> Result<(), EvaluationError> {
///         d[0] = -1.0;
///         Ok(())
///     }
/// }
/// // Chosen where the type is known; `None` for a problem without a smoothing.
/// let offered: Option<SmoothingOf<Smoothed>> = Some(SmoothingOf::new());
/// assert!(offered.is_some());
/// ```
pub struct SmoothingOf<P: ?Sized> {
    scale: fn(&P) -> f64,
    set: fn(&mut P, f64),
    derivative: Derivative<P>,
}

/// [`Smoothing::residual_smoothing_derivative`] as a function pointer.
type Derivative<P> = fn(&mut P, &[f64], &mut [f64]) -> Result<(), EvaluationError>;

impl<P: Smoothing + ?Sized> SmoothingOf<P> {
    /// The smoothing of `P` ([`Smoothing`]'s methods).
    pub fn new() -> Self {
        Self {
            scale: P::smoothing_scale,
            set: P::set_smoothing,
            derivative: P::residual_smoothing_derivative,
        }
    }
}

impl<P: Smoothing + ?Sized> Default for SmoothingOf<P> {
    fn default() -> Self {
        Self::new()
    }
}

impl<P: ?Sized> Clone for SmoothingOf<P> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<P: ?Sized> Copy for SmoothingOf<P> {}

impl<P: ?Sized> std::fmt::Debug for SmoothingOf<P> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SmoothingOf").finish_non_exhaustive()
    }
}

/// The polyalgorithm as a reusable solver: options plus the buffers of the iteration and
/// the Jacobian `J`, kept between solves (as [`NewtonSolver`](crate::newton::NewtonSolver)).
#[derive(Debug)]
pub struct Polyalgorithm<J> {
    options: PolyalgorithmOptions,
    work: Workspace<J>,
    /// The initial guess (each attempt starts from it).
    start: Vec<f64>,
}

impl<J> Polyalgorithm<J> {
    /// A solver with validated `options`.
    pub fn new(options: PolyalgorithmOptions) -> Result<Self, NewtonError> {
        options.validate()?;
        Ok(Self {
            options,
            work: Workspace::default(),
            start: Vec::new(),
        })
    }

    /// The attempts without the smoothing path, from `x` (initial guess in, best iterate
    /// out). `Ok(report)` when it ran, converged or not ([`NewtonReport::converged`]);
    /// [`NewtonError::DimensionMismatch`] when `x` does not fit the problem.
    pub fn solve<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
    ) -> Result<NewtonReport, NewtonError>
    where
        P: GeneralizedJacobian<Jacobian = J> + ?Sized,
        S: Factorize<J> + ?Sized,
    {
        self.solve_with(problem, linear, x, None)
    }

    /// The attempts with the smoothing path of `problem`, from `x`; as
    /// [`Polyalgorithm::solve`] otherwise.
    pub fn solve_smoothing<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
    ) -> Result<NewtonReport, NewtonError>
    where
        P: GeneralizedJacobian<Jacobian = J> + Smoothing + ?Sized,
        S: Factorize<J> + ?Sized,
    {
        self.solve_with(problem, linear, x, Some(SmoothingOf::new()))
    }

    /// The attempts from `x`, with the smoothing path when `smoothing` is given (for code
    /// generic over the problem, which cannot name [`Smoothing`]).
    pub fn solve_with<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
        smoothing: Option<SmoothingOf<P>>,
    ) -> Result<NewtonReport, NewtonError>
    where
        P: GeneralizedJacobian<Jacobian = J> + ?Sized,
        S: Factorize<J> + ?Sized,
    {
        let mut measured = self.work.begin(problem, linear, x)?;
        let work = (&mut measured.counters, &mut measured.log);
        let outcome = self.run(problem, linear, x, smoothing, work);
        Ok(measured.report(problem, linear, outcome))
    }
}

/// The polyalgorithm without the smoothing path: validates `options`, runs
/// [`Polyalgorithm::solve`] (`x`: initial guess in, best iterate out).
pub fn solve<P, S>(
    problem: &mut P,
    linear: &mut S,
    x: &mut [f64],
    options: &PolyalgorithmOptions,
) -> Result<NewtonReport, NewtonError>
where
    P: GeneralizedJacobian + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    Polyalgorithm::<P::Jacobian>::new(*options)?.solve(problem, linear, x)
}

/// The polyalgorithm with the smoothing path of `problem`: validates `options`, runs
/// [`Polyalgorithm::solve_smoothing`] (`x`: initial guess in, best iterate out).
pub fn solve_smoothing<P, S>(
    problem: &mut P,
    linear: &mut S,
    x: &mut [f64],
    options: &PolyalgorithmOptions,
) -> Result<NewtonReport, NewtonError>
where
    P: GeneralizedJacobian + Smoothing + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    Polyalgorithm::<P::Jacobian>::new(*options)?.solve_smoothing(problem, linear, x)
}

/// How to solve `F(x) = 0` from a guess, chosen at run time (a settings file's
/// `globalization`): one plain Newton run, or the polyalgorithm (the default).
///
/// ```
/// use semismooth::newton::{Globalization, NewtonOptions};
/// use semismooth::polyalgorithm::{PolyalgorithmOptions, SolveOptions};
/// let plain = SolveOptions::Newton(NewtonOptions {
///     globalization: Globalization::None,
///     ..Default::default()
/// });
/// assert!(plain.validate().is_ok());
/// let floor = SolveOptions::default().with_residual_floor(1e-9);
/// assert!(matches!(floor, SolveOptions::Polyalgorithm(o) if o.tolerances.residual_floor == 1e-9));
/// ```
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub enum SolveOptions {
    /// One run of [`crate::newton`] with these options.
    Newton(NewtonOptions),
    /// The polyalgorithm with these options.
    Polyalgorithm(PolyalgorithmOptions),
}

impl Default for SolveOptions {
    fn default() -> Self {
        Self::Polyalgorithm(PolyalgorithmOptions::default())
    }
}

impl SolveOptions {
    /// Checks the options of the chosen driver.
    pub fn validate(&self) -> Result<(), NewtonError> {
        match self {
            Self::Newton(options) => options.validate(),
            Self::Polyalgorithm(options) => options.validate(),
        }
    }

    /// The same with the residual floor (the `|F|` round-off alone produces near a
    /// solution) set to `floor`.
    pub fn with_residual_floor(mut self, floor: f64) -> Self {
        match &mut self {
            Self::Newton(options) => options.tolerances.residual_floor = floor,
            Self::Polyalgorithm(options) => options.tolerances.residual_floor = floor,
        }
        self
    }

    /// The same with the residual floor in proportion to the iterate's size
    /// ([`Tolerances::state_floor`]) set to `floor`.
    pub fn with_state_floor(mut self, floor: StateFloor) -> Self {
        match &mut self {
            Self::Newton(options) => options.tolerances.state_floor = floor,
            Self::Polyalgorithm(options) => options.tolerances.state_floor = floor,
        }
        self
    }

    /// Solves from `x` (initial guess in, best iterate out) with the chosen driver; the
    /// polyalgorithm follows the smoothing path when `smoothing` is given (plain Newton
    /// has no use for it).
    pub fn solve<P, S>(
        &self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
        smoothing: Option<SmoothingOf<P>>,
    ) -> Result<NewtonReport, NewtonError>
    where
        P: GeneralizedJacobian + ?Sized,
        S: Factorize<P::Jacobian> + ?Sized,
    {
        match self {
            Self::Newton(options) => newton::solve(problem, linear, x, options),
            Self::Polyalgorithm(options) => Polyalgorithm::<P::Jacobian>::new(*options)?
                .solve_with(problem, linear, x, smoothing),
        }
    }
}

/// Whether `termination` is the problem's own error, which ends the polyalgorithm too.
fn ends_run(termination: &Termination) -> bool {
    matches!(termination, Termination::Evaluation(e) if e.ends_run())
}
