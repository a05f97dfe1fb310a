//! Solving from zero: every point of a grid of rods, forcings, gaps and frequencies solved
//! from the zero initial guess with the scene defaults, and the hard cases beside it (a
//! fine rod at high H, the undamped rod at resonance, many contact points, the periodic
//! LCP over its time grids).
//!
//! Prints, per group: points, points converged, the worst and median Newton iteration
//! counts, the line-search backtracks, the strategies that succeeded, and the wall time.
//!
//! ```sh
//! cargo run --release --example from_zero            # everything (about a minute)
//! cargo run --release --example from_zero -- grid    # only the grid
//! cargo run --release --example from_zero -- grid hybrid   # with another globalization
//! cargo run --release --example from_zero -- hard auto "H = 80,undamped"  # some groups
//! ```
//!
//! The second argument names the globalization as a scene does (`auto`, the default;
//! `hybrid`, the default before the polyalgorithm; `none`, `armijo`, `nonmonotone`); the
//! third keeps the groups whose name contains one of its comma-separated parts. Points that
//! fail or take more than 60 iterations are listed with their attempts.

use std::time::Instant;

use semismooth_problems::from_zero::{hard_cases, public_grid, GridCase};
use semismooth_problems::runner::solve_rod;
use semismooth_problems::scene::GlobalizationChoice;

fn main() {
    let only = std::env::args().nth(1).filter(|o| o != "all");
    let globalization = match std::env::args().nth(2).as_deref() {
        None | Some("auto") => GlobalizationChoice::Auto,
        Some("hybrid") => GlobalizationChoice::Hybrid,
        Some("none") => GlobalizationChoice::None,
        Some("armijo") => GlobalizationChoice::Armijo,
        Some("nonmonotone") => GlobalizationChoice::Nonmonotone,
        Some(other) => {
            eprintln!("unknown globalization {other:?}: auto, hybrid, none, armijo, nonmonotone");
            std::process::exit(2);
        }
    };
    let mut groups: Vec<(String, Vec<GridCase>)> = Vec::new();
    if only.as_deref().is_none_or(|o| o == "grid") {
        groups.extend(public_grid(&[0.1, 0.2, 0.4]).expect("grid rods build"));
    }
    if only.as_deref().is_none_or(|o| o == "hard") {
        groups.extend(hard_cases().expect("hard-case rods build"));
    }
    println!(
        "{:<44} {:>6} {:>9} {:>6} {:>7} {:>10} {:>8}  strategies",
        "group", "points", "converged", "worst", "median", "backtracks", "seconds"
    );
    let filter = std::env::args().nth(3);
    for (name, cases) in groups {
        if filter
            .as_deref()
            .is_some_and(|f| !f.split(',').any(|p| name.contains(p)))
        {
            continue;
        }
        let start = Instant::now();
        let mut converged = 0;
        let mut iterations = Vec::new();
        let mut backtracks = 0;
        let mut strategies: Vec<(String, usize)> = Vec::new();
        let mut failures = Vec::new();
        for case in &cases {
            let mut settings = case.solver_settings();
            settings.globalization = globalization;
            match solve_rod(&case.rod, &settings, None) {
                Ok(sol) => {
                    backtracks += sol.counters.line_search_backtracks;
                    if !sol.converged || sol.iterations > 60 {
                        println!("    {} ({} iterations):", case.label, sol.iterations);
                        for a in &sol.attempts {
                            println!(
                                "        {} {} {}",
                                a.strategy.name(),
                                a.iterations,
                                a.outcome
                            );
                        }
                    }
                    if sol.converged {
                        converged += 1;
                        iterations.push(sol.iterations);
                    } else {
                        failures.push(format!("{} ({})", case.label, sol.termination));
                    }
                    let s = if sol.converged {
                        sol.strategy.unwrap_or("-").to_string()
                    } else {
                        "failed".to_string()
                    };
                    match strategies.iter_mut().find(|(k, _)| *k == s) {
                        Some((_, n)) => *n += 1,
                        None => strategies.push((s, 1)),
                    }
                }
                Err(e) => failures.push(format!("{}: {e}", case.label)),
            }
        }
        iterations.sort_unstable();
        let worst = iterations.last().copied().unwrap_or(0);
        let median = iterations.get(iterations.len() / 2).copied().unwrap_or(0);
        let strategies: Vec<String> = strategies
            .iter()
            .map(|(s, n)| format!("{s}: {n}"))
            .collect();
        println!(
            "{:<44} {:>6} {:>9} {:>6} {:>7} {:>10} {:>8.2}  {}",
            name,
            cases.len(),
            converged,
            worst,
            median,
            backtracks,
            start.elapsed().as_secs_f64(),
            strategies.join(", ")
        );
        for f in failures.iter().take(4) {
            println!("    not converged: {f}");
        }
        if failures.len() > 4 {
            println!("    ... and {} more", failures.len() - 4);
        }
    }
}
