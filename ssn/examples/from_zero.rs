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
//! `hybrid`: full steps, then the line search from the initial guess; `none`, `armijo`,
//! `nonmonotone`); the third keeps the groups whose name contains one of its comma-separated parts. Points that
//! fail or take more than 60 iterations are listed with their attempts.

use semismooth_contact::from_zero::{hard_cases, public_grid};
use ssn::scene::GlobalizationChoice;
use ssn::tables::solve_group;

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
    let mut groups = Vec::new();
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
        let g = solve_group(&name, &cases, globalization);
        for d in &g.details {
            println!("    {}", d.replace('\n', "\n    "));
        }
        println!(
            "{:<44} {:>6} {:>9} {:>6} {:>7} {:>10} {:>8.2}  {}",
            g.name,
            g.points,
            g.converged,
            g.worst,
            g.median,
            g.backtracks,
            g.seconds,
            g.strategies_text()
        );
        for f in g.failures.iter().take(4) {
            println!("    not converged: {f}");
        }
        if g.failures.len() > 4 {
            println!("    ... and {} more", g.failures.len() - 4);
        }
    }
}
