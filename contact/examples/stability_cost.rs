//! What stability costs in a sweep, and how its verdicts compare with the discrete
//! monodromy of the time-stepping map (the shooting verdict).
//!
//! `cargo run --release -p semismooth-contact --example stability_cost`
//!
//! For the branches of the default run's Fig. 2 (gaps 0.25, 0.5, 0.75; consistent mass at
//! H = 5, modified mass at H = 20) it sweeps each twice, with and without stability, best
//! of `REPEATS` runs each, and prints the time of both and their ratio (measured in the
//! same run). Times are the process's CPU time (user + system, from `/proc/self/stat`,
//! 10 ms ticks), which the load of a shared machine does not inflate as it does wall time. For the modified-mass branches it then compares every point's verdict with
//! the shooting verdict ([`map_stability`]) and prints how many agree, the points where they
//! differ, and the time per point of both analyses.

use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::settings::{SolverSettings, SweepSettings};
use semismooth_contact::stability::{map_stability, HbStability, StabilityOptions};
use semismooth_contact::sweep::frequency_response;

/// Runs per configuration; the fastest is reported.
const REPEATS: usize = 3;

fn main() {
    println!(
        "{:<8} {:>4} {:>7} {:>7} {:>12} {:>12} {:>6}",
        "mass", "H", "gap", "points", "no stab. ms", "with ms", "ratio"
    );
    println!(
        "(CPU time, best of {REPEATS}; {})",
        std::fs::read_to_string("/proc/loadavg")
            .map(|l| format!(
                "load average {}",
                l.split_whitespace().next().unwrap_or("?")
            ))
            .unwrap_or_default()
    );
    let mut comparisons = Vec::new();
    for (mass, harmonics) in [(MassModel::Consistent, 5), (MassModel::Modified, 20)] {
        for gap in [0.25, 0.5, 0.75] {
            let rod = build_rod(&RodSpec {
                mass,
                ..RodSpec::canonical().with_tip_gap(Some(gap))
            })
            .expect("the canonical rod builds");
            let settings = SolverSettings::with_harmonics(harmonics);
            let sweep = SweepSettings {
                step: 0.005,
                max_step: 0.005,
                max_points: 5000,
                ..SweepSettings::new(0.5, 2.0)
            };
            let time = |stability: bool| {
                let sweep = SweepSettings { stability, ..sweep };
                (0..REPEATS)
                    .map(|_| {
                        let t = cpu_seconds();
                        let r = frequency_response(&rod, &settings, &sweep, None)
                            .expect("the sweep runs");
                        (cpu_seconds() - t, r)
                    })
                    .min_by(|a, b| a.0.total_cmp(&b.0))
                    .expect("at least one run")
            };
            let (without, _) = time(false);
            let (with, response) = time(true);
            println!(
                "{:<8} {:>4} {:>7} {:>7} {:>12.1} {:>12.1} {:>6.2}",
                format!("{mass:?}").to_lowercase(),
                harmonics,
                gap,
                response.points.len(),
                1e3 * without,
                1e3 * with,
                with / without
            );
            if mass == MassModel::Modified {
                comparisons.push((gap, rod, settings, response));
            }
        }
    }
    println!("\nAgainst the shooting verdict (modified mass, H = 20, every point):");
    for (gap, rod, settings, r) in comparisons {
        let (mut agree, mut differ, mut undecided) = (0, Vec::new(), 0);
        let t = cpu_seconds();
        let n = rod.model.dofs() * (2 * settings.harmonics + 1);
        for i in 0..r.points.len() {
            let map = map_stability(
                &rod.model,
                settings.harmonics,
                r.points[i].omega,
                &r.points[i].state[..n],
                &StabilityOptions::default(),
            )
            .expect("the shooting runs");
            match (map.stable, r.points[i].stability.stable) {
                (Some(a), Some(b)) if a == b => agree += 1,
                (Some(_), Some(_)) => differ.push(r.points[i].omega / rod.omega_1),
                _ => undecided += 1,
            }
        }
        let shooting = cpu_seconds() - t;
        let t = cpu_seconds();
        let mut analysis =
            HbStability::new(&rod.model, &settings).expect("a harmonic-balance method");
        for i in 0..r.points.len() {
            analysis
                .of(r.points[i].omega, &r.points[i].state)
                .expect("the phases run");
        }
        let phases = cpu_seconds() - t;
        println!(
            "gap {gap}: {} points, {agree} agree, {} differ at omega/omega_1 {:.4?}, {undecided} \
             undecided by one of them; shooting {:.2} ms per point, contact phases {:.3} ms",
            r.points.len(),
            differ.len(),
            differ,
            1e3 * shooting / r.points.len() as f64,
            1e3 * phases / r.points.len() as f64
        );
    }
}

/// CPU time of this process (user + system), from `/proc/self/stat` (Linux; 0 elsewhere).
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the command name (which is in parentheses): utime and stime are the
    // 12th and 13th of them, in clock ticks of 1/100 s.
    let rest = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |k: usize| {
        fields
            .get(k)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}
