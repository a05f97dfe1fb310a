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
//! A second table sweeps each engine order over 2 % either side of its resonance, whole and
//! by the sector (pseudo-arclength continuation, no stability), and checks every point of
//! the sector's sweep against the full disk solved at its frequency from the recovered
//! state moved by 1e-3.
//!
//! `cargo run --release --example cyclic_disk -- [BLADES] [HARMONICS]` (defaults 100, 5).

mod args;

use std::time::Instant;

use args::positional;
use semismooth_contact::cyclic::CyclicSector;
use semismooth_contact::model::Structure;
use semismooth_contact::rod::natural_frequencies;
use semismooth_contact::settings::{default_hb_time_samples, SolverSettings, SweepSettings};
use semismooth_contact::solve::{solve, Solution};
use semismooth_contact::structures::{BladedDisk, DiskLoading};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};

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

/// One engine order's problem: the sector, its structure, the full disk with the
/// engine-order load, the forcing frequency (the nodal diameter's resonance), the samples
/// and the settings.
struct Case {
    sector: CyclicSector,
    sector_structure: Structure,
    full: Structure,
    nd: usize,
    omega: f64,
    samples: usize,
    settings: SolverSettings,
}

fn case(disk: &BladedDisk, loading: &DiskLoading, engine_order: usize, harmonics: usize) -> Case {
    let blades = disk.blades;
    let (sector, _) = disk
        .cyclic_sector(loading, engine_order)
        .expect("a valid sector");
    let sector_structure = sector.structure(1).expect("blade 0's tip");
    let mut full = disk.structure(loading).expect("a valid disk");
    let load = full.model.load.clone();
    full.model.load =
        (load.delayed_by_sector(&disk.sector_dofs(), engine_order)).expect("the disk's sectors");
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
    Case {
        sector,
        sector_structure,
        full,
        nd,
        omega,
        samples,
        settings,
    }
}

/// The largest difference between `a` and `b`, relative to the largest entry of `b`.
fn relative_gap(a: &[f64], b: &[f64]) -> f64 {
    let scale = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
        / scale
}

/// A converged sweep and its wall time in seconds.
fn timed_sweep(structure: &Structure, c: &Case, sweep: &SweepSettings) -> (FrequencyResponse, f64) {
    let start = Instant::now();
    let response = frequency_response(structure, &c.settings, sweep, None).expect("a valid sweep");
    assert!(response.converged(), "{:?}", response.termination);
    (response, start.elapsed().as_secs_f64())
}

/// The sweep row of one engine order: both sweeps timed, and the sector's points checked
/// against the full disk solved at their frequencies.
fn sweep_row(disk: &BladedDisk, c: &Case, engine_order: usize) {
    let ratio = c.omega / c.sector_structure.omega_1;
    let sweep = SweepSettings {
        stability: false,
        ..SweepSettings::new(0.98 * ratio, 1.02 * ratio)
    };
    let (full_response, full_seconds) = timed_sweep(&c.full, c, &sweep);
    let (response, sector_seconds) = timed_sweep(&c.sector_structure, c, &sweep);
    let harmonics = c.settings.harmonics;
    let len = 3 * disk.blades * (2 * harmonics + 1);
    let mut gap = 0.0f64;
    for point in &response.points {
        let recovered = disk.recover_state(&c.sector, &point.state, harmonics);
        let start: Vec<f64> = recovered.iter().map(|v| v * 1.001).collect();
        let solution = solve(&c.full, point.omega, &c.settings, Some(&start)).expect("a solve");
        assert!(solution.converged(), "{:?}", solution.termination);
        gap = gap.max(relative_gap(&recovered[..len], &solution.state[..len]));
    }
    assert!(
        gap < 1e-10,
        "EO {engine_order}: sweep against full disk {gap:e}"
    );
    println!(
        "| {engine_order} | {} | {} | {full_seconds:.3} | {sector_seconds:.4} | {:.0} | {gap:.1e} |",
        full_response.points.len(),
        response.points.len(),
        full_seconds / sector_seconds,
    );
}

fn main() {
    let blades: usize = positional(1, 100, "BLADES: a positive integer");
    let harmonics: usize = positional(2, 5, "HARMONICS: a positive integer");
    assert!(
        blades >= 1 && harmonics >= 1,
        "BLADES and HARMONICS: positive integers"
    );
    let disk = BladedDisk::tuned(blades);
    let loading = DiskLoading {
        amplitude: 0.06,
        ..DiskLoading::shipped((0..blades).collect())
    };
    let cases: Vec<Case> = [0, 3, 7]
        .map(|eo| case(&disk, &loading, eo, harmonics))
        .into_iter()
        .collect();
    println!("| EO | nodal diameter | omega | samples | full (s) | sector (s) | speed-up | max difference |");
    println!("|---|---|---|---|---|---|---|---|");
    for (engine_order, c) in [0, 3, 7].into_iter().zip(&cases) {
        let (reference, full_seconds) = timed(&c.full, c.omega, &c.settings);
        let (solution, sector_seconds) = timed(&c.sector_structure, c.omega, &c.settings);
        let len = 3 * blades * (2 * harmonics + 1);
        let recovered = disk.recover(&c.sector, &solution.state, harmonics);
        let gap = relative_gap(&recovered, &reference.state[..len]);
        // Both converged to 1e-12 on the same discrete equations (samples a multiple of
        // N / gcd(N, EO)): what the docs' table claims.
        assert!(
            gap < 1e-10,
            "EO {engine_order}: sector against full disk {gap:e}"
        );
        println!(
            "| {engine_order} | {} | {:.6} | {} | {full_seconds:.4} | {sector_seconds:.5} | {:.0} | \
             {gap:.1e} |",
            c.nd,
            c.omega,
            c.samples,
            full_seconds / sector_seconds,
        );
    }
    println!();
    println!("| EO | points (full) | points (sector) | full sweep (s) | sector sweep (s) | speed-up | max difference at the sector's points |");
    println!("|---|---|---|---|---|---|---|");
    for (engine_order, c) in [0, 3, 7].into_iter().zip(&cases) {
        sweep_row(&disk, c, engine_order);
    }
}
