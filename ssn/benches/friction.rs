//! Friction solve and sweep times, single-threaded (`faer::Par::Seq`).
//!
//! `cargo bench -p ssn --bench friction`:
//! - `friction/damper_solve`: the shipped friction-damper scene (`scenes/friction_damper.toml`,
//!   two blades joined by a damper, 42 dofs, SSN-HB at H = 7) solved from rest at its
//!   frequency;
//! - `friction/damper_sweep`: its response swept from 0.95 to 1.05 `omega_1` through the
//!   damped resonance;
//! - `friction/disk100_h10`: the 100-blade mistuned disk with a Coulomb friction contact
//!   on every blade's platform (100 friction points, `mu = 0.3`, `N = 1e-2`: the pads stick
//!   for part of the period) solved by SSN-HB at H = 10 from rest with the structured solve.

use std::hint::black_box;
use std::path::Path;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use semismooth::polyalgorithm::{solve_smoothing, PolyalgorithmOptions};
use semismooth::Residual;
use semismooth_contact::hb::{HbOptions, SsnHb, StructuredHbSolver};
use semismooth_contact::matrix_market::build_imported;
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::structures::{BladedDisk, DiskLoading, SHIPPED_MISTUNING};
use semismooth_contact::sweep::frequency_response;
use ssn::scene::Scene;

fn friction(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("friction");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));

    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/friction_damper.toml");
    let text = std::fs::read_to_string(&path).expect("the shipped scene");
    let scene = Scene::from_toml(&text, &path).expect("a valid scene");
    let damper = build_imported(scene.model.as_ref().expect("a [model] scene")).expect("files");
    let omega = scene.omega(damper.omega_1);
    let settings = SolverSettings {
        estimate_error: false,
        ..scene.solver.clone()
    };
    group.bench_function("damper_solve", |b| {
        b.iter(|| {
            let s = semismooth_contact::solve(&damper, omega, &settings, None).expect("runs");
            assert!(s.converged(), "{}", s.termination);
            black_box(s.stats.max)
        })
    });
    let sweep = SweepSettings::new(0.95, 1.05);
    group.bench_function("damper_sweep", |b| {
        b.iter(|| {
            let r = frequency_response(&damper, &settings, &sweep, None).expect("runs");
            assert!(r.converged(), "{}", r.termination);
            black_box(r.points.len())
        })
    });

    let disk = BladedDisk {
        blades: 100,
        mistuning: SHIPPED_MISTUNING,
    };
    let loading = DiskLoading::shipped(Vec::new());
    let (structure, omega) = disk
        .with_platform_friction(&loading, 0.3, 1e-2)
        .expect("a valid disk");
    let options = HbOptions {
        harmonics: 10,
        ..HbOptions::default()
    };
    group.bench_function("disk100_h10", |b| {
        b.iter(|| {
            let mut hb = SsnHb::new(&structure.model, omega, &options).expect("a valid problem");
            let mut x = vec![0.0; hb.dim()];
            let newton = PolyalgorithmOptions::default();
            let report = solve_smoothing(&mut hb, &mut StructuredHbSolver::new(), &mut x, &newton)
                .expect("runs");
            assert!(report.converged(), "{:?}", report.termination);
            black_box(report.iterations)
        })
    });
    group.finish();
}

criterion_group!(benches, friction);
criterion_main!(benches);
