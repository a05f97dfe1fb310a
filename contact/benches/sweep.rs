//! Frequency-response sweep times, single-threaded (`faer::Par::Seq`).
//!
//! `cargo bench --bench sweep`: the canonical rod (20 elements, modified mass, gap 0.5,
//! `zeta = 0.01`, distributed load 0.04) swept from 0.5 to 2 omega_1 by SSN-HB at H = 20
//! with the structured solver, and by penalty HB at H = 5 at the default penalty (its
//! corners crossed exactly).

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::settings::{Method, SolverSettings, SweepSettings};
use semismooth_contact::sweep::frequency_response;

fn sweep(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("sweep");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    let rod = build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })
    .expect("valid rod");
    let sweep = SweepSettings::new(0.5, 2.0);
    for (name, method, harmonics) in [
        ("ssn_hb_h20", Method::SsnHb, 20),
        ("penalty_hb_h5", Method::PenaltyHb, 5),
    ] {
        let settings = SolverSettings {
            method,
            ..SolverSettings::with_harmonics(harmonics)
        };
        group.bench_function(name, |b| {
            b.iter(|| {
                let response =
                    frequency_response(&rod, &settings, &sweep, None).expect("the sweep runs");
                assert!(response.converged(), "{}", response.termination);
                black_box(response.points.len())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, sweep);
criterion_main!(benches);
