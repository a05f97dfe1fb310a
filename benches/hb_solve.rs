//! Harmonic-balance solve times, single-threaded (`faer::Par::Seq`).
//!
//! `cargo bench --bench hb_solve` (about two minutes), or e.g. `-- canonical` for one group:
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

use criterion::{criterion_group, criterion_main, Criterion};
use semismooth::linalg::FaerDenseLu;
use semismooth::newton;
use semismooth::{Factorize, GeneralizedJacobian, LinearSolve, Residual};
use semismooth_problems::figures::default_settings;
use semismooth_problems::hb::{HbOptions, SsnHb, StructuredHbSolver};
use semismooth_problems::rod::{build_rod, MassModel, RodContact, RodModel, RodSpec};
use semismooth_problems::runner::{newton_options, solve_rod};
use semismooth_problems::scene::{default_hb_time_samples, Method, SolverSettings};

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

/// One SSN-HB solve from zero with the structured solver (`c`: `None` for the default
/// `K[tip, tip]`); returns the iterations.
fn solve_structured(rod: &RodModel, h: usize, c: Option<f64>) -> usize {
    let options = newton_options(&default_settings(h));
    let mut problem = SsnHb::new(&rod.model, &hb_options(h, c)).expect("valid HB problem");
    let mut x = vec![0.0; problem.dim()];
    let mut solver = StructuredHbSolver::new();
    let report = newton::solve(&mut problem, &mut solver, &mut x, &options).expect("runs");
    assert!(report.converged(), "structured solve did not converge");
    report.iterations
}

fn solve_dense(rod: &RodModel, h: usize) -> usize {
    let options = newton_options(&default_settings(h));
    let mut problem = SsnHb::new(&rod.model, &hb_options(h, None)).expect("valid HB problem");
    let mut x = vec![0.0; problem.dim()];
    let mut solver = FaerDenseLu::new();
    let report = newton::solve(&mut problem, &mut solver, &mut x, &options).expect("runs");
    assert!(report.converged(), "dense solve did not converge");
    report.iterations
}

fn canonical(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("canonical");
    group
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
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
    let mut group = c.benchmark_group("newton_solver");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(4));
    group.bench_function("structured", |b| {
        b.iter(|| black_box(solve_structured(&rod, H, None)))
    });
    group.bench_function("dense", |b| b.iter(|| black_box(solve_dense(&rod, H))));
    group.finish();

    // One Newton system at the converged state (an active set with contact).
    let options = newton_options(&default_settings(H));
    let mut problem = SsnHb::new(&rod.model, &hb_options(H, None)).expect("valid HB problem");
    let mut x = vec![0.0; problem.dim()];
    let mut solver = StructuredHbSolver::new();
    newton::solve(&mut problem, &mut solver, &mut x, &options).expect("runs");
    let mut jac = problem.new_jacobian();
    problem.jacobian(&x, &mut jac).expect("evaluates");
    let rhs: Vec<f64> = (0..problem.dim())
        .map(|i| (i as f64 * 0.37).sin())
        .collect();
    let mut work = rhs.clone();
    let mut group = c.benchmark_group("linear_solve");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    let mut structured = StructuredHbSolver::new();
    structured.factor(&jac).expect("factors");
    group.bench_function("structured_iteration", |b| {
        b.iter(|| {
            structured.factor(&jac).expect("factors");
            work.copy_from_slice(&rhs);
            structured.solve_in_place(&mut work).expect("solves");
            black_box(work[0])
        })
    });
    group.bench_function("structured_fresh", |b| {
        b.iter(|| {
            let mut s = StructuredHbSolver::new();
            s.factor(&jac).expect("factors");
            work.copy_from_slice(&rhs);
            s.solve_in_place(&mut work).expect("solves");
            black_box(work[0])
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
        b.iter(|| {
            dense.factor(&jac).expect("factors");
            work.copy_from_slice(&rhs);
            dense.solve_in_place(&mut work).expect("solves");
            black_box(work[0])
        })
    });
    group.finish();
}

fn elements(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("elements");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_secs(3));
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
        if let Ok(sol) = solve_rod(rod, s, None) {
            let err = (sol.stats.min - reference).abs() / reference.abs();
            if sol.converged && err <= accuracy {
                return s.clone();
            }
        }
    }
    candidates.last().expect("candidates").clone()
}

fn march_vs_hb(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let rod = rod(MassModel::Modified, 20);
    let base = default_settings(H);
    let reference = solve_rod(
        &rod,
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
        .map(|&h| default_settings(h))
        .collect();
    let march = first_accurate(&rod, &march, reference, 1e-3);
    let hb = first_accurate(&rod, &hb, reference, 1e-3);
    eprintln!(
        "march_vs_hb: reference tip min {reference:.10}; march {} steps/period (tolerance 1e-6), SSN-HB H = {} Nt = {}",
        march.steps_per_period, hb.harmonics, hb.time_samples
    );
    let mut group = c.benchmark_group("march_vs_hb");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(3));
    group.bench_function("march", |b| {
        b.iter(|| black_box(solve_rod(&rod, &march, None).expect("runs").stats.min))
    });
    group.bench_function("ssn_hb", |b| {
        b.iter(|| black_box(solve_rod(&rod, &hb, None).expect("runs").stats.min))
    });
    group.finish();
}

criterion_group!(benches, canonical, newton_solver, elements, march_vs_hb);
criterion_main!(benches);
