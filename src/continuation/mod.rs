//! Pseudo-arclength continuation of a branch of solutions of `F(x, p) = 0`, and a
//! natural-parameter sweep to compare it with.
//!
//! # The method
//!
//! Points `y = (x, p)` of the branch are measured with the weighted inner product
//! (BifurcationKit's `theta`, see Keller 1977 and Doedel's AUTO notes)
//!
//! ```text
//! <(a, α), (b, β)>_θ = (θ / n) a·b + (1 - θ) α β,        |y|_θ = sqrt(<y, y>_θ),
//! ```
//!
//! (with [`ContinuationOptions::state_scale`] `s`, `a·b` becomes `Σ a_i b_i / s_i^2`),
//! and step lengths `ds` are lengths in that norm. From an accepted point `y0` with unit
//! direction `t` (tangent for the first step, secant afterwards by default) the predictor is
//! `y0 + ds t`; the corrector is Newton on the bordered system
//!
//! ```text
//! F(x, p) = 0,    N(x, p) = <t, y - y0>_θ - ds = 0,
//! [[J, F_p], [w_x^T, w_p]] [dx; dp] = -[F; N],    w_x = (θ/n) t_x,  w_p = (1-θ) t_p,
//! ```
//!
//! solved by block elimination with ONE factorization of `J` per corrector iteration and two
//! solves, `J a = F_p` and `J b = F`: `dp = (w_x·b - N) / (w_p - w_x·a)`, `dx = -b - a dp`.
//! The bordered matrix is never assembled, so structured Jacobians (sparse, condensed)
//! keep their structure. The tangent at the converged point comes for free from the last
//! `a`: it is `±(-a, 1)` normalised (the kernel of `[J, F_p]`), with `J` and `F_p` from
//! the last corrector iteration, i.e. at the iterate before the converged one (an error
//! of the size of the last correction; the corrector always takes at least one step).
//!
//! # Folds and the dense fallback
//!
//! At a fold `J` is singular while the bordered matrix is not. Block elimination then loses
//! accuracy (the pivot `w_p - w_x·a` is a difference of large numbers) or the factorization
//! reports [`LinearSolveError::Singular`]. In practice the iterates rarely hit the singular
//! set exactly, and block elimination passes folds (the tests pass several). For Jacobians
//! that are singular on whole regions (piecewise-linear problems with a flat piece), the
//! continuation can fall back to a dense LU of the assembled `(n+1) x (n+1)` bordered
//! matrix. This is an optional capability chosen by a second entry point,
//! [`Continuation::with_dense_fallback`], which exists only when the Jacobian type
//! implements [`DenseAssemble`]; structured Jacobians that cannot be assembled use
//! [`Continuation::new`] and report a corrector failure instead (the step is then halved).
//!
//! # Step control
//!
//! After an accepted point corrected in `k` iterations the step is multiplied by
//! `sqrt(target_iterations / k)` clamped to `[1/2, 2]`, then clamped to
//! `[min_step, max_step]`. A failed corrector halves the step (not below `min_step`) and
//! restores the problem's parameter (`set_parameter`) to the last accepted point. The run
//! ends when an attempt at `min_step` fails ([`ContinuationTermination::StepTooSmall`]),
//! after `max_consecutive_failures` failures in a row
//! ([`ContinuationTermination::TooManyFailures`]), when the parameter leaves
//! `[parameter_min, parameter_max]` (the last point is then re-solved at the bound), or after
//! `max_points` points.
//!
//! Folds are detected as sign changes of the parameter component of the tangent, oriented
//! along the step just taken, confirmed by a reversal of the parameter's increments between
//! accepted points, and located by cubic Hermite interpolation of `p(s)` (values and slopes
//! `dp/ds = t_p` at both points); a reversal at a corner of a piecewise-smooth branch (no
//! sign change of `t_p`) is a fold at the extreme point ([`FoldDetector`], also usable on
//! branches stitched together from several runs).
//!
//! # Corners
//!
//! Branches of semismooth problems are only piecewise smooth. Where the branch turns by
//! more than 90° in the θ-norm at a corner, the pseudo-arclength hyperplane (normal to the
//! incoming direction `d`) no longer cuts the far piece, whatever the step: halving ends
//! the run there. Before giving up ([`ContinuationOptions::pass_corners`]), the step that
//! failed last is tried twice more from the last point: on the hyperplane normal to `d`'s
//! state part only, `d_x · (x - x_k) = ds |d_x|²` (cuts a far piece along which the state
//! keeps moving forward, e.g. a fold at a corner), then at the next parameter
//! `p_k + sign(d_p) ds / sqrt(1 - θ)` (cuts a far piece along which the parameter keeps
//! moving). A point found this way ([`ContinuationCounters::corner_passes`]) is accepted
//! with its tangent oriented along that constraint's normal, and the next predictor
//! follows that tangent (the chord across the corner is no direction for the far piece).
//!
//! The corrector takes full Newton steps unless
//! [`ContinuationOptions::corrector_line_search`] asks for Armijo backtracking on
//! `(|F|^2 + N^2) / 2` ([`crate::linesearch::backtrack`]).
//!
//! # Style
//!
//! [`Continuation`] is an [`Iterator`] over accepted points (BifurcationKit's style); the
//! first item is the starting point corrected at fixed `p0`. [`Continuation::run`] collects a
//! whole [`Branch`]. [`natural_sweep`] solves at a list of parameters with
//! [`crate::newton`] from the previous solution, for comparison: it fails or jumps at folds.
//!
//! References: H. B. Keller, *Numerical solution of bifurcation and nonlinear eigenvalue
//! problems* (1977); E. Allgower & K. Georg, *Numerical Continuation Methods* (1990), for
//! the bordered system and its block elimination; BifurcationKit.jl (`Palc`) for the
//! θ-weighted arclength and the iterator; NLvib for the step bounds.
//!
//! ```
//! use faer::Mat;
//! use semismooth::continuation::{Continuation, ContinuationOptions, ContinuationTermination};
//! use semismooth::linalg::FaerDenseLu;
//! use semismooth::{EvaluationError, GeneralizedJacobian, ParameterDependent, Residual};
//!
//! /// The S-curve x^3 - x - p = 0 (folds at p = ±2/(3√3)).
//! struct SCurve { p: f64 }
//! impl Residual for SCurve {
//!     fn dim(&self) -> usize { 1 }
//!     fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
//!         out[0] = x[0].powi(3) - x[0] - self.p;
//!         Ok(())
//!     }
//! }
//! impl GeneralizedJacobian for SCurve {
//!     type Jacobian = Mat<f64>;
//!     fn new_jacobian(&self) -> Mat<f64> { Mat::zeros(1, 1) }
//!     fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
//!         jac[(0, 0)] = 3.0 * x[0] * x[0] - 1.0;
//!         Ok(())
//!     }
//! }
//! impl ParameterDependent for SCurve {
//!     fn parameter(&self) -> f64 { self.p }
//!     fn set_parameter(&mut self, p: f64) { self.p = p; }
//! }
//!
//! let mut problem = SCurve { p: -1.0 };
//! let mut solver = FaerDenseLu::new();
//! let options = ContinuationOptions { parameter_min: -1.0, parameter_max: 1.0, ..Default::default() };
//! let branch = Continuation::new(&mut problem, &mut solver, &[-1.3], -1.0, options)
//!     .unwrap()
//!     .run()
//!     .unwrap();
//! assert_eq!(branch.fold_parameters().len(), 2);
//! assert!(matches!(branch.termination, ContinuationTermination::ReachedBound { .. }));
//! ```

mod branch;
mod corrector;
mod folds;
mod natural;
mod options;

pub use branch::{
    Branch, BranchPoint, ContinuationCounters, ContinuationError, ContinuationEvent,
    ContinuationTermination, CorrectorFailure,
};
pub use folds::FoldDetector;
pub use natural::{natural_sweep, NaturalSweep, SweepFailure, SweepPoint};
pub use options::{ContinuationOptions, Direction, Predictor, BORDER_PIVOT_THRESHOLD};

use corrector::{
    Bordered, Constraint, Corrected, Corrector, CorrectorCounts, DenseAssembler, Metric,
};

use crate::linalg::DenseAssemble;
use crate::newton::kernel::{armijo, KernelRules};
use crate::newton::WorkCounters;
use crate::{Factorize, GeneralizedJacobian, ParameterDependent, ProblemCounters};

enum Phase {
    NotStarted { x0: Vec<f64>, p0: f64 },
    Running,
    Finished,
}

/// Pseudo-arclength continuation as an iterator over accepted [`BranchPoint`]s.
///
/// The first item is the starting point corrected at fixed `p0` by the continuation's own
/// corrector (Newton, with the line search of
/// [`ContinuationOptions::corrector_line_search`] if set; from a poor guess, solve first
/// with [`crate::newton`]). An `Err` item
/// (the start could not be corrected) ends the iteration. When the iteration ends,
/// [`Continuation::termination`] says why, [`Continuation::events`] lists the folds and the
/// problem's parameter is that of the last accepted point.
pub struct Continuation<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    problem: &'a mut P,
    solver: &'a mut S,
    options: ContinuationOptions,
    fallback: Option<DenseAssembler<P::Jacobian>>,
    metric: Metric,
    bordered: Bordered<P::Jacobian>,
    work: WorkCounters,
    corrector_counts: CorrectorCounts,
    phase: Phase,
    /// Last accepted point.
    last: Option<BranchPoint>,
    /// Unit tangent at the last accepted point (length n + 1).
    tangent: Vec<f64>,
    /// Unit predictor direction for the next step (length n + 1).
    direction: Vec<f64>,
    step: f64,
    points: usize,
    consecutive_failures: usize,
    /// Sign of the last non-zero tangent parameter component.
    folds: FoldDetector,
    events: Vec<ContinuationEvent>,
    termination: Option<ContinuationTermination>,
    counters: ContinuationCounters,
    problem_start: ProblemCounters,
}

impl<'a, P, S> Continuation<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    /// Prepares a continuation from the guess `x0` at parameter `p0`. Checks the options,
    /// the dimension and that `p0` is finite and within the bounds; the work starts with the
    /// first call of [`Iterator::next`].
    pub fn new(
        problem: &'a mut P,
        solver: &'a mut S,
        x0: &[f64],
        p0: f64,
        options: ContinuationOptions,
    ) -> Result<Self, ContinuationError> {
        options.validate()?;
        let n = problem.dim();
        if n == 0 || x0.len() != n {
            return Err(ContinuationError::DimensionMismatch {
                expected: n,
                found: x0.len(),
            });
        }
        if !p0.is_finite() || p0 < options.parameter_min || p0 > options.parameter_max {
            return Err(ContinuationError::InvalidStart {
                parameter: p0,
                min: options.parameter_min,
                max: options.parameter_max,
            });
        }
        if let Some(scale) = &options.state_scale {
            if scale.len() != n {
                return Err(ContinuationError::InvalidOption {
                    name: "state_scale",
                    value: scale.len() as f64,
                    allowed: "one entry per unknown (the problem's dimension)",
                });
            }
        }
        let metric = Metric::new(
            n,
            options.theta,
            options.state_scale.as_deref(),
            options.parameter_scale,
        );
        let bordered = Bordered::new(n, problem.new_jacobian());
        let problem_start = problem.problem_counters();
        let folds = FoldDetector::new(options.refine_folds);
        Ok(Self {
            problem,
            solver,
            step: options.initial_step,
            options,
            fallback: None,
            metric,
            bordered,
            work: WorkCounters::default(),
            corrector_counts: CorrectorCounts::default(),
            phase: Phase::NotStarted {
                x0: x0.to_vec(),
                p0,
            },
            last: None,
            tangent: vec![0.0; n + 1],
            direction: vec![0.0; n + 1],
            points: 0,
            consecutive_failures: 0,
            folds,
            events: Vec::new(),
            termination: None,
            counters: ContinuationCounters::default(),
            problem_start,
        })
    }

    /// Why the run stopped (`None` while it runs, or after a start failure).
    pub fn termination(&self) -> Option<&ContinuationTermination> {
        self.termination.as_ref()
    }

    /// Events found so far.
    pub fn events(&self) -> &[ContinuationEvent] {
        &self.events
    }

    /// Work done so far.
    pub fn counters(&self) -> ContinuationCounters {
        let mut c = self.counters;
        c.work = self.work;
        c.work.problem = self.problem.problem_counters().since(&self.problem_start);
        c.parameter_derivative_evaluations = self.corrector_counts.parameter_derivatives;
        c.dense_bordered_factorizations = self.corrector_counts.dense_factorizations;
        c.corrector_iterations = self.corrector_counts.iterations;
        c
    }

    /// The problem (its parameter is that of the last accepted point between items), e.g.
    /// to evaluate user quantities at the point just returned.
    pub fn problem(&self) -> &P {
        self.problem
    }

    /// The step length the next attempt will use.
    pub fn next_step(&self) -> f64 {
        self.step
    }

    /// Runs to the end and collects the branch.
    pub fn run(mut self) -> Result<Branch, ContinuationError> {
        let mut points = Vec::new();
        for item in self.by_ref() {
            points.push(item?);
        }
        let termination = self
            .termination
            .clone()
            .unwrap_or(ContinuationTermination::MaxPoints {
                points: points.len(),
            });
        Ok(Branch {
            points,
            events: std::mem::take(&mut self.events),
            termination,
            counters: self.counters(),
        })
    }

    fn finish(&mut self, termination: ContinuationTermination) {
        self.termination = Some(termination);
        self.phase = Phase::Finished;
    }

    /// Normalises the corrector's raw tangent in the θ-norm into `self.tangent`, oriented
    /// to have a non-negative inner product with `(ref_x, ref_p)`.
    fn take_tangent(&mut self, reference: Option<&[f64]>, ref_p: f64) {
        let n = self.metric.n;
        let raw = &self.bordered.tangent;
        let norm = self.metric.norm(&raw[..n], raw[n]);
        let mut t: Vec<f64> = raw.iter().map(|v| v / norm).collect();
        let orientation = match reference {
            Some(r) => self.metric.dot(&t[..n], t[n], &r[..n], r[n]),
            None => t[n] * ref_p,
        };
        if orientation < 0.0 {
            for v in &mut t {
                *v = -*v;
            }
        }
        self.tangent = t;
    }

    /// The corrector on this run's problem, solver, workspace and counters, from
    /// `(x, p)`; the converged point is written back. Also returns the smallest finite
    /// residual norm seen.
    fn correct_at(
        &mut self,
        x: &mut [f64],
        p: &mut f64,
        constraint: Constraint,
    ) -> (Result<Corrected, CorrectorFailure>, f64) {
        let n = self.metric.n;
        let mut y = Vec::with_capacity(n + 1);
        y.extend_from_slice(x);
        y.push(*p);
        let corrector = Corrector {
            problem: &mut *self.problem,
            solver: &mut *self.solver,
            ws: &mut self.bordered,
            fallback: self.fallback,
            metric: &self.metric,
            trust: None,
            rules: KernelRules {
                absolute_tolerance: self.options.corrector_tolerance,
                relative_tolerance: 0.0,
                residual_floor: 0.0,
                step_tolerance: self.options.step_tolerance,
                max_iterations: self.options.max_corrector_iterations,
                min_iterations: 1,
                globalization: armijo(self.options.corrector_line_search),
                restore_best: false,
            },
        };
        let outcome = corrector.correct(
            &mut y,
            constraint,
            &mut self.work,
            &mut self.corrector_counts,
        );
        x.copy_from_slice(&y[..n]);
        *p = y[n];
        outcome
    }

    fn start(&mut self, x0: Vec<f64>, p0: f64) -> Result<BranchPoint, ContinuationError> {
        let mut x = x0;
        let mut p = p0;
        let constraint = Constraint {
            arclength: false,
            w_p: 1.0,
            target: p0,
        };
        let (corrected, _) = self.correct_at(&mut x, &mut p, constraint);
        let corrected = match corrected {
            Ok(c) => c,
            Err(failure) => {
                self.problem.set_parameter(p0);
                self.phase = Phase::Finished;
                return Err(ContinuationError::StartNotConverged {
                    parameter: p0,
                    failure,
                });
            }
        };
        self.take_tangent(None, self.options.direction.sign());
        self.direction.copy_from_slice(&self.tangent);
        let n = self.metric.n;
        let point = BranchPoint {
            state: x,
            parameter: p,
            iterations: corrected.iterations,
            residual_norm: corrected.residual_norm,
            step: 0.0,
            tangent_parameter: self.tangent[n],
        };
        self.folds
            .push(point.parameter, point.tangent_parameter, 0.0);
        self.last = Some(point.clone());
        self.points = 1;
        self.phase = Phase::Running;
        if self.points >= self.options.max_points {
            self.finish(ContinuationTermination::MaxPoints {
                points: self.points,
            });
        }
        Ok(point)
    }

    /// Attempts steps until one is accepted (`Some`) or the run ends (`None`).
    fn advance(&mut self) -> Option<BranchPoint> {
        let n = self.metric.n;
        let last = self.last.clone()?;
        let mut x = vec![0.0; n];
        loop {
            let ds = self.step;
            for ((xi, si), di) in x.iter_mut().zip(&last.state).zip(&self.direction) {
                *xi = si + ds * di;
            }
            self.direction_weights();
            let mut p = last.parameter + ds * self.direction[n];
            let w_p = self.metric.parameter_dot(self.direction[n], 1.0);
            let w_dot_last: f64 = self
                .bordered
                .w
                .iter()
                .zip(&last.state)
                .map(|(u, v)| u * v)
                .sum::<f64>()
                + w_p * last.parameter;
            let constraint = Constraint {
                arclength: true,
                w_p,
                target: w_dot_last + ds,
            };
            let before = self.corrector_counts.iterations;
            let (corrected, smallest) = self.correct_at(&mut x, &mut p, constraint);
            match corrected {
                Ok(c) => return self.accept(&last, x, p, ds, c, None),
                Err(failure) => {
                    self.reject(before, last.parameter);
                    self.consecutive_failures += 1;
                    let ending = ds <= self.options.min_step
                        || self.consecutive_failures >= self.options.max_consecutive_failures;
                    if ending && self.options.pass_corners {
                        if let Some(point) = self.pass_corner(&last, ds) {
                            return point;
                        }
                    }
                    if ds <= self.options.min_step {
                        self.finish(ContinuationTermination::StepTooSmall {
                            parameter: last.parameter,
                            step: ds,
                            residual_norm: smallest,
                            failure,
                        });
                        return None;
                    }
                    if self.consecutive_failures >= self.options.max_consecutive_failures {
                        self.finish(ContinuationTermination::TooManyFailures {
                            parameter: last.parameter,
                            step: ds,
                            failures: self.consecutive_failures,
                            residual_norm: smallest,
                            failure,
                        });
                        return None;
                    }
                    self.step = (0.5 * ds).max(self.options.min_step);
                }
            }
        }
    }

    /// `w_x = (θ/n) s⁻² ⊙ d_x`: the state part of the normal of the arclength constraint
    /// along the current direction `d` (`s` the state scale, 1 without one).
    fn direction_weights(&mut self) {
        let n = self.metric.n;
        self.metric
            .state_normal(&self.direction[..n], &mut self.bordered.w);
    }

    /// Books a rejected attempt (begun at `before` corrector iterations) and restores the
    /// problem's parameter to the last accepted point's.
    fn reject(&mut self, before: u64, parameter: f64) {
        self.counters.rejected_steps += 1;
        self.counters.rejected_iterations += self.corrector_counts.iterations - before;
        self.problem.set_parameter(parameter);
    }

    /// The corner passes of the module documentation (*Corners*), with step `ds` from
    /// `last` along the current direction: first on the hyperplane normal to the direction's
    /// state part, then at the next parameter `p + ds / sqrt(1 - θ)` (sign of the direction's
    /// parameter component). `Some(result of accept)` when one converged.
    fn pass_corner(&mut self, last: &BranchPoint, ds: f64) -> Option<Option<BranchPoint>> {
        let n = self.metric.n;
        let d = self.direction.clone();
        let state_part = self.metric.dot(&d[..n], 0.0, &d[..n], 0.0);
        let parameter_part = self.metric.parameter_dot(d[n], d[n]);
        for on_state in [true, false] {
            let (scale, along, constraint) = if on_state {
                if state_part < 1e-6 {
                    continue;
                }
                self.direction_weights();
                let mut along = d.clone();
                along[n] = 0.0;
                let target: f64 = self
                    .bordered
                    .w
                    .iter()
                    .zip(&last.state)
                    .zip(&d)
                    .map(|((w, x), di)| w * (x + ds * di))
                    .sum();
                let constraint = Constraint {
                    arclength: true,
                    w_p: 0.0,
                    target,
                };
                (ds, along, constraint)
            } else {
                if parameter_part < 1e-6 {
                    continue;
                }
                let step_p = ds / self.metric.parameter_dot(1.0, 1.0).sqrt() * d[n].signum();
                let mut along = vec![0.0; n + 1];
                along[n] = d[n].signum();
                let constraint = Constraint {
                    arclength: false,
                    w_p: 1.0,
                    target: last.parameter + step_p,
                };
                (step_p / d[n], along, constraint)
            };
            let mut x: Vec<f64> = last
                .state
                .iter()
                .zip(&d)
                .map(|(x, di)| x + scale * di)
                .collect();
            let mut p = last.parameter + scale * d[n];
            let before = self.corrector_counts.iterations;
            match self.correct_at(&mut x, &mut p, constraint).0 {
                Ok(c) => {
                    self.counters.corner_passes += 1;
                    let step = self.metric.norm(
                        &x.iter()
                            .zip(&last.state)
                            .map(|(a, b)| a - b)
                            .collect::<Vec<_>>(),
                        p - last.parameter,
                    );
                    return Some(self.accept(last, x, p, step, c, Some(&along)));
                }
                Err(_) => self.reject(before, last.parameter),
            }
        }
        None
    }

    fn accept(
        &mut self,
        last: &BranchPoint,
        mut x: Vec<f64>,
        mut p: f64,
        ds: f64,
        corrected: Corrected,
        along: Option<&[f64]>,
    ) -> Option<BranchPoint> {
        let n = self.metric.n;
        self.consecutive_failures = 0;
        let direction = self.direction.clone();
        self.take_tangent(Some(&direction), 0.0);
        let mut iterations = corrected.iterations;
        let mut residual_norm = corrected.residual_norm;
        let mut step = ds;

        // Leaving the bounds: re-solve at the bound from the interpolated point.
        let bound = if p > self.options.parameter_max {
            Some(self.options.parameter_max)
        } else if p < self.options.parameter_min {
            Some(self.options.parameter_min)
        } else {
            None
        };
        if bound == Some(last.parameter) {
            // Already on the bound and heading out: nothing new to report.
            self.problem.set_parameter(last.parameter);
            self.finish(ContinuationTermination::ReachedBound {
                parameter: last.parameter,
                bound: last.parameter,
            });
            return None;
        }
        if let Some(pb) = bound {
            let lambda = (pb - last.parameter) / (p - last.parameter);
            let mut xb: Vec<f64> = last
                .state
                .iter()
                .zip(&x)
                .map(|(a, b)| a + lambda * (b - a))
                .collect();
            let mut pbv = pb;
            let constraint = Constraint {
                arclength: false,
                w_p: 1.0,
                target: pb,
            };
            let saved_tangent = self.tangent.clone();
            match self.correct_at(&mut xb, &mut pbv, constraint).0 {
                Ok(c) => {
                    self.take_tangent(Some(&direction), 0.0);
                    x = xb;
                    p = pbv;
                    iterations += c.iterations;
                    residual_norm = c.residual_norm;
                    step = lambda * ds;
                }
                Err(_) => {
                    self.tangent = saved_tangent;
                    // Keep the point outside the bound; the problem follows it.
                    self.problem.set_parameter(p);
                }
            }
        }

        // Secant direction for the next predictor.
        let dx: Vec<f64> = x.iter().zip(&last.state).map(|(a, b)| a - b).collect();
        let dpar = p - last.parameter;
        let chord = self.metric.norm(&dx, dpar);
        // Orient the tangent along the step just taken: where the branch turns sharply the
        // predictor's direction can make an obtuse angle with the new tangent, and orienting
        // by it would reverse the tangent (a spurious fold, and a tangent predictor heading
        // back along the branch). The secant always has a positive component along the
        // predictor (the arclength constraint), so it is the forward direction here.
        let forward = match along {
            Some(a) => self
                .metric
                .dot(&self.tangent[..n], self.tangent[n], &a[..n], a[n]),
            None if chord > 0.0 => self
                .metric
                .dot(&self.tangent[..n], self.tangent[n], &dx, dpar),
            None => 0.0,
        };
        if forward < 0.0 {
            for v in &mut self.tangent {
                *v = -*v;
            }
        }

        // Fold detection.
        let tp = self.tangent[n];
        if let Some(event) = self.folds.push(p, tp, chord) {
            self.events.push(event);
        }

        match self.options.predictor {
            // After a corner the chord cuts across it: the new piece's tangent is the way on.
            Predictor::Secant if chord > 0.0 && along.is_none() => {
                for (d, v) in self.direction.iter_mut().zip(&dx) {
                    *d = v / chord;
                }
                self.direction[n] = dpar / chord;
            }
            _ => self.direction.copy_from_slice(&self.tangent),
        }

        let factor = (self.options.target_iterations as f64 / iterations.max(1) as f64)
            .sqrt()
            .clamp(0.5, 2.0);
        self.step = (ds * factor).clamp(self.options.min_step, self.options.max_step);

        let point = BranchPoint {
            state: x,
            parameter: p,
            iterations,
            residual_norm,
            step,
            tangent_parameter: tp,
        };
        self.last = Some(point.clone());
        self.points += 1;
        if let Some(pb) = bound {
            self.finish(ContinuationTermination::ReachedBound {
                parameter: point.parameter,
                bound: pb,
            });
        } else if self.points >= self.options.max_points {
            self.finish(ContinuationTermination::MaxPoints {
                points: self.points,
            });
        }
        Some(point)
    }
}

impl<'a, P, S> Continuation<'a, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    P::Jacobian: DenseAssemble,
    S: Factorize<P::Jacobian> + ?Sized,
{
    /// Enables the dense fallback: when `J` is singular (the factorization fails) or the
    /// block-elimination pivot vanishes, the corrector assembles the `(n+1) x (n+1)`
    /// bordered matrix and solves it by dense LU (counted in
    /// [`ContinuationCounters::dense_bordered_factorizations`]). Only available when the
    /// Jacobian type implements [`DenseAssemble`]; meant for small or dense problems.
    pub fn with_dense_fallback(mut self) -> Self {
        self.fallback = Some(<P::Jacobian as DenseAssemble>::assemble_dense);
        self
    }
}

impl<P, S> Iterator for Continuation<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    type Item = Result<BranchPoint, ContinuationError>;

    fn next(&mut self) -> Option<Self::Item> {
        match std::mem::replace(&mut self.phase, Phase::Running) {
            Phase::Finished => {
                self.phase = Phase::Finished;
                None
            }
            Phase::NotStarted { x0, p0 } => Some(self.start(x0, p0)),
            Phase::Running => self.advance().map(Ok),
        }
    }
}

impl<P, S> std::iter::FusedIterator for Continuation<'_, P, S>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
}

/// Runs a whole continuation: [`Continuation::new`] then [`Continuation::run`].
pub fn run<P, S>(
    problem: &mut P,
    solver: &mut S,
    x0: &[f64],
    p0: f64,
    options: ContinuationOptions,
) -> Result<Branch, ContinuationError>
where
    P: GeneralizedJacobian + ParameterDependent + ?Sized,
    S: Factorize<P::Jacobian> + ?Sized,
{
    Continuation::new(problem, solver, x0, p0, options)?.run()
}
