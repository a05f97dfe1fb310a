//! The semismooth Newton driver on problems with known answers: convergence order on
//! smooth and nonsmooth problems, globalization, exact work counters, every termination.

mod common;

use std::cell::Cell;

use common::branches::Closure;

use faer::Mat;
use semismooth::linalg::{FaerDenseLu, LinearSolveError, NalgebraLu};
use semismooth::newton::{
    solve, Globalization, LineSearchOptions, NewtonError, NewtonOptions, NewtonReport,
    NewtonSolver, Termination, Tolerances, WorkCounters,
};
use semismooth::polyalgorithm::{self, PolyalgorithmOptions};
use semismooth::InvalidOption;
use semismooth::{EvaluationError, GeneralizedJacobian, ProblemCounters, Residual};

fn options(globalization: Globalization) -> NewtonOptions {
    NewtonOptions {
        globalization,
        ..Default::default()
    }
}

fn armijo() -> Globalization {
    Globalization::Armijo(LineSearchOptions::default())
}

/// Plain Newton with its default globalization, then the polyalgorithm, on `problem()`
/// from `x0`: each report with the returned `x`.
fn both_drivers<P>(
    mut problem: impl FnMut() -> P,
    mut linear: impl FnMut() -> Box<dyn semismooth::Factorize<Mat<f64>>>,
    x0: [f64; 1],
) -> [(Result<NewtonReport, NewtonError>, [f64; 1]); 2]
where
    P: GeneralizedJacobian<Jacobian = Mat<f64>>,
{
    let (mut x, mut y) = (x0, x0);
    let plain = solve(
        &mut problem(),
        &mut *linear(),
        &mut x,
        &NewtonOptions::default(),
    );
    let poly = polyalgorithm::solve(
        &mut problem(),
        &mut *linear(),
        &mut y,
        &PolyalgorithmOptions::default(),
    );
    [(plain, x), (poly, y)]
}

/// The report of a run that must have run and stopped without converging.
fn not_converged(result: Result<NewtonReport, NewtonError>) -> NewtonReport {
    match result {
        Ok(report) if !report.converged() => report,
        other => panic!("expected a run that did not converge, got {other:?}"),
    }
}

/// A scalar problem from closures: F(x) = f(x), J = df(x).
struct Scalar<F, D> {
    f: F,
    df: D,
}
impl<F: Fn(f64) -> f64, D: Fn(f64) -> f64> Residual for Scalar<F, D> {
    fn dim(&self) -> usize {
        1
    }
    fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
        out[0] = (self.f)(x[0]);
        Ok(())
    }
}
impl<F: Fn(f64) -> f64, D: Fn(f64) -> f64> GeneralizedJacobian for Scalar<F, D> {
    type Jacobian = Mat<f64>;
    fn new_jacobian(&self) -> Mat<f64> {
        Mat::zeros(1, 1)
    }
    fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
        jac[(0, 0)] = (self.df)(x[0]);
        Ok(())
    }
}

fn scalar(
    f: impl Fn(f64) -> f64,
    df: impl Fn(f64) -> f64,
) -> Scalar<impl Fn(f64) -> f64, impl Fn(f64) -> f64> {
    Scalar { f, df }
}

/// F(x) = x^3: root 0 with a singular Jacobian; Newton gives x_{k+1} = 2/3 x_k.
fn cube() -> Scalar<impl Fn(f64) -> f64, impl Fn(f64) -> f64> {
    scalar(|x| x * x * x, |x| 3.0 * x * x)
}

/// Newton on [`cube`] from x0 = 1 with the dense LU: the report and the final x.
fn newton_on_cube(opts: &NewtonOptions) -> (semismooth::newton::NewtonReport, [f64; 1]) {
    let mut x = [1.0];
    let report = solve(&mut cube(), &mut FaerDenseLu::new(), &mut x, opts).unwrap();
    (report, x)
}

/// Gradient of Rosenbrock's function f = (1 - x)^2 + 100 (y - x^2)^2; its only root is
/// the minimizer (1, 1), where the Hessian [[802, -400], [-400, 200]] is regular.
fn rosenbrock_gradient() -> Closure {
    Closure {
        n: 2,
        p: 0.0,
        f: Box::new(|v, _, out| {
            let (x, y) = (v[0], v[1]);
            out[0] = -2.0 * (1.0 - x) - 400.0 * x * (y - x * x);
            out[1] = 200.0 * (y - x * x);
        }),
        j: Box::new(|v, _, jac| {
            let (x, y) = (v[0], v[1]);
            jac[(0, 0)] = 2.0 - 400.0 * (y - 3.0 * x * x);
            jac[(0, 1)] = -400.0 * x;
            jac[(1, 0)] = -400.0 * x;
            jac[(1, 1)] = 200.0;
        }),
        fp: None,
    }
}

/// Coupled squares F(x) = B (x o x) - B (s o s) with B well conditioned: the root x = s
/// (all s_i > 0) is regular (J = 2 B diag(x)). The problem and its root `s`.
fn coupled_squares(n: usize) -> (Closure, Vec<f64>) {
    let b = Mat::from_fn(n, n, |i, j| {
        if i == j {
            4.0
        } else {
            1.0 / (1.0 + (i + j) as f64)
        }
    });
    let target: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
    let (b_jac, s) = (b.clone(), target.clone());
    let problem = Closure {
        n,
        p: 0.0,
        f: Box::new(move |x, _, out| {
            for (i, o) in out.iter_mut().enumerate() {
                *o = (0..n)
                    .map(|j| b[(i, j)] * (x[j] * x[j] - s[j] * s[j]))
                    .sum();
            }
        }),
        j: Box::new(move |x, _, jac| {
            for i in 0..n {
                for j in 0..n {
                    jac[(i, j)] = 2.0 * b_jac[(i, j)] * x[j];
                }
            }
        }),
        fp: None,
    };
    (problem, target)
}

/// On smooth systems with a regular root, the observed order over the last three
/// residuals is >= 1.8 (theory: 2; measured 2.0) and the root matches the closed form.
/// The absolute tolerance 1e-9 stops before the residual reaches round-off (~1e-13
/// here), which would corrupt the order estimate.
#[test]
fn smooth_regular_root_converges_with_order_at_least_1_8() {
    let opts = NewtonOptions {
        tolerances: Tolerances::absolute(1e-9),
        ..options(Globalization::None)
    };
    let (mut problem, target) = coupled_squares(6);
    let mut x: Vec<f64> = target.iter().map(|s| s * 1.3).collect();
    let report = solve(&mut problem, &mut FaerDenseLu::new(), &mut x, &opts).unwrap();
    println!("coupled squares: {:?}", report.residual_norms);
    assert!(report.converged());
    let q = report.observed_order.unwrap();
    assert!(q >= 1.8, "order {q}");
    for (xi, si) in x.iter().zip(&target) {
        assert!((xi - si).abs() < 1e-10);
    }

    // Rosenbrock's gradient from the classical start (-1.2, 1), full steps (the merit
    // |grad f|^2 has a curved valley where Armijo takes tiny steps; Newton's iteration
    // itself reaches the quadratic region within a few steps from here).
    let opts = NewtonOptions {
        tolerances: Tolerances::absolute(1e-11),
        ..options(Globalization::None)
    };
    let mut x = [-1.2, 1.0];
    let report = solve(
        &mut rosenbrock_gradient(),
        &mut FaerDenseLu::new(),
        &mut x,
        &opts,
    )
    .unwrap();
    println!(
        "rosenbrock: {:?} steps {:?}",
        report.residual_norms, report.step_lengths
    );
    assert!(report.converged());
    // The run ends exactly at 0 (measured: 25, 8.6e-6, 8.3e-9, 0), too short a tail for
    // an order estimate; check the superlinear contraction r_{k+1} <= 1e-2 r_k over the
    // last two nonzero steps instead.
    let tail: Vec<f64> = report
        .residual_norms
        .iter()
        .copied()
        .filter(|&r| r > 0.0)
        .collect();
    let t = tail.len();
    assert!(tail[t - 1] <= 1e-2 * tail[t - 2] && tail[t - 2] <= 1e-2 * tail[t - 3]);
    assert!(
        (x[0] - 1.0).abs() < 1e-12 && (x[1] - 1.0).abs() < 1e-12,
        "{x:?}"
    );
}

/// The order estimate tells linear from quadratic convergence: F(x) = x^3 has a
/// singular Jacobian at its root, Newton gives x_{k+1} = 2/3 x_k and r_k = x_k^3, so
/// the estimate is 1 (to round-off).
#[test]
fn singular_root_is_reported_with_order_one() {
    let (report, _) = newton_on_cube(&NewtonOptions {
        tolerances: Tolerances::absolute(1e-12),
        ..options(Globalization::None)
    });
    assert!(report.converged());
    let q = report.observed_order.unwrap();
    assert!((q - 1.0).abs() < 1e-6, "order {q}");
    // Closed form: x_k = (2/3)^k and r_k = (2/3)^(3k) until r_k <= 1e-12.
    let k = (0..)
        .find(|&k| (2.0f64 / 3.0).powi(3 * k) <= 1e-12)
        .unwrap() as usize;
    assert_eq!(report.iterations, k);
}

/// atan(x) = 0 from x0 = 10: the full Newton step overshoots ever further
/// (x_{k+1} = x_k - (1 + x_k^2) atan(x_k)) and the local method fails (reported, not
/// converged, x left at the best iterate 10); Armijo and the non-monotone rule converge
/// to the root 0.
#[test]
fn atan_from_10_fails_without_globalization_and_converges_with_line_search() {
    let problem = || scalar(f64::atan, |x| 1.0 / (1.0 + x * x));
    let mut x = [10.0];
    let report = not_converged(solve(
        &mut problem(),
        &mut FaerDenseLu::new(),
        &mut x,
        &options(Globalization::None),
    ));
    println!(
        "none: {:?} after {} iterations",
        report.termination, report.iterations
    );
    assert!(!report.converged());
    assert_eq!(x, [10.0], "best iterate is the initial guess");
    assert!(report.residual_norms.iter().skip(1).all(|&r| r > 1.47));

    for globalization in [armijo(), Globalization::non_monotone()] {
        let mut x = [10.0];
        let report = solve(
            &mut problem(),
            &mut FaerDenseLu::new(),
            &mut x,
            &options(globalization),
        )
        .unwrap();
        println!(
            "{globalization:?}: {} iterations, {} backtracks, steps {:?}",
            report.iterations, report.counters.line_search_backtracks, report.step_lengths
        );
        assert!(report.converged());
        assert!(x[0].abs() < 1e-10);
        assert!(report.counters.line_search_backtracks > 0);
    }
}

/// An absolute tolerance no run reaches (the run ends on another test).
const UNREACHABLE_TOLERANCE: f64 = 1e-300;

/// A solve from the guess it is given.
type Driver = dyn Fn(&mut [f64]) -> Result<NewtonReport, NewtonError>;

/// The problem's own failure (an inner solve that diverged at `x`).
#[derive(Debug, PartialEq)]
struct InnerFailure(f64);

impl std::fmt::Display for InnerFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "the inner solve diverged at x = {}", self.0)
    }
}

impl std::error::Error for InnerFailure {}

/// atan(x) = 0 from x0 = 10, the problem failing beyond |x| = 20 (where the first full step,
/// x_1 = 10 - 101 atan(10) = -138.6, lands): an error outside the domain is an infinite
/// merit that the line search shortens (and converges), the problem's own error ends the
/// run at once and comes back in the termination, with any globalization.
#[test]
fn the_problems_own_error_ends_the_run_and_comes_back_in_the_termination() {
    struct Atan {
        own_error: bool,
    }
    impl Residual for Atan {
        fn dim(&self) -> usize {
            1
        }
        fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
            if x[0].abs() > 20.0 {
                return Err(if self.own_error {
                    EvaluationError::problem(InnerFailure(x[0]))
                } else {
                    EvaluationError::OutsideDomain {
                        what: "|x|",
                        value: x[0].abs(),
                    }
                });
            }
            out[0] = x[0].atan();
            Ok(())
        }
    }
    impl GeneralizedJacobian for Atan {
        type Jacobian = Mat<f64>;
        fn new_jacobian(&self) -> Mat<f64> {
            Mat::zeros(1, 1)
        }
        fn jacobian(&mut self, x: &[f64], jac: &mut Mat<f64>) -> Result<(), EvaluationError> {
            jac[(0, 0)] = 1.0 / (1.0 + x[0] * x[0]);
            Ok(())
        }
    }
    let mut x = [10.0];
    let report = solve(
        &mut Atan { own_error: false },
        &mut FaerDenseLu::new(),
        &mut x,
        &options(armijo()),
    )
    .unwrap();
    assert!(report.converged() && x[0].abs() < 1e-10);
    let drivers: [(&str, &Driver); 4] = [
        ("armijo", &|x| {
            let options = options(armijo());
            solve(
                &mut Atan { own_error: true },
                &mut FaerDenseLu::new(),
                x,
                &options,
            )
        }),
        ("full steps", &|x| {
            let options = options(Globalization::None);
            solve(
                &mut Atan { own_error: true },
                &mut FaerDenseLu::new(),
                x,
                &options,
            )
        }),
        ("hybrid", &|x| {
            let options = options(Globalization::hybrid());
            solve(
                &mut Atan { own_error: true },
                &mut FaerDenseLu::new(),
                x,
                &options,
            )
        }),
        ("polyalgorithm", &|x| {
            let options = PolyalgorithmOptions::default();
            polyalgorithm::solve(
                &mut Atan { own_error: true },
                &mut FaerDenseLu::new(),
                x,
                &options,
            )
        }),
    ];
    for (globalization, driver) in drivers {
        let mut x = [10.0];
        let report = not_converged(driver(&mut x));
        let Termination::Evaluation(error) = &report.termination else {
            panic!("{globalization:?}: {:?}", report.termination);
        };
        let first_step = 10.0 - 101.0 * 10f64.atan();
        let failure = error.downcast_ref::<InnerFailure>().unwrap();
        assert!((failure.0 - first_step).abs() < 1e-12, "{failure:?}");
        assert!(report
            .termination
            .to_string()
            .starts_with("problem-error: the inner solve diverged at x = -138.5"));
        // Nothing after the failed evaluation: one attempt, no step, x kept.
        assert_eq!(
            (report.iterations, report.attempts.len(), x),
            (0, 1, [10.0]),
            "{globalization:?}"
        );
        assert_eq!(report.counters.residual_evaluations, 2);
    }
}

/// A linear problem F(x) = A x - b with a problem counter of fake transforms (2 per
/// evaluation): one Newton step solves it, so exactly 2 residual evaluations, 1 Jacobian,
/// 1 factorization, 1 solve, 0 backtracks, 4 transforms; the same again on a second solve with
/// a reused `NewtonSolver`, which creates the Jacobian only once.
#[test]
fn counters_are_exact_on_a_linear_problem_and_jacobian_is_reused() {
    struct Linear {
        ffts: u64,
        jacobians_created: Cell<u32>,
    }
    const A: [[f64; 2]; 2] = [[3.0, 1.0], [1.0, 2.0]];
    impl Residual for Linear {
        fn dim(&self) -> usize {
            2
        }
        fn residual(&mut self, x: &[f64], out: &mut [f64]) -> Result<(), EvaluationError> {
            self.ffts += 2;
            out[0] = A[0][0] * x[0] + A[0][1] * x[1] - 5.0;
            out[1] = A[1][0] * x[0] + A[1][1] * x[1] - 5.0;
            Ok(())
        }
        fn problem_counters(&self) -> ProblemCounters {
            ProblemCounters::new().with("transforms", self.ffts)
        }
    }
    impl GeneralizedJacobian for Linear {
        type Jacobian = nalgebra::DMatrix<f64>;
        fn new_jacobian(&self) -> Self::Jacobian {
            self.jacobians_created.set(self.jacobians_created.get() + 1);
            nalgebra::DMatrix::zeros(2, 2)
        }
        fn jacobian(&mut self, _: &[f64], jac: &mut Self::Jacobian) -> Result<(), EvaluationError> {
            *jac = nalgebra::DMatrix::from_row_slice(2, 2, &[3.0, 1.0, 1.0, 2.0]);
            Ok(())
        }
    }
    let mut problem = Linear {
        ffts: 7,
        jacobians_created: Cell::new(0),
    };
    let mut newton = NewtonSolver::new(NewtonOptions::default()).unwrap();
    let mut lu = NalgebraLu::new();
    let expected = WorkCounters {
        residual_evaluations: 2,
        jacobian_evaluations: 1,
        factorizations: 1,
        linear_solves: 1,
        line_search_backtracks: 0,
        krylov_iterations: 0,
        problem: ProblemCounters::new().with("transforms", 4),
    };
    let mut total = WorkCounters::default();
    for start in [[0.0, 0.0], [-4.0, 9.0]] {
        let mut x = start;
        let report = newton.solve(&mut problem, &mut lu, &mut x).unwrap();
        assert!(report.converged());
        assert_eq!(report.iterations, 1);
        assert_eq!(report.counters, expected);
        // Solution of [[3, 1], [1, 2]] x = [5, 5]: x = [1, 2].
        assert!((x[0] - 1.0).abs() < 1e-14 && (x[1] - 2.0).abs() < 1e-14);
        assert_eq!(report.step_lengths, vec![1.0]);
        total += report.counters;
    }
    assert_eq!(total.residual_evaluations, 4);
    assert_eq!(total.problem.get("transforms"), 8);
    assert_eq!(problem.jacobians_created.get(), 1);
    // Already at the solution: converged with 0 iterations and one evaluation.
    let mut x = [1.0, 2.0];
    let report = newton.solve(&mut problem, &mut lu, &mut x).unwrap();
    assert!(report.converged());
    assert_eq!(
        (report.iterations, report.counters.residual_evaluations),
        (0, 1)
    );
}

/// A wrong-sign Jacobian gives an ascent direction: every trial increases the merit.
/// Trials alpha = 2^-k for k = 0..=33 (2^-33 ~ 1.2e-10 >= min_step = 1e-10, 2^-34 < it):
/// 34 rejections, 35 residual evaluations, x unchanged.
#[test]
fn line_search_failure_is_reported_with_exact_trial_count() {
    let mut p = scalar(|x| x, |_| -1.0);
    let mut x = [1.0];
    let report = not_converged(solve(
        &mut p,
        &mut FaerDenseLu::new(),
        &mut x,
        &options(armijo()),
    ));
    assert_eq!(report.termination, Termination::LineSearchFailed);
    assert_eq!(report.counters.line_search_backtracks, 34);
    assert_eq!(report.counters.residual_evaluations, 35);
    assert_eq!(x, [1.0]);
    assert_eq!(
        (
            report.iterations,
            report.residual_norm(),
            report.residual_norms[0]
        ),
        (0, 1.0, 1.0)
    );
}

/// F(x) = x^2 + 1 at x0 = 0 has J = 0: a linear-solve termination carrying the solver's
/// `Singular` error (plain Newton and the polyalgorithm).
#[test]
fn singular_jacobian_is_a_termination_carrying_the_linear_solver_error() {
    let runs = both_drivers(
        || scalar(|x| x * x + 1.0, |x| 2.0 * x),
        || Box::new(FaerDenseLu::new()),
        [0.0],
    );
    for (result, x) in runs {
        let report = not_converged(result);
        assert!(matches!(
            report.termination,
            Termination::LinearSolve(LinearSolveError::Singular { index: 0, .. })
        ));
        assert!(report
            .termination
            .to_string()
            .starts_with("singular-jacobian"));
        assert_eq!(x, [0.0]);
    }
}

/// A linear solver that cannot allocate its factors: every `factor` is `OutOfMemory`.
struct NoMemory;

impl semismooth::LinearSolve for NoMemory {
    fn solve_in_place(&mut self, _rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        Err(LinearSolveError::NotFactored)
    }
}

impl semismooth::Factorize<Mat<f64>> for NoMemory {
    fn factor(&mut self, _jac: &Mat<f64>) -> Result<(), LinearSolveError> {
        Err(LinearSolveError::OutOfMemory {
            during: "the dense factors",
        })
    }
}

/// A factorization that runs out of memory ends the run with its own termination,
/// `out-of-memory`, not as a singular Jacobian; x is kept (plain Newton and the
/// polyalgorithm).
#[test]
fn an_allocation_failure_is_its_own_termination_not_a_singular_jacobian() {
    let runs = both_drivers(
        || scalar(|x| x * x - 4.0, |x| 2.0 * x),
        || Box::new(NoMemory),
        [1.0],
    );
    for (result, x) in runs {
        let report = not_converged(result);
        assert_eq!(
            report.termination,
            Termination::LinearSolve(LinearSolveError::OutOfMemory {
                during: "the dense factors"
            })
        );
        let text = report.termination.to_string();
        assert!(text.starts_with("out-of-memory"), "{text}");
        assert!(!text.contains("singular"), "{text}");
        assert_eq!(x, [1.0]);
    }
}

/// A NaN residual at the start (sqrt of a negative number) is NonFinite with x
/// unchanged; the reported norm is infinite, not NaN (plain Newton and the polyalgorithm).
#[test]
fn non_finite_residual_is_reported_and_x_kept() {
    let runs = both_drivers(
        || scalar(|x: f64| x.sqrt() - 1.0, |x: f64| 0.5 / x.sqrt()),
        || Box::new(FaerDenseLu::new()),
        [-1.0],
    );
    for (result, x) in runs {
        let report = not_converged(result);
        assert_eq!(report.termination, Termination::NonFinite);
        assert_eq!(report.iterations, 0);
        assert_eq!(x, [-1.0]);
        assert_eq!(report.residual_norm(), f64::INFINITY);
    }
}

/// F(x) = x^3 converges linearly with steps x_k / 3; with step_tolerance 0.01 the run
/// stops as Stalled at the first k with x_k / 3 <= 0.01 (1 + x_{k+1}), x_k = (2/3)^k,
/// and the report still carries the observed (linear) order.
#[test]
fn small_steps_without_convergence_are_reported_as_stalled() {
    let (report, x) = newton_on_cube(&NewtonOptions {
        tolerances: Tolerances {
            absolute_tolerance: UNREACHABLE_TOLERANCE,
            step_tolerance: 0.01,
            ..Default::default()
        },
        ..options(Globalization::None)
    });
    assert_eq!(report.termination, Termination::Stalled);
    let r = 2.0f64 / 3.0;
    let k = (0..)
        .find(|&k| r.powi(k) / 3.0 <= 0.01 * (1.0 + r.powi(k + 1)))
        .unwrap();
    assert_eq!(report.iterations, k as usize + 1);
    assert!((x[0] - r.powi(k + 1)).abs() < 1e-14);
    // Not converged, but the rate is still estimated: linear, r_{k+1}/r_k = 8/27.
    let q = report.observed_order.unwrap();
    assert!((q - 1.0).abs() < 1e-9, "order {q}");
}

#[test]
fn max_iterations_is_a_termination_not_an_error() {
    let (report, x) = newton_on_cube(&NewtonOptions {
        max_iterations: 3,
        ..Default::default()
    });
    assert_eq!(report.termination, Termination::MaxIterations);
    assert_eq!(report.iterations, 3);
    assert_eq!(report.residual_norms.len(), 4);
    assert!((x[0] - 8.0 / 27.0).abs() < 1e-15);
}

#[test]
fn bad_options_and_dimensions_are_errors_before_any_evaluation() {
    let mut p = scalar(|x| x, |_| 1.0);
    let mut x = [1.0];
    let opts = NewtonOptions {
        tolerances: Tolerances {
            step_tolerance: -1.0,
            ..Default::default()
        },
        ..Default::default()
    };
    assert_eq!(
        solve(&mut p, &mut FaerDenseLu::new(), &mut x, &opts),
        Err(NewtonError::InvalidOption(InvalidOption::new(
            "step_tolerance",
            -1.0,
            "finite and >= 0"
        )))
    );
    let mut x2 = [1.0, 2.0];
    assert_eq!(
        solve(
            &mut p,
            &mut FaerDenseLu::new(),
            &mut x2,
            &NewtonOptions::default()
        ),
        Err(NewtonError::DimensionMismatch {
            expected: 1,
            found: 2
        })
    );
}

/// The relative tolerance stops at |F| <= rel |F(x0)|: for x^3 from 1 (|F0| = 1,
/// r_k = (8/27)^k) and rel = 1e-3, at the first k with (8/27)^k <= 1e-3, i.e. k = 6.
#[test]
fn relative_tolerance_is_relative_to_initial_residual() {
    let (report, _) = newton_on_cube(&NewtonOptions {
        tolerances: Tolerances {
            absolute_tolerance: 0.0,
            relative_tolerance: 1e-3,
            ..Default::default()
        },
        ..options(Globalization::None)
    });
    assert!(report.converged());
    assert_eq!(report.iterations, 6);
}
