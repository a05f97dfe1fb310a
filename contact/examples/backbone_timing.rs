//! Backbones per second: the nonlinear mode of the paper's rod with its stop, of a
//! friction-damped oscillator (a Jenkins element) and of a friction-damped cantilever (the
//! model of `scenes/beam_friction_modes.toml`), timed; prints the table of `docs/modes.md`.
//!
//! `cargo run --release -p semismooth-contact --example backbone_timing`
//!
//! Each backbone is computed `REPEATS` times with each solve (the dense LU of the bordered
//! EPMC Jacobian, and the structured solve) and the fastest wall time is reported with its
//! points, corrector iterations (one factorization each) and points per second.

use std::time::Instant;

use semismooth_contact::builder::sparse_matrix;
use semismooth_contact::hb::HbOptions;
use semismooth_contact::model::{ContactRow, FrictionPoint, HarmonicLoad, StructuralModel};
use semismooth_contact::modes::{backbone, AmplitudeMeasure, BackboneOptions, EpmcSolve};
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::structures::cantilever_with_tip_spring;

/// Runs per backbone; the fastest is reported.
const REPEATS: usize = 3;

/// `u'' + 0.01 u' + u + 3 (u - w) = 0`, the massless slider `w` held by Coulomb friction
/// of limit 0.5 (the tests' Jenkins element).
fn jenkins() -> StructuralModel {
    let sparse = |entries: &[(usize, usize, f64)]| sparse_matrix(2, entries).unwrap();
    StructuralModel {
        mass: sparse(&[(0, 0, 1.0)]),
        damping: Some(sparse(&[(0, 0, 0.01)])),
        stiffness: sparse(&[(0, 0, 4.0), (0, 1, -3.0), (1, 0, -3.0), (1, 1, 3.0)]),
        load: HarmonicLoad::zero(2),
        contacts: Vec::new(),
        friction: vec![FrictionPoint::prescribed(
            ContactRow::unit(1, 1.0),
            0.5,
            1.0,
        )],
        cyclic: None,
        frictional_contacts: Vec::new(),
    }
}

/// The cantilever of `scenes/beam_friction_modes.toml`: 10 elements, its tip pad on a spring
/// 0.3 held by a Coulomb slider of slip force 0.003, `D = 0.05 M`.
fn friction_beam() -> StructuralModel {
    let (k, m, f) = cantilever_with_tip_spring(10, 0.3);
    let pad = k.nrows() - 1;
    StructuralModel::new(m, k, f)
        .with_rayleigh_damping(0.05, 0.0)
        .with_friction(FrictionPoint::prescribed(
            ContactRow::unit(pad, 1.0),
            0.5,
            0.006,
        ))
}

fn main() {
    let rod = build_rod(&RodSpec {
        mass: MassModel::Modified,
        ..RodSpec::canonical()
    })
    .unwrap();
    let tip = rod.tip_dof();
    let cases = [
        (
            "rod with a tip stop (20 elements, modified mass)",
            rod.structure.model.clone(),
            tip,
            20,
            (0.05, 1.5),
            None,
        ),
        (
            "Jenkins element (friction-damped oscillator)",
            jenkins(),
            0,
            15,
            (0.01, 3.0),
            None,
        ),
        (
            "cantilever with a friction damper at its tip (10 elements)",
            friction_beam(),
            18,
            15,
            (0.001, 0.5),
            // The scene's c: the slider's stiffness.
            Some(0.3),
        ),
    ];
    println!(
        "| backbone | solve | H | unknowns | amplitude range | points | corrector iterations | seconds | points / s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let runs = cases.into_iter().flat_map(|case| {
        [EpmcSolve::Dense, EpmcSolve::Structured].map(|solve| (case.clone(), solve))
    });
    for ((name, model, dof, harmonics, (from, to), c), solve) in runs {
        let mut options = BackboneOptions::new(1, AmplitudeMeasure::Dof(dof), from, to);
        options.hb = HbOptions {
            harmonics,
            c,
            ..HbOptions::default()
        };
        options.solve = solve;
        let rows = model.dofs() + model.contact_count() + model.friction_count();
        let unknowns = rows * (2 * harmonics + 1) + 2;
        let mut best = f64::INFINITY;
        let mut result = None;
        for _ in 0..REPEATS {
            let started = Instant::now();
            let branch = backbone(&model, &options).unwrap();
            best = best.min(started.elapsed().as_secs_f64());
            result = Some(branch);
        }
        let branch = result.unwrap();
        let points = branch.points.len();
        println!(
            "| {name} | {solve:?} | {harmonics} | {unknowns} | {from} to {to} | {points} | {} | {best:.3} | {:.1} |",
            branch.counters.corrector_iterations,
            points as f64 / best
        );
    }
    println!(
        "\n(wall time, best of {REPEATS}; load average {})",
        std::fs::read_to_string("/proc/loadavg")
            .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
            .unwrap_or_default()
    );
}
