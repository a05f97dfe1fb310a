//! The memory of a long SSN-HB sweep on a large model, keeping full states or only the
//! contact forces ([`StateStorage`]).
//!
//! `cargo run --release -p semismooth-contact --example sweep_memory -- ELEMENTS H POINTS STORAGE [TOL]`
//!
//! Sweeps the modified-mass rod refined to `ELEMENTS` elements (`N = ELEMENTS` dofs, one tip
//! contact at gap 0.5, distributed load 0.2) with `H` harmonics from `0.5 omega_1` upwards
//! until `POINTS` points (step 0.005, stability off: the monodromy is limited to 400 dofs),
//! storing `full` or `contact-forces` (Newton's tolerance on `|F|` `TOL`, default the
//! scene's: at `10^5` elements the residual's round-off floor `eps max K_ii sqrt(n) max|u|`
//! is near 5e-8, so give `1e-7`), and prints the points, the numbers their states keep
//! against `(2H + 1)(N + m)` a point, the peak resident memory (`VmHWM` of
//! `/proc/self/status`) and the wall time. Run it under `/usr/bin/time -v` for the
//! maximum resident set size as the system counts it.

use std::time::Instant;

use semismooth_contact::rod::{build_rod, MassModel, RodContact, RodSpec};
use semismooth_contact::settings::{GlobalizationChoice, Method, SolverSettings, SweepSettings};
use semismooth_contact::sweep::{frequency_response_storing, StateStorage};

/// The peak resident set size of this process in MB (`VmHWM`), `NaN` where unreadable.
fn peak_resident_mb() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|line| line.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let number = |i: usize, default: usize| {
        args.get(i)
            .map_or(Ok(default), |a| a.parse::<usize>())
            .unwrap_or_else(|e| panic!("argument {}: {e}", i + 1))
    };
    let (elements, harmonics, points) = (number(0, 10_000), number(1, 20), number(2, 200));
    let storage = match args.get(3).map_or("contact-forces", String::as_str) {
        "full" => StateStorage::Full,
        "contact-forces" => StateStorage::ContactForces,
        other => panic!("storage {other}: allowed full, contact-forces"),
    };
    let rod = build_rod(&RodSpec {
        elements,
        amplitude: 0.2,
        mass: MassModel::Modified,
        contacts: vec![RodContact {
            node: elements,
            gap: 0.5,
        }],
        ..RodSpec::canonical()
    })
    .expect("the rod builds");
    // The sweeps' settings of the tests: 100 Newton iterations, non-monotone line search.
    let mut settings = SolverSettings {
        method: Method::SsnHb,
        max_iterations: 100,
        globalization: GlobalizationChoice::Nonmonotone,
        ..SolverSettings::with_harmonics(harmonics)
    };
    if let Some(tolerance) = args.get(4) {
        settings.tolerance = tolerance.parse().expect("argument 5: a tolerance");
    }
    let sweep = SweepSettings {
        step: 0.005,
        max_step: 0.005,
        max_points: points,
        stability: false,
        ..SweepSettings::new(0.5, 4.0)
    };
    let started = Instant::now();
    let before = peak_resident_mb();
    let response =
        frequency_response_storing(&rod, &settings, &sweep, storage, None).expect("the sweep runs");
    let seconds = started.elapsed().as_secs_f64();
    let (n, m) = (rod.model.dofs(), rod.model.contact_count());
    let full_mb = |p: usize| (p * (2 * harmonics + 1) * (n + m) * 8) as f64 / 1e6;
    let p = response.points.len();
    println!(
        "N = {n}, m = {m}, H = {harmonics}, storage {:?}: {p} points to omega = {:.4} omega_1 ({})",
        response.state_storage,
        response
            .points
            .last()
            .map_or(f64::NAN, |q| q.omega / rod.omega_1),
        response.termination,
    );
    println!(
        "stored states {:.2} MB (full states would be {:.1} MB); peak resident {:.0} MB \
         ({:.0} MB after building the rod); {seconds:.1} s wall",
        (response.stored_state_numbers() * 8) as f64 / 1e6,
        full_mb(p),
        peak_resident_mb(),
        before,
    );
}
