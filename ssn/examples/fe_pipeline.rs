//! The steps of a finite-element scene timed one by one: parse the scene (and the `.dof`
//! map), read the CalculiX matrices, import (read, symmetry and range checks, `omega_1`),
//! `omega_1` alone (one sparse Cholesky of `K` and shift-invert Lanczos), the scene's
//! `[reduction]` (Cholesky of `K_ii`, fixed-interface modes, constraint modes, projection)
//! and one harmonic-balance solve of the reduced model at the scene's frequency; with
//! `--exact`, also the exact unreduced solve (SSN-HB condensed onto the contact unknowns,
//! one sparse factorization of the full model's harmonic blocks held at a time:
//! `solve::solve_condensed`) and the difference of the two answers at the observed dof. Prints a Markdown table of wall and CPU seconds and the
//! peak resident memory after each step, and the load average before and after (the
//! machine may be shared: compare ratios between steps, not absolute times).
//!
//! ```sh
//! # the 54,000-dof cantilever with 16 tip contacts (docs/finite_element_models.md):
//! python3 ssn/examples/fe_pipeline_deck.py /tmp/fe_big 80 14 14 && (cd /tmp/fe_big && ccx big)
//! cargo run --release -p ssn --example fe_pipeline -- /tmp/fe_big            # big.toml
//! cargo run --release -p ssn --example fe_pipeline -- DIR scene.toml [--exact]
//! ```

use std::path::{Path, PathBuf};
use std::time::Instant;

use semismooth_contact::matrix_market::read_calculix_matrix;
use semismooth_contact::reduction::lowest_frequencies;
use semismooth_contact::solve::Solution;
use ssn::cli::prepare;
use ssn::scene::Scene;
use ssn::work::Workload;

/// User plus system CPU seconds of this process so far (`/proc/self/stat`, 100 ticks a
/// second); 0 where there is no `/proc`.
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the parenthesised command name: utime and stime are the 12th and 13th.
    let after = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = after.split_whitespace().collect();
    let ticks = |k: usize| {
        fields
            .get(k)
            .and_then(|f| f.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

/// The peak resident memory of this process so far in MB (`VmHWM` of `/proc/self/status`);
/// 0 where there is no `/proc`.
fn peak_megabytes() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kb = status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .unwrap_or(0.0);
    kb / 1024.0
}

fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "unknown".into())
}

/// Times `f`, prints its row and returns its value.
fn step<T>(rows: &mut Vec<Row>, name: &str, f: impl FnOnce() -> T) -> T {
    let (wall, cpu) = (Instant::now(), cpu_seconds());
    let value = f();
    let row = (
        name.to_string(),
        wall.elapsed().as_secs_f64(),
        cpu_seconds() - cpu,
        peak_megabytes(),
    );
    eprintln!(
        "{:<40} {:>8.2} s wall {:>8.2} s CPU {:>8.0} MB peak",
        row.0, row.1, row.2, row.3
    );
    rows.push(row);
    value
}

/// Prints how the exact solve ended and how far the reduced answer's observed dof is from
/// its over the period.
fn print_difference(exact: &Solution, reduced: &Solution) {
    let scale = exact.observed.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let difference = (exact.observed.iter().zip(&reduced.observed))
        .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    println!(
        "exact: converged {} in {} iterations ({:?}, |F| = {:.3e}, c = {:?}); max |u_reduced - \
         u_exact| over the period = {:.2e} of max |u_exact| = {scale:.6e}",
        exact.converged(),
        exact.iterations,
        exact.termination,
        exact.residual_norm,
        exact.c,
        difference / scale
    );
}

/// A step's name, wall and CPU seconds, and the peak resident memory after it (MB).
type Row = (String, f64, f64, f64);

fn main() {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .expect("usage: fe_pipeline DIR [SCENE] [--exact]"),
    );
    let exact = std::env::args().any(|a| a == "--exact");
    let name = std::env::args()
        .nth(2)
        .filter(|a| a != "--exact")
        .unwrap_or_else(|| "big.toml".into());
    let path = dir.join(name);
    let load_before = load_average();
    let mut rows = Vec::new();
    let scene = step(&mut rows, "parse the scene and the .dof map", || {
        Scene::from_path(&path).unwrap_or_else(|e| panic!("{e}"))
    });
    let spec = scene.model.clone().expect("a [model] scene");
    let n = spec.dof_map.as_ref().map_or(0, |d| d.map.len());
    step(&mut rows, "read K and M (.sti, .mas)", || {
        let read = |p: &Path| read_calculix_matrix(p, n).unwrap_or_else(|e| panic!("{e}"));
        (read(&spec.stiffness), read(&spec.mass))
    });
    let loaded = step(&mut rows, "import (read, checks, omega_1)", || {
        prepare(scene.clone(), Workload::Check, None).unwrap_or_else(|e| panic!("{e}"))
    });
    let full = &loaded.structure;
    let omega_1 = step(&mut rows, "omega_1 alone (Cholesky + Lanczos)", || {
        lowest_frequencies(&full.model, 1).unwrap_or_else(|e| panic!("{e}"))[0]
    });
    let spec = scene.reduction.as_ref().expect("a [reduction] section");
    let reduced = step(&mut rows, "reduce (Craig-Bampton)", || {
        ssn::reduce::reduce(&scene, spec, full, loaded.omega).unwrap_or_else(|e| panic!("{e}"))
    });
    let solution = step(&mut rows, "solve one frequency (reduced)", || {
        semismooth_contact::solve(&reduced.structure, loaded.omega, &scene.solver, None)
            .unwrap_or_else(|e| panic!("{e}"))
    });
    if exact {
        let size = 2 * scene.solver.harmonics + 1;
        let full_solution = step(&mut rows, "solve one frequency (exact, unreduced)", || {
            // The reduced solve's equations (its `c`, which it may have raised), started from
            // its contact forces (the same contact rows).
            let forces = &solution.state[reduced.structure.model.dofs() * size..];
            let settings = semismooth_contact::settings::SolverSettings {
                c: solution.c,
                ..scene.solver.clone()
            };
            semismooth_contact::solve::solve_condensed(full, loaded.omega, &settings, Some(forces))
                .unwrap_or_else(|e| panic!("{e}"))
        });
        print_difference(&full_solution, &solution);
    }
    let total: (f64, f64) = rows.iter().fold((0.0, 0.0), |t, r| (t.0 + r.1, t.1 + r.2));
    println!(
        "model: {} dofs, {} contacts, omega_1 = {omega_1:.6} (import: {:.6}); reduced to {} \
         dofs ({} boundary, {} modes up to {:.6})",
        full.model.dofs(),
        full.model.contacts.len(),
        full.omega_1,
        reduced.structure.model.dofs(),
        reduced.boundary.len(),
        reduced.interface_frequencies.len(),
        reduced.interface_frequencies.last().copied().unwrap_or(0.0),
    );
    let peak = solution.observed.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    println!(
        "solve: converged {} in {} iterations, max |u_observed| = {peak:.6e}",
        solution.converged(),
        solution.iterations
    );
    println!(
        "load average (1, 5, 15 min): before {load_before}, after {}",
        load_average()
    );
    println!("\n| step | wall s | CPU s | peak MB after |\n|---|---|---|---|");
    for (name, wall, cpu, peak) in &rows {
        println!("| {name} | {wall:.2} | {cpu:.2} | {peak:.0} |");
    }
    println!("| total | {:.2} | {:.2} | |", total.0, total.1);
}
