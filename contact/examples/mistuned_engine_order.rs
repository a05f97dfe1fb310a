//! A mistuned bladed disk under an engine-order excitation, scanned on the full model (a
//! mistuned disk has no cyclic symmetry), beside the tuned disk scanned on one cyclic sector:
//! the largest blade-tip amplitude over the scan and over the blades, and its
//! amplification factor against the tuned sector's peak, for several mistuning amplitudes
//! of the builder's pattern `delta_j = m sin(2.3 j)` (`structures::BladedDisk`).
//!
//! 24 blades, a casing contact on every blade (gap 1, three times the shipped load), engine
//! order 3, 5 harmonics, 72 samples (a multiple of `N / gcd(N, EO) = 8`), scanned upward
//! over 8 % either side of nodal diameter 3's resonance (161 frequencies, warm starts).
//! The row "0 (full)" is the tuned disk scanned whole: its peak is the tuned sector's (the
//! check of the sector's scan).
//!
//! Then other mistuning patterns at amplitudes 0.01 and 0.05: the builder's, random
//! (uniform in `[-m, m]` from a seeded xorshift generator, seed 1), alternate
//! (`(-1)^j m`) and one rogue blade (blade 0 at `-m`, the others tuned), each against the
//! same tuned peak.
//!
//! `cargo run --release --example mistuned_engine_order [-- --write]`; `--write` puts the
//! patterns' table into `docs/mistuning_patterns.md`.

use std::time::Instant;

use semismooth_contact::model::Structure;
use semismooth_contact::rod::natural_frequencies;
use semismooth_contact::settings::SolverSettings;
use semismooth_contact::solve::solve;
use semismooth_contact::structures::{BladedDisk, DiskLoading};

const BLADES: usize = 24;
const HARMONICS: usize = 5;
const ENGINE_ORDER: usize = 3;
/// Frequencies of each scan.
const POINTS: usize = 161;

fn settings() -> SolverSettings {
    SolverSettings {
        harmonics: HARMONICS,
        time_samples: 72,
        tolerance: 1e-12,
        c: Some(5.0),
        estimate_error: false,
        ..SolverSettings::default()
    }
}

/// `max_t |u(t)|` of one dof from its harmonic-major coefficients (`n` dofs), on 144
/// instants of the period.
fn amplitude(u: &[f64], n: usize, dof: usize) -> f64 {
    (0..144)
        .map(|i| {
            let t = 2.0 * std::f64::consts::PI * i as f64 / 144.0;
            (1..=HARMONICS).fold(u[dof], |v, k| {
                let (a, b) = (u[(2 * k - 1) * n + dof], u[2 * k * n + dof]);
                v + a * (k as f64 * t).cos() + b * (k as f64 * t).sin()
            })
        })
        .fold(0.0f64, |m, v| m.max(v.abs()))
}

/// An upward scan of `structure` over `POINTS` frequencies from `from` to `to`, each solve
/// warm-started from the previous one (so it follows the upper branch of an overhang until
/// it jumps): the largest tip amplitude over the points and the blades `blades` (the tip of
/// blade `j` is dof `3 j + 1`), the solves that did not converge, and the wall time.
fn peak(structure: &Structure, from: f64, to: f64, blades: usize) -> (f64, usize, f64) {
    let n = structure.model.dofs();
    let start = Instant::now();
    let (mut largest, mut failed, mut warm): (f64, usize, Option<Vec<f64>>) = (0.0, 0, None);
    for i in 0..POINTS {
        let omega = from + (to - from) * i as f64 / (POINTS - 1) as f64;
        let solution = solve(structure, omega, &settings(), warm.as_deref()).expect("a solve");
        if !solution.converged() {
            failed += 1;
            warm = None;
            continue;
        }
        for j in 0..blades {
            largest = largest.max(amplitude(&solution.state, n, 3 * j + 1));
        }
        warm = Some(solution.state);
    }
    (largest, failed, start.elapsed().as_secs_f64())
}

/// Seed of the random pattern.
const SEED: u64 = 1;

/// Uniform numbers in `[0, 1)` from the xorshift64 generator seeded `seed` (no dependency:
/// the pattern is the same on every machine).
fn uniform(seed: u64, count: usize) -> Vec<f64> {
    let mut x = seed.max(1);
    (0..count)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x >> 11) as f64 / (1u64 << 53) as f64
        })
        .collect()
}

/// The mistuning patterns of amplitude `m` over `blades` blades, with their names.
fn patterns(m: f64, blades: usize) -> Vec<(&'static str, Vec<f64>)> {
    let sine = (0..blades).map(|j| m * (2.3 * j as f64).sin()).collect();
    let random = uniform(SEED, blades)
        .iter()
        .map(|u| m * (2.0 * u - 1.0))
        .collect();
    let alternate = (0..blades)
        .map(|j| if j % 2 == 0 { m } else { -m })
        .collect();
    let rogue = (0..blades).map(|j| if j == 0 { -m } else { 0.0 }).collect();
    vec![
        ("builder's m sin(2.3 j)", sine),
        ("random, seed 1", random),
        ("alternate", alternate),
        ("one rogue blade", rogue),
    ]
}

/// The markdown page of the patterns' amplification factors (`rows`: pattern, amplitude,
/// failed solves, peak) against the tuned peak `tuned`.
fn patterns_page(rows: &[(&str, f64, usize, f64)], tuned: f64) -> String {
    let mut page = String::from(
        "# Mistuning patterns under engine order 3\n\n\
         Written by `cargo run --release --example mistuned_engine_order -- --write` (do not \
         edit). The 24-blade disk with a casing contact on every blade (gap 1, three times the \
         shipped load), engine order 3, 5 harmonics, 72 samples, scanned upward over 8 % either \
         side of nodal diameter 3's resonance (161 frequencies, warm starts); blade `j`'s \
         stiffness is `k_b (1 + delta_j)`. The amplification factor is the largest blade-tip \
         amplitude over the scan and the blades against the tuned disk's peak by one cyclic \
         sector. Failed solves (near the jumps of the overhangs) are counted, not used.\n\n",
    );
    page.push_str(&format!("Tuned peak (sector): {tuned:.6}.\n\n"));
    page.push_str(
        "| pattern | amplitude m | failed solves | peak tip amplitude | amplification factor |\n",
    );
    page.push_str("|---|---|---|---|---|\n");
    for (name, m, failed, peak) in rows {
        let factor = peak / tuned;
        page.push_str(&format!(
            "| {name} | {m} | {failed} | {peak:.6} | {factor:.3} |\n"
        ));
    }
    page
}

/// The full disk of `pattern` under `loading` and the engine-order load.
fn mistuned_disk(loading: &DiskLoading, pattern: &[f64]) -> Structure {
    let disk = BladedDisk {
        blades: pattern.len(),
        mistuning: 0.0,
    };
    let mut full = (disk.structure_with_mistuning(loading, pattern)).expect("the disk");
    full.model.load = (full.model.load.clone())
        .delayed_by_sector(&disk.sector_dofs(), ENGINE_ORDER)
        .expect("the disk's sectors");
    full
}

fn main() {
    let loading = DiskLoading {
        amplitude: 0.06,
        ..DiskLoading::shipped((0..BLADES).collect())
    };
    let tuned = BladedDisk::tuned(BLADES);
    let (sector, _) = tuned
        .cyclic_sector(&loading, ENGINE_ORDER)
        .expect("a sector");
    let nd = sector.nodal_diameter(1);
    let resonance = natural_frequencies(&sector.nodal_diameter_model(nd), 1).expect("modes")[0];
    let (from, to) = (0.92 * resonance, 1.08 * resonance);
    let structure = sector.structure(1).expect("blade 0's tip");
    // The sector's blade 0 tip is its reduced dof 1 (one sector: every blade is it, delayed).
    let (tuned_peak, failed, sector_seconds) = peak(&structure, from, to, 1);
    println!(
        "| mistuning | failed solves | peak tip amplitude | amplification factor | scan (s) |"
    );
    println!("|---|---|---|---|---|");
    println!("| 0 (sector) | {failed} | {tuned_peak:.6} | 1.000 | {sector_seconds:.3} |");
    for mistuning in [0.0, 0.005, 0.01, 0.02, 0.05] {
        let disk = BladedDisk {
            blades: BLADES,
            mistuning,
        };
        let mut full = disk.structure(&loading).expect("the disk");
        full.model.load = (full.model.load.clone())
            .delayed_by_sector(&disk.sector_dofs(), ENGINE_ORDER)
            .expect("the disk's sectors");
        let (largest, failed, seconds) = peak(&full, from, to, BLADES);
        let name = if mistuning == 0.0 {
            "0 (full)".to_string()
        } else {
            mistuning.to_string()
        };
        println!(
            "| {name} | {failed} | {largest:.6} | {:.3} | {seconds:.3} |",
            largest / tuned_peak
        );
    }
    let mut rows = Vec::new();
    println!("\n| pattern | amplitude | failed solves | peak | amplification factor |");
    println!("|---|---|---|---|---|");
    for m in [0.01, 0.05] {
        for (name, pattern) in patterns(m, BLADES) {
            let full = mistuned_disk(&loading, &pattern);
            let (largest, failed, _) = peak(&full, from, to, BLADES);
            let factor = largest / tuned_peak;
            println!("| {name} | {m} | {failed} | {largest:.6} | {factor:.3} |");
            rows.push((name, m, failed, largest));
        }
    }
    if std::env::args().any(|a| a == "--write") {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../docs/mistuning_patterns.md");
        std::fs::write(path, patterns_page(&rows, tuned_peak)).expect("docs/ is writable");
        println!("wrote {path}");
    }
}
