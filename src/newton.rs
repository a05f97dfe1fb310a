//! Semismooth Newton method with line-search globalization.
//!
//! Each iteration solves `J_k d = -F(x_k)` with `J_k` an element of the generalized
//! Jacobian (provided by the problem, [`GeneralizedJacobian`]), then takes
//! `x_{k+1} = x_k + alpha_k d` with `alpha_k` from the chosen [`Globalization`] on the
//! merit `m(x) = 0.5 |F(x)|^2` (Qi & Sun 1993, Math. Program. 58; globalization as in
//! De Luca, Facchinei & Kanzow 1996, Math. Program. 75, and Grippo, Lampariello &
//! Lucidi 1986 for the non-monotone rule). Near a BD-regular solution of a strongly
//! semismooth `F`, the full step is accepted and convergence is Q-quadratic.
//!
//! The driver owns the loop; the line search sees only `alpha -> merit`
//! ([`crate::linesearch`]); the linear solver only matrices and right-hand sides
//! ([`LinearSolve`]). [`NewtonSolver`] keeps all buffers (and the Jacobian) between
//! solves, so continuation and parameter sweeps allocate nothing per iteration; [`solve`]
//! is a one-shot wrapper.
//!
//! Options and defaults ([`NewtonOptions`]):
//!
//! | field | default | meaning |
//! |---|---|---|
//! | `absolute_tolerance` | `1e-10` | converged when `\|F\|_2 <= max(abs, rel \|F(x_0)\|_2)` |
//! | `relative_tolerance` | `0` (off) | see above; in `[0, 1)` |
//! | `step_tolerance` | `1e-15` | stalled when `alpha \|d\| <= step_tol (1 + \|x\|)` |
//! | `max_iterations` | `100` | Newton iterations (not counting line-search trials) |
//! | `globalization` | `NonMonotone { memory: 10, .. }` | none, Armijo or non-monotone |
//!
//! ```
//! use faer::Mat;
//! use semismooth::linalg::FaerDenseLu;
//! use semismooth::newton::{solve, NewtonOptions};
//! use semismooth::{GeneralizedJacobian, Residual};
//!
//! /// F(x) = min(x, A x + q) for the LCP with A = [[2, 1], [1, 2]], q = [-1, 1]:
//! /// solution x = [0.5, 0] (w = A x + q = [0, 1.5]).
//! struct Lcp;
//! const A: [[f64; 2]; 2] = [[2.0, 1.0], [1.0, 2.0]];
//! const Q: [f64; 2] = [-1.0, 1.0];
//! impl Residual for Lcp {
//!     fn dim(&self) -> usize { 2 }
//!     fn residual(&mut self, x: &[f64], out: &mut [f64]) {
//!         for i in 0..2 {
//!             let w = A[i][0] * x[0] + A[i][1] * x[1] + Q[i];
//!             out[i] = x[i].min(w);
//!         }
//!     }
//! }
//! impl GeneralizedJacobian for Lcp {
//!     type Jacobian = Mat<f64>;
//!     fn new_jacobian(&self) -> Mat<f64> { Mat::zeros(2, 2) }
//!     fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) {
//!         for i in 0..2 {
//!             let w = A[i][0] * x[0] + A[i][1] * x[1] + Q[i];
//!             for j in 0..2 {
//!                 // min picks x_i where x_i <= w_i (row of I), else w_i (row of A).
//!                 jac[(i, j)] = if x[i] <= w { (i == j) as u8 as f64 } else { A[i][j] };
//!             }
//!         }
//!     }
//! }
//!
//! let mut x = [1.0, 1.0];
//! let report = solve(&mut Lcp, &mut FaerDenseLu::new(), &mut x, &NewtonOptions::default())
//!     .unwrap()
//!     .into_result()
//!     .unwrap();
//! assert!((x[0] - 0.5).abs() < 1e-12 && x[1].abs() < 1e-12);
//! assert!(report.iterations <= 5);
//! ```

use std::ops::AddAssign;

use crate::linalg::LinearSolveError;
use crate::linesearch::{backtrack, NonMonotoneHistory};
pub use crate::linesearch::{InvalidLineSearchOption, LineSearchOptions};
use crate::{GeneralizedJacobian, LinearSolve};

/// How the step length is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Globalization {
    /// Always the full step `alpha = 1` (local method).
    None,
    /// Armijo backtracking on `0.5 |F|^2`: monotone decrease.
    Armijo(LineSearchOptions),
    /// Grippo–Lampariello–Lucidi: Armijo against the largest merit of the last
    /// `memory` iterates (`memory >= 1`; `1` is Armijo).
    NonMonotone {
        /// Number of past merits in the reference (default 10).
        memory: usize,
        /// Backtracking options.
        line_search: LineSearchOptions,
    },
    /// Full steps first, then the non-monotone line search: the first `full_steps`
    /// iterations take `alpha = 1` whenever `F` stays finite (semismooth Newton on
    /// complementarity systems then behaves as a primal-dual active-set method, which
    /// may cross regions of large residual on its way to the solution); if it has not
    /// converged by then, it restarts from the initial guess with the GLL line search
    /// (the best iterate of both phases is returned).
    Hybrid {
        /// Iterations of the full-step phase.
        full_steps: usize,
        /// Memory of the non-monotone phase (`>= 1`).
        memory: usize,
        /// Backtracking options of the non-monotone phase.
        line_search: LineSearchOptions,
    },
}

impl Globalization {
    /// [`Globalization::Hybrid`] with 30 full steps, then GLL with memory 10.
    pub fn hybrid() -> Self {
        Self::Hybrid {
            full_steps: 30,
            memory: 10,
            line_search: LineSearchOptions::default(),
        }
    }
}

impl Default for Globalization {
    fn default() -> Self {
        Self::NonMonotone {
            memory: 10,
            line_search: LineSearchOptions::default(),
        }
    }
}

/// Options of the Newton driver (defaults in the [module docs](self)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NewtonOptions {
    /// Absolute tolerance on `|F|_2`, `>= 0`.
    pub absolute_tolerance: f64,
    /// Relative tolerance on `|F|_2 / |F(x_0)|_2`, in `[0, 1)` (0 = off).
    pub relative_tolerance: f64,
    /// Stall threshold on the accepted step, `>= 0`.
    pub step_tolerance: f64,
    /// Maximum number of Newton iterations.
    pub max_iterations: usize,
    /// Step-length rule.
    pub globalization: Globalization,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self {
            absolute_tolerance: 1e-10,
            relative_tolerance: 0.0,
            step_tolerance: 1e-15,
            max_iterations: 100,
            globalization: Globalization::default(),
        }
    }
}

impl NewtonOptions {
    /// Checks every field; the error names the field, the value and the allowed range.
    pub fn validate(&self) -> Result<(), NewtonError> {
        let invalid = |name, value, allowed| NewtonError::InvalidOption {
            name,
            value,
            allowed,
        };
        let t = self.absolute_tolerance;
        if !(t.is_finite() && t >= 0.0) {
            return Err(invalid("absolute_tolerance", t, "finite and >= 0"));
        }
        let t = self.relative_tolerance;
        if !(t.is_finite() && (0.0..1.0).contains(&t)) {
            return Err(invalid("relative_tolerance", t, "[0, 1)"));
        }
        let t = self.step_tolerance;
        if !(t.is_finite() && t >= 0.0) {
            return Err(invalid("step_tolerance", t, "finite and >= 0"));
        }
        let line_search = match self.globalization {
            Globalization::None => None,
            Globalization::Armijo(ls) => Some(ls),
            Globalization::NonMonotone {
                memory,
                line_search,
            }
            | Globalization::Hybrid {
                memory,
                line_search,
                ..
            } => {
                if memory == 0 {
                    return Err(invalid("globalization.memory", 0.0, ">= 1"));
                }
                Some(line_search)
            }
        };
        if let Some(ls) = line_search {
            ls.validate().map_err(|e| {
                let name = match e.name {
                    "sufficient_decrease" => "line_search.sufficient_decrease",
                    "shrink" => "line_search.shrink",
                    _ => "line_search.min_step",
                };
                invalid(name, e.value, e.allowed)
            })?;
        }
        Ok(())
    }
}

/// Why the iteration stopped.
#[derive(Clone, Debug, PartialEq)]
pub enum Termination {
    /// `|F| <= max(absolute, relative |F(x_0)|)`.
    Converged,
    /// `max_iterations` reached without convergence.
    MaxIterations,
    /// The accepted step `alpha |d|` fell below `step_tolerance (1 + |x|)`.
    Stalled,
    /// No step length `>= min_step` gave sufficient decrease.
    LineSearchFailed,
    /// The Jacobian could not be factored (or the solve failed).
    SingularJacobian(LinearSolveError),
    /// `F` or the Newton direction had a NaN or infinite component.
    NonFinite,
}

/// Work done by a solve. Summable (`+=`) over several solves.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorkCounters {
    /// Calls to `Residual::residual` (including line-search trials).
    pub residual_evaluations: u64,
    /// Calls to `GeneralizedJacobian::jacobian`.
    pub jacobian_evaluations: u64,
    /// Calls to `LinearSolve::factor` (successful or not).
    pub factorizations: u64,
    /// Calls to `LinearSolve::solve_in_place`.
    pub linear_solves: u64,
    /// Rejected line-search trials.
    pub line_search_backtracks: u64,
    /// FFTs performed by the problem during the solve (difference of `fft_count`).
    pub ffts: u64,
}

impl AddAssign for WorkCounters {
    fn add_assign(&mut self, rhs: Self) {
        self.residual_evaluations += rhs.residual_evaluations;
        self.jacobian_evaluations += rhs.jacobian_evaluations;
        self.factorizations += rhs.factorizations;
        self.linear_solves += rhs.linear_solves;
        self.line_search_backtracks += rhs.line_search_backtracks;
        self.ffts += rhs.ffts;
    }
}

/// What a Newton run did.
#[derive(Clone, Debug, PartialEq)]
pub struct NewtonReport {
    /// Why it stopped.
    pub termination: Termination,
    /// Accepted Newton steps.
    pub iterations: usize,
    /// `|F|_2` at the initial guess and after each accepted step (`iterations + 1` values).
    pub residual_norms: Vec<f64>,
    /// Accepted step lengths `alpha_k` (`iterations` values).
    pub step_lengths: Vec<f64>,
    /// Accepted step norms `alpha_k |d_k|_2` (`iterations` values).
    pub step_norms: Vec<f64>,
    /// Estimated order `q` from the last three residual norms,
    /// `log(r_{k+1}/r_k) / log(r_k/r_{k-1})` (also for runs that did not converge: a
    /// stalled or capped run shows its rate); `None` with fewer than three norms, when
    /// one of them is below `1e-300` (exact termination, e.g. the active set was found
    /// and the remaining system was linear), or when the estimate is undefined.
    pub observed_order: Option<f64>,
    /// Work counters.
    pub counters: WorkCounters,
}

impl NewtonReport {
    /// Whether the termination is [`Termination::Converged`].
    pub fn converged(&self) -> bool {
        self.termination == Termination::Converged
    }

    /// `|F|_2` at the returned `x`, the best accepted iterate (the smallest entry of
    /// [`residual_norms`](Self::residual_norms)); `NaN` only if `F(x_0)` was not finite.
    pub fn residual_norm(&self) -> f64 {
        self.residual_norms
            .iter()
            .copied()
            .reduce(f64::min)
            .unwrap_or(f64::NAN)
    }

    /// `Ok(self)` if converged, otherwise [`NewtonError::NotConverged`] with the numbers.
    pub fn into_result(self) -> Result<NewtonReport, NewtonError> {
        if self.converged() {
            Ok(self)
        } else {
            Err(NewtonError::NotConverged {
                initial_residual_norm: self.residual_norms.first().copied().unwrap_or(f64::NAN),
                residual_norm: self.residual_norm(),
                iterations: self.iterations,
                termination: self.termination,
            })
        }
    }
}

/// The solver could not run, or (through [`NewtonReport::into_result`]) did not converge.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NewtonError {
    /// An option is outside its allowed range.
    #[error("invalid Newton option {name} = {value}: allowed {allowed}")]
    InvalidOption {
        /// Field name (dotted for nested fields).
        name: &'static str,
        /// Rejected value.
        value: f64,
        /// Allowed range.
        allowed: &'static str,
    },
    /// `x` does not have the problem's dimension.
    #[error("initial guess has length {found}, the problem has dimension {expected}")]
    DimensionMismatch {
        /// `problem.dim()`.
        expected: usize,
        /// `x.len()`.
        found: usize,
    },
    /// The run stopped without convergence.
    #[error(
        "Newton did not converge ({termination:?}) after {iterations} iterations: |F| = {residual_norm:e} (initial {initial_residual_norm:e})"
    )]
    NotConverged {
        /// Why it stopped.
        termination: Termination,
        /// Iterations done.
        iterations: usize,
        /// Best residual norm reached.
        residual_norm: f64,
        /// Residual norm at the initial guess.
        initial_residual_norm: f64,
    },
}

fn norm2(v: &[f64]) -> f64 {
    // Infinity for any NaN/inf component; scaled to avoid overflow (diverging iterates)
    // and underflow of the squares.
    let mut scale = 0.0_f64;
    for x in v {
        if !x.is_finite() {
            return f64::INFINITY;
        }
        scale = scale.max(x.abs());
    }
    if scale == 0.0 {
        return 0.0;
    }
    scale * v.iter().map(|x| (x / scale).powi(2)).sum::<f64>().sqrt()
}

/// `log(r3/r2) / log(r2/r1)` from the last three norms, see
/// [`NewtonReport::observed_order`].
fn observed_order(norms: &[f64]) -> Option<f64> {
    let [r1, r2, r3] = norms.get(norms.len().checked_sub(3)?..)? else {
        return None;
    };
    if [r1, r2, r3]
        .iter()
        .any(|r| !(r.is_finite() && **r >= 1e-300))
    {
        return None;
    }
    let q = (r3 / r2).ln() / (r2 / r1).ln();
    q.is_finite().then_some(q)
}

/// A reusable semismooth Newton solver: options plus every buffer of the iteration and
/// the Jacobian `J`, kept between [`NewtonSolver::solve`] calls.
///
/// The Jacobian is created by the problem's `new_jacobian` on the first solve and again
/// only when the dimension changes (call [`NewtonSolver::clear_jacobian`] to force it).
/// After a solve the linear solver holds the factorization of the Jacobian at the last
/// iterate where a Newton direction was computed (not necessarily the returned `x`).
#[derive(Debug)]
pub struct NewtonSolver<J> {
    options: NewtonOptions,
    jacobian: Option<J>,
    dim: usize,
    f: Vec<f64>,
    f_trial: Vec<f64>,
    direction: Vec<f64>,
    trial: Vec<f64>,
    best_x: Vec<f64>,
    start_x: Vec<f64>,
    history: NonMonotoneHistory,
}

impl<J> NewtonSolver<J> {
    /// A solver with validated `options`.
    pub fn new(options: NewtonOptions) -> Result<Self, NewtonError> {
        options.validate()?;
        Ok(Self {
            options,
            jacobian: None,
            dim: 0,
            f: Vec::new(),
            f_trial: Vec::new(),
            direction: Vec::new(),
            trial: Vec::new(),
            best_x: Vec::new(),
            start_x: Vec::new(),
            history: NonMonotoneHistory::new(1),
        })
    }

    /// The options in use.
    pub fn options(&self) -> &NewtonOptions {
        &self.options
    }

    /// Replaces the options (validated first; unchanged on error).
    pub fn set_options(&mut self, options: NewtonOptions) -> Result<(), NewtonError> {
        options.validate()?;
        self.options = options;
        Ok(())
    }

    /// Drops the stored Jacobian so the next solve asks the problem for a new one.
    pub fn clear_jacobian(&mut self) {
        self.jacobian = None;
    }

    /// The residual `F(x)` at the returned `x` of the last solve (empty before any solve).
    pub fn residual(&self) -> &[f64] {
        &self.f[..self.dim.min(self.f.len())]
    }

    fn resize(&mut self, n: usize) {
        if self.dim != n {
            self.jacobian = None;
        }
        self.dim = n;
        for v in [
            &mut self.f,
            &mut self.f_trial,
            &mut self.direction,
            &mut self.trial,
            &mut self.best_x,
            &mut self.start_x,
        ] {
            v.resize(n, 0.0);
        }
    }

    /// Runs semismooth Newton from `x` (initial guess in, best iterate out).
    ///
    /// `Ok(report)` whenever it ran, converged or not ([`NewtonReport::converged`],
    /// [`NewtonReport::into_result`]); `Err` only for a dimension mismatch. `x` always
    /// holds finite values on return if it did on entry.
    pub fn solve<P, S>(
        &mut self,
        problem: &mut P,
        linear: &mut S,
        x: &mut [f64],
    ) -> Result<NewtonReport, NewtonError>
    where
        P: GeneralizedJacobian<Jacobian = J> + ?Sized,
        S: LinearSolve<J> + ?Sized,
    {
        let n = problem.dim();
        if x.len() != n {
            return Err(NewtonError::DimensionMismatch {
                expected: n,
                found: x.len(),
            });
        }
        self.resize(n);
        let options = self.options;
        let fft_start = problem.fft_count();
        let mut counters = WorkCounters::default();
        let capacity = options.max_iterations.min(1000);
        let mut residual_norms = Vec::with_capacity(capacity + 1);
        let mut step_lengths = Vec::with_capacity(capacity);
        let mut step_norms = Vec::with_capacity(capacity);

        problem.residual(x, &mut self.f);
        counters.residual_evaluations += 1;
        let mut norm = norm2(&self.f);
        residual_norms.push(norm);
        let tolerance = options
            .absolute_tolerance
            .max(options.relative_tolerance * norm);
        let (memory, line_search, mut full_steps) = match options.globalization {
            Globalization::None => (1, None, 0),
            Globalization::Armijo(ls) => (1, Some(ls), 0),
            Globalization::NonMonotone {
                memory,
                line_search,
            } => (memory, Some(line_search), 0),
            Globalization::Hybrid {
                full_steps,
                memory,
                line_search,
            } => (memory, Some(line_search), full_steps),
        };
        self.history.reset(memory);
        self.history.push(0.5 * norm * norm);
        self.best_x.copy_from_slice(x);
        self.start_x.copy_from_slice(x);
        let mut best_norm = norm;
        let mut iterations = 0;

        let termination = 'newton: {
            if !norm.is_finite() {
                break 'newton Termination::NonFinite;
            }
            if norm <= tolerance {
                break 'newton Termination::Converged;
            }
            let jac = self.jacobian.get_or_insert_with(|| problem.new_jacobian());
            while iterations < options.max_iterations {
                if full_steps > 0 && iterations == full_steps {
                    // End of the full-step phase: start again from the initial guess with
                    // the line search (the full steps may have wandered into a region where
                    // descent stalls; the best iterate so far is still kept and returned if
                    // nothing better is found).
                    full_steps = 0;
                    x.copy_from_slice(&self.start_x);
                    problem.residual(x, &mut self.f);
                    counters.residual_evaluations += 1;
                    norm = norm2(&self.f);
                    self.history.reset(memory);
                    self.history.push(0.5 * norm * norm);
                }
                problem.jacobian(x, jac);
                counters.jacobian_evaluations += 1;
                counters.factorizations += 1;
                if let Err(e) = linear.factor(jac) {
                    break 'newton Termination::SingularJacobian(e);
                }
                for (d, f) in self.direction.iter_mut().zip(&self.f) {
                    *d = -f;
                }
                counters.linear_solves += 1;
                if let Err(e) = linear.solve_in_place(&mut self.direction) {
                    break 'newton Termination::SingularJacobian(e);
                }
                if self.direction.iter().any(|d| !d.is_finite()) {
                    break 'newton Termination::NonFinite;
                }

                let merit0 = 0.5 * norm * norm;
                let (f_trial, trial, direction) =
                    (&mut self.f_trial, &mut self.trial, &self.direction);
                let mut merit = |alpha: f64| {
                    for ((t, xi), d) in trial.iter_mut().zip(x.iter()).zip(direction) {
                        *t = xi + alpha * d;
                    }
                    problem.residual(trial, f_trial);
                    counters.residual_evaluations += 1;
                    let r = norm2(f_trial);
                    if r.is_finite() {
                        0.5 * r * r
                    } else {
                        f64::INFINITY
                    }
                };
                let mut alpha_taken = 1.0;
                let full_step_phase = iterations < full_steps;
                if full_step_phase && merit(1.0).is_finite() {
                    // Full step accepted without a merit test.
                } else if let Some(ls) = line_search {
                    if full_step_phase {
                        // A non-finite full step ends the full-step phase.
                        full_steps = 0;
                        self.history.reset(memory);
                        self.history.push(merit0);
                    }
                    match backtrack(self.history.reference(), -2.0 * merit0, &ls, &mut merit) {
                        Ok(step) => {
                            counters.line_search_backtracks += step.backtracks;
                            alpha_taken = step.step;
                        }
                        Err(fail) => {
                            counters.line_search_backtracks += fail.backtracks;
                            break 'newton Termination::LineSearchFailed;
                        }
                    }
                } else if !merit(1.0).is_finite() {
                    break 'newton Termination::NonFinite;
                }
                let alpha = alpha_taken;

                // Accept: x <- trial, F <- F(trial).
                x.copy_from_slice(&self.trial);
                std::mem::swap(&mut self.f, &mut self.f_trial);
                norm = norm2(&self.f);
                iterations += 1;
                let step_norm = alpha * norm2(&self.direction);
                residual_norms.push(norm);
                step_lengths.push(alpha);
                step_norms.push(step_norm);
                self.history.push(0.5 * norm * norm);
                if norm < best_norm {
                    best_norm = norm;
                    self.best_x.copy_from_slice(x);
                }
                if norm <= tolerance {
                    break 'newton Termination::Converged;
                }
                if step_norm <= options.step_tolerance * (1.0 + norm2(x)) {
                    break 'newton Termination::Stalled;
                }
            }
            Termination::MaxIterations
        };

        // Return the best iterate (non-monotone steps and failures may end elsewhere).
        if norm.is_nan() || best_norm < norm {
            x.copy_from_slice(&self.best_x);
            problem.residual(x, &mut self.f);
            counters.residual_evaluations += 1;
        }
        counters.ffts = problem.fft_count().saturating_sub(fft_start);
        Ok(NewtonReport {
            observed_order: observed_order(&residual_norms),
            termination,
            iterations,
            residual_norms,
            step_lengths,
            step_norms,
            counters,
        })
    }
}

/// One-shot semismooth Newton: validates `options`, runs [`NewtonSolver::solve`].
///
/// `x`: initial guess in, best iterate out. `Ok(report)` whenever it ran (converged or
/// not); `Err` only when it could not run (invalid options, dimension mismatch).
pub fn solve<P, S>(
    problem: &mut P,
    solver: &mut S,
    x: &mut [f64],
    options: &NewtonOptions,
) -> Result<NewtonReport, NewtonError>
where
    P: GeneralizedJacobian + ?Sized,
    S: LinearSolve<P::Jacobian> + ?Sized,
{
    NewtonSolver::<P::Jacobian>::new(*options)?.solve(problem, solver, x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn observed_order_from_last_three_norms() {
        let q = observed_order(&[1.0, 1e-2, 1e-4, 1e-8]).unwrap();
        assert!((q - 2.0).abs() < 1e-12);
        assert_eq!(observed_order(&[1.0, 1e-2]), None);
        assert_eq!(observed_order(&[1.0, 1e-2, 0.0]), None);
        assert_eq!(observed_order(&[1.0, 1.0, 0.5]), None);
    }

    #[test]
    fn norm_does_not_overflow_and_flags_non_finite() {
        assert!((norm2(&[3e200, 4e200]) / 5e200 - 1.0).abs() < 1e-15);
        assert_eq!(norm2(&[0.0, 0.0]), 0.0);
        assert_eq!(norm2(&[1.0, f64::NAN]), f64::INFINITY);
        assert_eq!(norm2(&[f64::INFINITY]), f64::INFINITY);
    }

    #[test]
    fn validation_names_field_value_and_range() {
        let o = NewtonOptions {
            relative_tolerance: 1.0,
            ..Default::default()
        };
        assert_eq!(
            o.validate(),
            Err(NewtonError::InvalidOption {
                name: "relative_tolerance",
                value: 1.0,
                allowed: "[0, 1)"
            })
        );
        let o = NewtonOptions {
            globalization: Globalization::NonMonotone {
                memory: 0,
                line_search: LineSearchOptions::default(),
            },
            ..Default::default()
        };
        assert!(matches!(
            o.validate(),
            Err(NewtonError::InvalidOption {
                name: "globalization.memory",
                ..
            })
        ));
        let o = NewtonOptions {
            globalization: Globalization::Armijo(LineSearchOptions {
                shrink: 0.0,
                ..Default::default()
            }),
            ..Default::default()
        };
        assert!(
            matches!(o.validate(), Err(NewtonError::InvalidOption { name: "line_search.shrink", value, .. }) if value == 0.0)
        );
        let o = NewtonOptions {
            absolute_tolerance: f64::NAN,
            ..Default::default()
        };
        assert!(matches!(
            o.validate(),
            Err(NewtonError::InvalidOption {
                name: "absolute_tolerance",
                ..
            })
        ));
        assert!(NewtonOptions::default().validate().is_ok());
    }
}
