//! Harmonic-balance solve times, single-threaded (`faer::Par::Seq`).
//!
//! `cargo bench --bench hb_solve`, or e.g. `-- canonical` for one group:
//! - `canonical/{modified,consistent}`: the canonical rod (20 elements), H = 20, from zero:
//!   SSN-HB problem + structured solver built and Newton run to 1e-10 (target < 2 ms);
//! - `newton_solver/{structured,dense}`: the same full Newton solve (modified mass) with the
//!   structured and the dense LU linear solver (target: structured >= 20x faster);
//! - `linear_solve/{structured_iteration,structured_fresh,dense}`: one factor + solve of the
//!   Newton system at the converged state (`structured_iteration` reuses the per-harmonic
//!   factorizations as the Newton iterations at fixed omega do, `structured_fresh` redoes
//!   them), and the parts of one iteration: `part_{residual,jacobian,factor,solve}`
//!   (structured factor with the per-harmonic factorizations reused);
//! - `elements/{1000,10000}`: the modified-mass rod with that many elements (contact at the
//!   tip), H = 20, from zero (target: 10,000 under 1 s; the full scan up to 100,000 with the
//!   fitted exponent is `cargo run --release --example scaling`);
//! - `march_vs_hb/{march,ssn_hb}`: the cheapest time-marching and SSN-HB settings reaching
//!   1e-3 relative accuracy on the tip minimum against a time-marching reference with 8000
//!   steps per period (chosen at start-up and printed).

use std::hint::black_box;
use std::time::Duration;

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion};
use semismooth::linalg::FaerDenseLu;
use semismooth::polyalgorithm::SmoothingOf;
use semismooth::{Factorize, GeneralizedJacobian, LinearSolve, Residual};

use semismooth_contact::hb::{HbJacobian, HbOptions, SsnHb, StructuredHbSolver};
use semismooth_contact::rod::{build_rod, MassModel, RodContact, RodModel, RodSpec};
use semismooth_contact::settings::{default_hb_time_samples, Method, SolverSettings};
use semismooth_contact::solve::newton_options;

const H: usize = 20;

fn rod(mass: MassModel, elements: usize) -> RodModel {
    build_rod(&RodSpec {
        mass,
        elements,
        contacts: vec![RodContact {
            node: elements,
            gap: 0.5,
        }],
        ..RodSpec::canonical()
    })
    .expect("valid rod")
}

fn hb_options(h: usize, c: Option<f64>) -> HbOptions {
    HbOptions {
        harmonics: h,
        time_samples: Some(default_hb_time_samples(h)),
        c,
    }
}

/// SSN-HB on `rod` (`c`: `None` for the default) solved from zero with `solver`; returns
/// the problem and its solution.
fn solve_hb<S: Factorize<HbJacobian>>(
    rod: &RodModel,
    h: usize,
    c: Option<f64>,
    mut solver: S,
) -> (SsnHb, Vec<f64>) {
    let options = newton_options(&SolverSettings::with_harmonics(h));
    let mut problem =
        SsnHb::new(&rod.model, rod.omega(), &hb_options(h, c)).expect("valid HB problem");
    let mut x = vec![0.0; problem.dim()];
    let report = options
        .solve(&mut problem, &mut solver, &mut x, Some(SmoothingOf::new()))
        .expect("runs");
    assert!(report.converged(), "{:?}", report.termination);
    (problem, x)
}

/// One SSN-HB solve from zero with the structured solver (`c`: `None` for the default);
/// returns the solution's first entry.
fn solve_structured(rod: &RodModel, h: usize, c: Option<f64>) -> f64 {
    solve_hb(rod, h, c, StructuredHbSolver::new()).1[0]
}

/// Factors `jac` with `solver` and solves for `rhs` in `work`; returns `work[0]`.
fn factor_and_solve<S: Factorize<HbJacobian>>(
    solver: &mut S,
    jac: &HbJacobian,
    rhs: &[f64],
    work: &mut [f64],
) -> f64 {
    solver.factor(jac).expect("factors");
    work.copy_from_slice(rhs);
    solver.solve_in_place(work).expect("solves");
    work[0]
}

/// A benchmark group with `samples` samples, warmed up for `warm_up_ms` and measured for
/// `measure_s` seconds.
fn configured_group<'a>(
    c: &'a mut Criterion,
    name: &str,
    samples: usize,
    warm_up_ms: u64,
    measure_s: u64,
) -> BenchmarkGroup<'a, WallTime> {
    let mut group = c.benchmark_group(name);
    group
        .sample_size(samples)
        .warm_up_time(Duration::from_millis(warm_up_ms))
        .measurement_time(Duration::from_secs(measure_s));
    group
}

fn canonical(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = configured_group(c, "canonical", 100, 500, 3);
    for (name, mass) in [
        ("modified", MassModel::Modified),
        ("consistent", MassModel::Consistent),
    ] {
        let rod = rod(mass, 20);
        group.bench_function(name, |b| {
            b.iter(|| black_box(solve_structured(&rod, H, None)))
        });
    }
    group.finish();
}

fn newton_solver(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let rod = rod(MassModel::Modified, 20);
    let mut group = configured_group(c, "newton_solver", 10, 500, 4);
    group.bench_function("structured", |b| {
        b.iter(|| black_box(solve_structured(&rod, H, None)))
    });
    group.bench_function("dense", |b| {
        b.iter(|| black_box(solve_hb(&rod, H, None, FaerDenseLu::new()).1[0]))
    });
    group.finish();

    // One Newton system at the converged state (an active set with contact).
    let (mut problem, x) = solve_hb(&rod, H, None, StructuredHbSolver::new());
    let mut jac = problem.new_jacobian();
    problem.jacobian(&x, &mut jac).expect("evaluates");
    let rhs: Vec<f64> = (0..problem.dim())
        .map(|i| (i as f64 * 0.37).sin())
        .collect();
    let mut work = rhs.clone();
    let mut group = configured_group(c, "linear_solve", 20, 300, 2);
    let mut structured = StructuredHbSolver::new();
    structured.factor(&jac).expect("factors");
    group.bench_function("structured_iteration", |b| {
        b.iter(|| black_box(factor_and_solve(&mut structured, &jac, &rhs, &mut work)))
    });
    group.bench_function("structured_fresh", |b| {
        b.iter(|| {
            let mut fresh = StructuredHbSolver::new();
            black_box(factor_and_solve(&mut fresh, &jac, &rhs, &mut work))
        })
    });
    // The parts of one Newton iteration (profile of the canonical H = 20 solve).
    let mut f = vec![0.0; problem.dim()];
    group.bench_function("part_residual", |b| {
        b.iter(|| {
            problem.residual(&x, &mut f).expect("evaluates");
            black_box(f[0])
        })
    });
    group.bench_function("part_jacobian", |b| {
        b.iter(|| {
            problem.jacobian(&x, &mut jac).expect("evaluates");
            black_box(jac.harmonics())
        })
    });
    group.bench_function("part_factor", |b| {
        b.iter(|| structured.factor(&jac).expect("factors"))
    });
    group.bench_function("part_solve", |b| {
        b.iter(|| {
            work.copy_from_slice(&rhs);
            structured.solve_in_place(&mut work).expect("solves");
            black_box(work[0])
        })
    });
    let mut dense = FaerDenseLu::new();
    group.bench_function("dense", |b| {
        b.iter(|| black_box(factor_and_solve(&mut dense, &jac, &rhs, &mut work)))
    });
    group.finish();
}

fn elements(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = configured_group(c, "elements", 10, 200, 3);
    for n in [1000, 10_000] {
        let rod = rod(MassModel::Modified, n);
        // c = EA / L, the static tip stiffness (see examples/scaling.rs: the default
        // K[tip, tip] grows with n and Newton from zero then cycles).
        let c = rod.spec.axial_stiffness / rod.spec.length;
        group.bench_function(n.to_string(), |b| {
            b.iter(|| black_box(solve_structured(&rod, H, Some(c))))
        });
    }
    group.finish();
}

/// Cheapest setting of a list (in order of increasing cost) reaching `accuracy` on the tip
/// minimum against `reference`.
fn first_accurate(
    rod: &RodModel,
    candidates: &[SolverSettings],
    reference: f64,
    accuracy: f64,
) -> SolverSettings {
    for s in candidates {
        if let Ok(sol) = semismooth_contact::solve(rod, rod.omega(), s, None) {
            let err = (sol.stats.min - reference).abs() / reference.abs();
            if sol.converged() && err <= accuracy {
                return s.clone();
            }
        }
    }
    candidates.last().expect("candidates").clone()
}

fn march_vs_hb(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let rod = rod(MassModel::Modified, 20);
    let base = SolverSettings::with_harmonics(H);
    let reference = semismooth_contact::solve(
        &rod,
        rod.omega(),
        &SolverSettings {
            method: Method::March,
            steps_per_period: 8000,
            march_tolerance: 1e-10,
            ..base.clone()
        },
        None,
    )
    .expect("reference runs")
    .stats
    .min;
    let march: Vec<SolverSettings> = [16, 32, 64, 128, 256, 512]
        .iter()
        .map(|&steps| SolverSettings {
            method: Method::March,
            steps_per_period: steps,
            march_tolerance: 1e-6,
            ..base.clone()
        })
        .collect();
    let hb: Vec<SolverSettings> = [3, 5, 7, 10, 15, 20]
        .iter()
        .map(|&h| SolverSettings::with_harmonics(h))
        .collect();
    let march = first_accurate(&rod, &march, reference, 1e-3);
    let hb = first_accurate(&rod, &hb, reference, 1e-3);
    eprintln!(
        "march_vs_hb: reference tip min {reference:.10}; march {} steps/period (tolerance 1e-6), SSN-HB H = {} Nt = {}",
        march.steps_per_period, hb.harmonics, hb.time_samples
    );
    let mut group = configured_group(c, "march_vs_hb", 10, 300, 3);
    for (name, settings) in [("march", &march), ("ssn_hb", &hb)] {
        group.bench_function(name, |b| {
            b.iter(|| {
                black_box(
                    semismooth_contact::solve(&rod, rod.omega(), settings, None)
                        .expect("runs")
                        .stats
                        .min,
                )
            })
        });
    }
    group.finish();
}

criterion_group!(benches, canonical, newton_solver, elements, march_vs_hb);
criterion_main!(benches);
