//! The 100-blade mistuned disk (`structures::BladedDisk`, the shipped mistuning) with a
//! Coulomb friction contact on every blade: each blade's platform (its massless pad, on
//! the tip spring) rubs a fixed part under a constant normal load `N` (`mu = 0.3`), 100
//! friction points. SSN-HB with the structured solve (the Newton systems condensed onto the
//! friction unknowns), from rest, at the first resonance; a table of the time per solve,
//! the Newton iterations and the first blade's peak tip deflection, for three loads from
//! nearly free slip to mostly stuck.
//!
//! `cargo run --release -p semismooth-contact --example bladed_disk_friction -- [H]`
//! (default `H = 10`).

mod args;

use std::time::Instant;

use args::positional;
use semismooth::polyalgorithm::{solve_smoothing, PolyalgorithmOptions};
use semismooth::Residual;
use semismooth_contact::hb::{HbOptions, SsnHb, StructuredHbSolver};
use semismooth_contact::structures::{BladedDisk, DiskLoading, SHIPPED_MISTUNING};

fn main() {
    let harmonics: usize = positional(1, 10, "H: a positive integer");
    let disk = BladedDisk {
        blades: 100,
        mistuning: SHIPPED_MISTUNING,
    };
    let loading = DiskLoading::shipped(Vec::new());
    println!(
        "| normal load N | H | unknowns | Newton iterations | solve time | blade 0 peak tip |"
    );
    println!("|---:|---:|---:|---:|---:|---:|");
    for normal_load in [1e-4, 1e-2, 1.0] {
        let (structure, omega) = disk
            .with_platform_friction(&loading, 0.3, normal_load)
            .expect("a valid disk");
        let options = HbOptions {
            harmonics,
            ..HbOptions::default()
        };
        let start = Instant::now();
        let mut hb = SsnHb::new(&structure.model, omega, &options).expect("a valid problem");
        let mut x = vec![0.0; hb.dim()];
        let newton = PolyalgorithmOptions::default();
        let report = solve_smoothing(&mut hb, &mut StructuredHbSolver::new(), &mut x, &newton)
            .expect("the solve runs");
        let seconds = start.elapsed().as_secs_f64();
        assert!(
            report.converged(),
            "N = {normal_load}: {:?}",
            report.termination
        );
        let tip = hb
            .displacement_samples(&x, BladedDisk::tip(0), 512)
            .expect("a dof of the model");
        let peak = tip.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        println!(
            "| {normal_load:.0e} | {harmonics} | {} | {} | {seconds:.2} s | {peak:.4e} |",
            hb.dim(),
            report.iterations
        );
    }
}
