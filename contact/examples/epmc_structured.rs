//! The structured EPMC solve against the dense one: the paper's rod with its tip stop
//! refined until the dense bordered LU is slow, then far beyond its reach.
//!
//! `cargo run --release -p semismooth-contact --example epmc_structured`
//!
//! 1. 100 elements, `H = 10` (2 123 unknowns): the backbone from tip amplitude 0.05 to
//!    1.5 with [`EpmcSolve::Dense`] and [`EpmcSolve::Structured`], their largest difference
//!    and the time per corrector iteration of each.
//! 2. 2 000 elements, `H = 10` (42 023 unknowns, a dense matrix of 14 GB): the whole
//!    backbone, structured only, and apart the time of its linear mode (a dense symmetric
//!    eigenproblem of the model's size, the same on both paths).

use std::time::Instant;

use semismooth_contact::hb::HbOptions;
use semismooth_contact::model::StructuralModel;
use semismooth_contact::modes::{
    backbone, linear_mode, AmplitudeMeasure, Backbone, BackboneOptions, EpmcSolve,
};
use semismooth_contact::rod::{build_rod, MassModel, RodContact, RodSpec};

/// Harmonics of both runs.
const HARMONICS: usize = 10;

/// The paper's rod with `elements` elements, its massless contact node at the tip against
/// the stop at 0.5; its tip dof.
fn rod(elements: usize) -> (StructuralModel, usize) {
    let rod = build_rod(&RodSpec {
        elements,
        mass: MassModel::Modified,
        contacts: vec![RodContact {
            node: elements,
            gap: 0.5,
        }],
        ..RodSpec::canonical()
    })
    .expect("the canonical rod builds");
    let tip = rod.tip_dof();
    (rod.structure.model, tip)
}

/// The backbone of `model` from tip amplitude 0.05 to `to` with `solve`, at most `points`
/// points; its wall time in seconds.
fn timed(
    model: &StructuralModel,
    tip: usize,
    to: f64,
    points: usize,
    solve: EpmcSolve,
) -> (Backbone, f64) {
    let mut options = BackboneOptions::new(1, AmplitudeMeasure::Dof(tip), 0.05, to);
    options.hb = HbOptions {
        harmonics: HARMONICS,
        ..HbOptions::default()
    };
    options.solve = solve;
    options.continuation.max_points = points;
    let started = Instant::now();
    let branch = backbone(model, &options).expect("the backbone starts");
    (branch, started.elapsed().as_secs_f64())
}

fn unknowns(model: &StructuralModel) -> usize {
    (model.dofs() + model.contact_count()) * (2 * HARMONICS + 1) + 2
}

/// Prints one row of the table; returns the seconds per corrector iteration.
fn print_row(
    solve: EpmcSolve,
    elements: usize,
    model: &StructuralModel,
    branch: &Backbone,
    seconds: f64,
) -> f64 {
    let iterations = branch.counters.corrector_iterations;
    println!(
        "| {solve:?} | {elements} | {} | {} | {iterations} | {seconds:.2} | {:.1} |",
        unknowns(model),
        branch.points.len(),
        1e3 * seconds / iterations as f64
    );
    seconds / iterations as f64
}

fn main() {
    let (model, tip) = rod(100);
    println!(
        "| solve | elements | unknowns | points | corrector iterations | seconds | ms / iteration |"
    );
    println!("|---|---|---|---|---|---|---|");
    let mut runs = Vec::new();
    for solve in [EpmcSolve::Dense, EpmcSolve::Structured] {
        let (branch, seconds) = timed(&model, tip, 1.5, 1000, solve);
        let per_iteration = print_row(solve, 100, &model, &branch, seconds);
        runs.push((branch, per_iteration));
    }
    let difference = runs[0]
        .0
        .points
        .iter()
        .zip(&runs[1].0.points)
        .map(|(p, q)| ((p.omega - q.omega) / p.omega).abs())
        .fold(0.0, f64::max);
    let (model, tip) = rod(2000);
    let started = Instant::now();
    linear_mode(&model, 1).expect("the rod has a first mode");
    let eigen_seconds = started.elapsed().as_secs_f64();
    let (branch, seconds) = timed(&model, tip, 1.5, 1000, EpmcSolve::Structured);
    print_row(EpmcSolve::Structured, 2000, &model, &branch, seconds);
    println!(
        "\n100 elements: speed-up per iteration {:.0}, largest relative difference in w {difference:.1e}; \
         2000 elements: last point w = {:.4} at tip amplitude {:.3} ({:?}), its linear mode \
         alone {eigen_seconds:.1} s.",
        runs[0].1 / runs[1].1,
        branch.points.last().map_or(f64::NAN, |p| p.omega),
        branch.points.last().map_or(f64::NAN, |p| p.amplitude),
        branch.termination
    );
    println!(
        "(wall time; load average {})",
        std::fs::read_to_string("/proc/loadavg")
            .map(|l| l.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
            .unwrap_or_default()
    );
}
