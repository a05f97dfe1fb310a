//! Frequency-response sweep times, single-threaded (`faer::Par::Seq`).
//!
//! `cargo bench --bench sweep`: the canonical rod (20 elements, modified mass, gap 0.5,
//! `zeta = 0.01`, distributed load 0.04) swept from 0.5 to 2 omega_1 by SSN-HB at H = 20
//! with the structured solver, and by penalty HB at H = 5 at the default penalty (its
//! corners crossed exactly). The scenes are given as TOML text so that the same benchmark
//! runs on any version of the program.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use semismooth_problems::rod::build_rod;
use semismooth_problems::scene::Scene;
use semismooth_problems::sweep::frequency_response;

fn scene(method: &str, harmonics: usize) -> Scene {
    let text = format!(
        "[rod]\nelements = 20\nmass = \"modified\"\n[damping]\nzeta = 0.01\n\
         [forcing]\namplitude = 0.04\n[contact]\ngap = 0.5\n\
         [solver]\nmethod = \"{method}\"\nharmonics = {harmonics}\n\
         [sweep]\nomega_ratio_from = 0.5\nomega_ratio_to = 2.0\n"
    );
    Scene::from_toml(&text, "bench.toml").expect("valid scene")
}

fn sweep(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("sweep");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(5));
    for (name, method, harmonics) in [
        ("ssn_hb_h20", "ssn-hb", 20),
        ("penalty_hb_h5", "penalty-hb", 5),
    ] {
        let scene = scene(method, harmonics);
        let rod = build_rod(&scene.rod).expect("valid rod");
        let sweep = scene.sweep.clone().expect("a [sweep] section");
        group.bench_function(name, |b| {
            b.iter(|| {
                let response =
                    frequency_response(&rod, &scene.solver, &sweep, None).expect("the sweep runs");
                assert!(response.converged, "{}", response.termination);
                black_box(response.points())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, sweep);
criterion_main!(benches);
