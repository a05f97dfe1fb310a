//! The tuned bladed disk with a casing contact on every blade under engine orders 0, 3
//! and 7, solved whole and by one cyclic sector (`semismooth_contact::cyclic`): the time
//! of each solve, the speed-up, and the largest difference of the disk's coefficients
//! recovered from the sector against the full solve (relative to the largest).
//!
//! Each engine order is forced at the lowest natural frequency of its nodal diameter,
//! with three times the shipped load so that the casing closes. The AFT samples are a
//! multiple of `N / gcd(N, EO)`, so that the sector delay `EO T / N` is a whole number of
//! samples and the sector poses exactly the full disk's equations.
//!
//! `cargo run --release --example cyclic_disk -- [BLADES] [HARMONICS]` (defaults 100, 5).

mod args;

use std::time::Instant;

use args::positional;
use semismooth_contact::model::Structure;
use semismooth_contact::rod::natural_frequencies;
use semismooth_contact::settings::{default_hb_time_samples, SolverSettings};
use semismooth_contact::solve::{solve, Solution};
use semismooth_contact::structures::{BladedDisk, DiskLoading};

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// A converged solve and its wall time in seconds.
fn timed(structure: &Structure, omega: f64, settings: &SolverSettings) -> (Solution, f64) {
    let start = Instant::now();
    let solution = solve(structure, omega, settings, None).expect("a valid solve");
    assert!(solution.converged(), "{:?}", solution.termination);
    (solution, start.elapsed().as_secs_f64())
}

fn main() {
    let blades: usize = positional(1, 100, "BLADES: a positive integer");
    let harmonics: usize = positional(2, 5, "HARMONICS: a positive integer");
    assert!(
        blades >= 1 && harmonics >= 1,
        "BLADES and HARMONICS: positive integers"
    );
    let disk = BladedDisk {
        blades,
        mistuning: 0.0,
    };
    let loading = DiskLoading {
        amplitude: 0.06,
        ..DiskLoading::shipped((0..blades).collect())
    };
    println!("| EO | nodal diameter | omega | samples | full (s) | sector (s) | speed-up | max difference |");
    println!("|---|---|---|---|---|---|---|---|");
    for engine_order in [0, 3, 7] {
        let (sector, _) = disk
            .cyclic_sector(&loading, engine_order)
            .expect("a valid sector");
        let sector_structure = sector.structure(1).expect("blade 0's tip");
        let mut full = disk.structure(&loading).expect("a valid disk");
        let load = full.model.load.clone();
        full.model.load = (load.delayed_by_sector(&disk.sector_dofs(), engine_order))
            .expect("the disk's sectors");
        let nd = sector.nodal_diameter(1);
        let omega = natural_frequencies(&sector.nodal_diameter_model(nd), 1).expect("modes")[0];
        let period = blades / gcd(blades, engine_order % blades);
        let samples = default_hb_time_samples(harmonics).div_ceil(period) * period;
        let settings = SolverSettings {
            harmonics,
            time_samples: samples,
            tolerance: 1e-12,
            c: Some(5.0),
            estimate_error: false,
            ..SolverSettings::default()
        };
        let (reference, full_seconds) = timed(&full, omega, &settings);
        let (solution, sector_seconds) = timed(&sector_structure, omega, &settings);
        let n = 3 * blades;
        let u_full = &reference.state[..n * (2 * harmonics + 1)];
        let reduced = &solution.state[..3 * (2 * harmonics + 1)];
        let scale = u_full.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let mut gap = 0.0f64;
        for s in 0..blades {
            let u_s = sector.sector_coefficients(reduced, harmonics, s);
            for j in 0..2 * harmonics + 1 {
                for dof in 0..4 {
                    let full_dof = (3 * s + dof) % n;
                    gap = gap.max((u_s[j * 4 + dof] - u_full[j * n + full_dof]).abs());
                }
            }
        }
        println!(
            "| {engine_order} | {nd} | {omega:.6} | {samples} | {full_seconds:.4} | \
             {sector_seconds:.5} | {:.0} | {:.1e} |",
            full_seconds / sector_seconds,
            gap / scale
        );
    }
}
