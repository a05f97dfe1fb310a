//! Fold frequencies to an accuracy: a coarse sweep whose folds are located again with more
//! harmonics only around them, against the sweep with the fixed harmonics that meets the
//! same accuracy everywhere.
//!
//! `cargo run --release -p semismooth-contact --example fold_accuracy [-- TARGET [--reference]]`
//!
//! The strongly forced rod (modified mass, `p0 = 0.2`, gap 0.5) is swept over
//! `[0.5, 2] ω_1` with SSN-HB at `H = 20`, and [`refine_folds`] brings each fold to the
//! relative `TARGET` (default 1e-4). The fixed-`H` sweep at the finest harmonics the
//! refinement used is run in the same process for its cost and folds; with
//! `--reference`, a sweep at twice those harmonics gives the converged folds (minutes).
//! Times are CPU seconds of this process (`/proc/self/stat`, 10 ms ticks), which the load
//! of a shared machine does not inflate as it does wall time.

mod args;

use args::positional;
use semismooth_contact::rod::{build_rod, MassModel, RodModel, RodSpec};
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::sweep::fold_accuracy::{refine_folds, MAX_FOLD_HARMONICS};
use semismooth_contact::sweep::{frequency_response, FrequencyResponse};

/// CPU seconds (user + system) of this process.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat
        .rsplit(')')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .collect();
    let ticks = |i: usize| fields.get(i).and_then(|v| v.parse::<f64>().ok());
    // Fields 14 and 15 of the line (utime, stime) are 11 and 12 after the command name.
    match (ticks(11), ticks(12)) {
        (Some(u), Some(s)) => (u + s) / 100.0,
        _ => f64::NAN,
    }
}

fn sweep_at(rod: &RodModel, harmonics: usize, sweep: &SweepSettings) -> (FrequencyResponse, f64) {
    let settings = SolverSettings::with_harmonics(harmonics);
    let start = cpu_seconds();
    let response = frequency_response(rod, &settings, sweep, None).expect("the sweep runs");
    assert!(
        response.converged(),
        "H = {harmonics}: {}",
        response.termination
    );
    (response, cpu_seconds() - start)
}

fn main() {
    let target: f64 = positional(1, 1e-4, "TARGET: a number");
    let reference = std::env::args().any(|a| a == "--reference");
    let rod = build_rod(&RodSpec {
        mass: MassModel::Modified,
        amplitude: 0.2,
        ..RodSpec::canonical()
    })
    .expect("the strongly forced rod builds");
    let w1 = rod.omega_1;
    let sweep = SweepSettings {
        stability: false,
        ..SweepSettings::new(0.5, 2.0)
    };
    let coarse_h = 20;
    let (coarse, coarse_cpu) = sweep_at(&rod, coarse_h, &sweep);
    let start = cpu_seconds();
    let folds = refine_folds(
        &rod,
        &SolverSettings::with_harmonics(coarse_h),
        &sweep,
        &coarse,
        (target, MAX_FOLD_HARMONICS),
    )
    .expect("the refinement runs");
    let refine_cpu = cpu_seconds() - start;
    let finest = folds
        .iter()
        .map(|f| f.harmonics())
        .max()
        .unwrap_or(coarse_h);
    let (fixed, fixed_cpu) = sweep_at(&rod, finest, &sweep);
    let converged = reference.then(|| sweep_at(&rod, 2 * finest, &sweep).0);

    println!(
        "strongly forced rod, SSN-HB, target {target:e} on fold frequencies ({})",
        std::fs::read_to_string("/proc/loadavg")
            .map(|l| format!("load {}", l.split_whitespace().next().unwrap_or("?")))
            .unwrap_or_default()
    );
    println!(
        "{:>4} {:>11} {:>11} {:>11} {:>5} {:>11} {:>11}  ladder (H: omega/omega_1)",
        "fold", "sweep H=20", "refined", "uncert.", "H", "fixed H", "converged"
    );
    for (k, f) in folds.iter().enumerate() {
        let ladder: Vec<String> = f
            .rungs
            .iter()
            .map(|r| format!("{}: {:.6}", r.harmonics, r.omega / w1))
            .collect();
        println!(
            "{:>4} {:>11.6} {:>11.6} {:>11.2e} {:>5} {:>11.6} {:>11}  {}{}",
            k,
            f.sweep_omega / w1,
            f.omega / w1,
            f.uncertainty.map_or(f64::NAN, |u| u / f.omega),
            f.harmonics(),
            fixed.folds.get(k).map_or(f64::NAN, |w| w / w1),
            converged
                .as_ref()
                .and_then(|c| c.folds.get(k))
                .map_or("-".to_string(), |w| format!("{:.6}", w / w1)),
            ladder.join(", "),
            if f.met() {
                String::new()
            } else {
                format!("  (not met: {:?})", f.stop)
            }
        );
    }
    println!(
        "cost (CPU s): sweep H = {coarse_h} {coarse_cpu:.2} + folds {refine_cpu:.2} = {:.2}; \
         fixed H = {finest} sweep {fixed_cpu:.2}; ratio {:.2}",
        coarse_cpu + refine_cpu,
        (coarse_cpu + refine_cpu) / fixed_cpu
    );
}
