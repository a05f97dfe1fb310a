//! Forced response of a tuned 24-blade blisk with friction dampers between neighbouring
//! blades under several engine orders, each computed on one cyclic sector
//! (`scenes/blisk_dampers_sector.toml` is engine order 3): the blade tip's amplitude over
//! a sweep of the forcing frequency, with the dampers (gap 0.2, `mu = 0.3`) and without
//! them (the linear sector). Each engine order's peak is checked against the whole disk
//! solved at its frequency from the recovered state moved by 1e-3 (the largest difference,
//! relative, is printed).
//!
//! `cargo run --release -p ssn --example blisk_dampers -- [--write]`: prints the peaks;
//! `--write` also writes `docs/blisk_dampers.svg`.

use std::path::Path;
use std::time::Instant;

use semismooth_contact::cyclic::CyclicSector;
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::solve::solve;
use semismooth_contact::structures::{BladeDamper, BladedDisk, DiskLoading};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};
use ssn::output::{write_line_plot, PlotSpec, Series};

const BLADES: usize = 24;
const HARMONICS: usize = 5;
const DAMPER: BladeDamper = BladeDamper {
    gap: 0.2,
    friction: 0.3,
};

fn settings() -> SolverSettings {
    SolverSettings {
        harmonics: HARMONICS,
        // A multiple of N = 24: every engine order's delay is a whole number of samples.
        time_samples: 72,
        tolerance: 1e-12,
        c: Some(5.0),
        estimate_error: false,
        ..SolverSettings::default()
    }
}

fn sweep(sector: &CyclicSector) -> FrequencyResponse {
    let structure = sector.structure(1).expect("blade 0's tip");
    let range = SweepSettings {
        stability: false,
        max_step: 0.02,
        max_points: 20_000,
        ..SweepSettings::new(0.95, 1.8)
    };
    // A branch that turns back before the upper bound (folds of the damped response) is
    // kept as computed: its points are solutions all the same.
    frequency_response(&structure, &settings(), &range, None).expect("a sweep")
}

/// The largest relative difference between the disk recovered from the sector's point
/// `at` and the whole disk solved there from it moved by 1e-3.
fn check_against_full_disk(disk: &BladedDisk, sector: &CyclicSector, at: (f64, &[f64])) -> f64 {
    let loading = DiskLoading::shipped(Vec::new());
    let mut full = disk.structure(&loading).expect("the disk");
    full.model.load = (full.model.load.clone())
        .delayed_by_sector(&disk.sector_dofs(), sector.engine_order())
        .expect("the disk's sectors");
    DAMPER.add_to_disk(disk, &mut full.model);
    let recovered = disk.recover_state(sector, at.1, HARMONICS);
    let start: Vec<f64> = recovered.iter().map(|v| v * 1.001).collect();
    let solution = solve(&full, at.0, &settings(), Some(&start)).expect("a solve");
    assert!(solution.converged(), "{:?}", solution.termination);
    let len = 3 * BLADES * (2 * HARMONICS + 1);
    let u = &solution.state[..len];
    let scale = u.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    (u.iter().zip(&recovered)).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / scale
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let write = std::env::args().any(|a| a == "--write");
    let disk = BladedDisk::tuned(BLADES);
    let loading = DiskLoading::shipped(Vec::new());
    println!("| EO | peak omega / omega_1 (dampers) | peak tip amplitude (dampers) | peak (no dampers) | points | reached the upper bound | sector sweep (s) | full disk at the peak |");
    println!("|---|---|---|---|---|---|---|---|");
    let mut series = Vec::new();
    for (color, engine_order) in [1usize, 3, 6, 12].into_iter().enumerate() {
        let (bare, _) = disk
            .cyclic_sector(&loading, engine_order)
            .expect("a sector");
        let damped = DAMPER.add_to_sector(&bare).expect("a damped sector");
        let start = Instant::now();
        let response = sweep(&damped);
        let seconds = start.elapsed().as_secs_f64();
        let linear = sweep(&bare);
        let peak = (response.points.iter())
            .max_by(|a, b| a.amplitude.total_cmp(&b.amplitude))
            .expect("points");
        let linear_peak = linear.points.iter().fold(0.0f64, |m, p| m.max(p.amplitude));
        let gap = check_against_full_disk(&disk, &damped, (peak.omega, &peak.state));
        // The sector poses the whole disk's equations (samples a multiple of N): both
        // converged to 1e-12: what the docs' table claims (1e-10).
        assert!(
            gap < 1e-10,
            "EO {engine_order}: sector against whole disk {gap:e}"
        );
        println!(
            "| {engine_order} | {:.4} | {:.4} | {linear_peak:.4} | {} | {} | {seconds:.3} | {gap:.1e} |",
            peak.omega / response.omega_1,
            peak.amplitude,
            response.points.len(),
            response.converged(),
        );
        let curve = |r: &FrequencyResponse| -> (Vec<f64>, Vec<f64>) {
            r.points
                .iter()
                .map(|p| (p.omega / r.omega_1, p.amplitude))
                .unzip()
        };
        let (x, y) = curve(&response);
        let mut s = Series::new(format!("EO {engine_order}, dampers"), x, y);
        s.color = Some(color);
        series.push(s);
        let (x, y) = curve(&linear);
        let mut s = Series::dashed(format!("EO {engine_order}, no dampers"), x, y);
        s.color = Some(color);
        series.push(s);
    }
    if write {
        let spec = PlotSpec {
            title: format!(
                "Blisk of {BLADES} blades with friction dampers between blades, by one sector"
            ),
            x_label: "omega / omega_1".into(),
            y_label: "blade tip amplitude".into(),
            log_log: false,
        };
        write_line_plot(Path::new("docs/blisk_dampers.svg"), &spec, &series)?;
        println!("wrote docs/blisk_dampers.svg");
    }
    Ok(())
}
