//! Backbones per second: EPMC of the paper's rod with its tip stop and of the cantilever
//! with a friction damper at its tip, single-threaded (`faer::Par::Seq`).
//!
//! `cargo bench --bench backbone`: criterion's throughput is in backbone points per
//! second. The rod: 20 elements, modified mass, gap 0.5, `zeta = 0.01`, tip amplitude 0.05
//! to 1.5 at `H = 20`; the beam: `scenes/beam_friction_modes.toml`'s model (10 elements,
//! pad spring 0.3, slip force 0.003, `D = 0.05 M`, `c = 0.3`), tip amplitude 0.001 to 0.5
//! at `H = 15`; each with the dense and the structured bordered solve.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use semismooth_contact::hb::HbOptions;
use semismooth_contact::model::{ContactRow, FrictionPoint, StructuralModel};
use semismooth_contact::modes::{backbone, AmplitudeMeasure, BackboneOptions, EpmcSolve};
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::structures::cantilever_with_tip_spring;

/// The scene's beam: its pad (the last dof) on a Coulomb slider of slip force 0.003.
fn friction_beam() -> StructuralModel {
    let (k, m, f) = cantilever_with_tip_spring(10, 0.3);
    let pad = ContactRow::unit(k.nrows() - 1, 1.0);
    StructuralModel::new(m, k, f)
        .with_rayleigh_damping(0.05, 0.0)
        .with_friction(FrictionPoint::prescribed(pad, 0.5, 0.006))
}

fn backbones(c: &mut Criterion) {
    faer::set_global_parallelism(faer::Par::Seq);
    let mut group = c.benchmark_group("backbone");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(10));
    let rod = build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })
    .expect("valid rod");
    let tip = rod.tip_dof();
    let cases = [
        ("rod", rod.structure.model, tip, 20, (0.05, 1.5), None),
        (
            "friction_beam",
            friction_beam(),
            18,
            15,
            (0.001, 0.5),
            Some(0.3),
        ),
    ];
    for (name, model, dof, harmonics, (from, to), c) in cases {
        for solve in [EpmcSolve::Dense, EpmcSolve::Structured] {
            let mut options = BackboneOptions::new(1, AmplitudeMeasure::Dof(dof), from, to);
            options.hb = HbOptions {
                harmonics,
                c,
                ..HbOptions::default()
            };
            options.solve = solve;
            let points = backbone(&model, &options)
                .expect("the backbone runs")
                .points
                .len();
            group.throughput(Throughput::Elements(points as u64));
            group.bench_function(format!("{name}_{solve:?}").to_lowercase(), |b| {
                b.iter(|| black_box(backbone(&model, &options).expect("the backbone runs")))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, backbones);
criterion_main!(benches);
