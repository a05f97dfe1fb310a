//! Contact scaling: SSN-HB on a bladed disk of 3334 blades (10,002 dofs) with stops on 10,
//! 100 and 1,000 evenly spaced blades, H = 20: one solve from zero and one Newton iteration
//! (Jacobian, factorization and solve at the converged active set), with the condensed
//! system factored dense or solved matrix-free (GMRES).
//!
//! `cargo run --release --example contact_scaling -- [--solver auto|dense|krylov]
//! [--harmonics H] [--blades B] [COUNTS...]` (defaults: auto, 20, 3334, `10 100 1000`).
//! Each count runs in a child process of this program so that the peak resident size
//! (`VmHWM` of `/proc/self/status`) is that count's alone.

use std::process::Command;
use std::time::Instant;

use semismooth::{Factorize, GeneralizedJacobian, LinearSolve, Residual};
use semismooth_contact::hb::{CondensedSolve, HbOptions, SsnHb};
use semismooth_contact::settings::{LinearSolverChoice, SolverSettings};
use semismooth_contact::solve::{solve, structured_solver};
use semismooth_contact::structures::{BladedDisk, DiskLoading, SHIPPED_MISTUNING};

struct Args {
    solver: String,
    harmonics: usize,
    blades: usize,
    counts: Vec<usize>,
    child: bool,
}

fn parse() -> Args {
    let mut args = Args {
        solver: "auto".into(),
        harmonics: 20,
        blades: 3334,
        counts: Vec::new(),
        child: false,
    };
    let mut it = std::env::args().skip(1);
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().unwrap_or_else(|| panic!("{name} needs a value"));
        match a.as_str() {
            "--solver" => args.solver = value("--solver"),
            "--harmonics" => args.harmonics = value("--harmonics").parse().expect("H"),
            "--blades" => args.blades = value("--blades").parse().expect("B"),
            "--child" => args.child = true,
            n => args
                .counts
                .push(n.parse().expect("COUNTS: positive integers")),
        }
    }
    if args.counts.is_empty() {
        args.counts = vec![10, 100, 1000];
    }
    args
}

fn peak_rss_kb() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find_map(|l| l.strip_prefix("VmHWM:"))
                .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        })
        .unwrap_or(0)
}

/// One count in this process: prints one tab-separated line.
fn run_one(args: &Args, count: usize) {
    let (choice, condensed) = match args.solver.as_str() {
        "dense" => (LinearSolverChoice::CondensedDense, CondensedSolve::Dense),
        "krylov" => (LinearSolverChoice::CondensedKrylov, CondensedSolve::Krylov),
        _ => (LinearSolverChoice::Structured, CondensedSolve::Auto),
    };
    let disk = BladedDisk {
        blades: args.blades,
        mistuning: SHIPPED_MISTUNING,
    };
    let stops = (0..count).map(|i| i * args.blades / count).collect();
    let loading = DiskLoading::shipped(stops);
    let structure = disk.structure(&loading).expect("valid disk");
    let omega = loading.omega(structure.omega_1);
    let settings = SolverSettings {
        linear_solver: choice,
        ..SolverSettings::with_harmonics(args.harmonics)
    };
    let solution = solve(&structure, omega, &settings, None).expect("a run");
    if std::env::var_os("SCALING_HISTORY").is_some() {
        eprintln!(
            "{:?} {:?} {:?}",
            solution.strategy, solution.attempts, solution.residual_history
        );
    }
    // One Newton iteration at the converged active set, timed alone.
    let options = HbOptions {
        harmonics: settings.harmonics,
        time_samples: Some(settings.time_samples),
        c: settings.c,
    };
    let mut problem = SsnHb::new(&structure.model, omega, &options).expect("valid problem");
    let x = &solution.state;
    let mut rhs = vec![0.0; problem.dim()];
    let mut jac = problem.new_jacobian();
    let mut solver = structured_solver(condensed, settings.tolerance);
    // The frequency's factorizations (once per frequency) outside the iteration's time.
    problem.jacobian(x, &mut jac).expect("jacobian");
    solver.factor(&jac).expect("factor");
    let gmres_before = solver.krylov_iterations();
    let start = Instant::now();
    problem.residual(x, &mut rhs).expect("residual");
    // A right-hand side of the size of a step from zero: F at the solution is ~0.
    for (i, r) in rhs.iter_mut().enumerate() {
        *r += 1e-3 * ((i as f64) * 0.7).sin();
    }
    problem.jacobian(x, &mut jac).expect("jacobian");
    solver.factor(&jac).expect("factor");
    let step = solver.solve_in_place(&mut rhs);
    let iteration = start.elapsed().as_secs_f64();
    println!(
        "{count}\t{}\t{}\t{}\t{:.3}\t{:.4}\t{}\t{}\t{:.6e}\t{}",
        structure.model.dofs(),
        count * (2 * args.harmonics + 1),
        if solver.is_matrix_free() {
            "krylov"
        } else {
            "dense"
        },
        solution.solve_seconds,
        iteration,
        solution.iterations,
        if step.is_ok() {
            (solver.krylov_iterations() - gmres_before).to_string()
        } else {
            format!("{step:?}")
        },
        solution.stats.max,
        if solution.converged() {
            peak_rss_kb().to_string()
        } else {
            format!(
                "{} (not converged: {})",
                peak_rss_kb(),
                solution.termination
            )
        },
    );
}

fn main() {
    let args = parse();
    if args.child {
        for &count in &args.counts {
            run_one(&args, count);
        }
        return;
    }
    println!(
        "bladed disk, {} blades ({} dofs), H = {}, solver {}",
        args.blades,
        3 * args.blades,
        args.harmonics,
        args.solver
    );
    println!(
        "| contacts | condensed unknowns | path | solve (s) | one iteration (s) | Newton iterations | GMRES iterations in the one iteration | observed max | peak RSS (MB) |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let exe = std::env::current_exe().expect("own path");
    for &count in &args.counts {
        let out = Command::new(&exe)
            .args([
                "--child",
                "--solver",
                &args.solver,
                "--harmonics",
                &args.harmonics.to_string(),
                "--blades",
                &args.blades.to_string(),
                &count.to_string(),
            ])
            .stderr(std::process::Stdio::inherit())
            .output()
            .expect("child run");
        let text = String::from_utf8_lossy(&out.stdout);
        let Some(line) = text.lines().next() else {
            println!(
                "| {count} | failed: {} |",
                String::from_utf8_lossy(&out.stderr).trim()
            );
            continue;
        };
        let f: Vec<&str> = line.split('\t').collect();
        let rss = f[9]
            .split_whitespace()
            .next()
            .and_then(|v| v.parse::<f64>().ok())
            .map_or(String::from("?"), |kb| format!("{:.0}", kb / 1000.0));
        let note = f[9].split_once(' ').map_or("", |(_, n)| n);
        println!(
            "| {} | {} | {} | {} | {} | {} | {} | {} | {rss} {note} |",
            f[0], f[2], f[3], f[4], f[5], f[6], f[7], f[8]
        );
    }
}
