//! Every measured table of the README, computed and printed as markdown in the README's
//! format, section by section (the functions are in `ssn::tables`).
//!
//! ```sh
//! cargo run --release --example readme_tables                 # every section (minutes: hard)
//! cargo run --release --example readme_tables -- methods sweeps
//! ```
//!
//! Sections: `methods` (method comparison, both mass models, about 3 s), `accuracy`
//! (cheapest setting per method, about 5 s), `sweeps` (about 10 s), `from-zero` (the public
//! grid with `auto` and `hybrid`, about 6 s), `performance` (what the examples time, about
//! 2 s), `hard` (the hard cases from zero, about 2 minutes, most of it the 100-contact rod).
//! Wall times vary with the machine and its load; every other cell is deterministic, and
//! `tests/readme_tables.rs` checks those of the cheap tables against README.md.

use semismooth_contact::from_zero::{hard_cases, public_grid};
use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use ssn::scene::{GlobalizationChoice, SolverSettings};
use ssn::study::accuracy_cost;
use ssn::tables;

const SECTIONS: [&str; 6] = [
    "methods",
    "accuracy",
    "sweeps",
    "from-zero",
    "performance",
    "hard",
];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    faer::set_global_parallelism(faer::Par::Seq);
    let asked: Vec<String> = std::env::args().skip(1).collect();
    if let Some(bad) = asked.iter().find(|a| !SECTIONS.contains(&a.as_str())) {
        return Err(format!("unknown section {bad:?}: one of {}", SECTIONS.join(", ")).into());
    }
    let wanted = |s: &str| asked.is_empty() || asked.iter().any(|a| a == s);
    let command = |s: &str| {
        println!("\n## {s}\n\n`cargo run --release --example readme_tables -- {s}`\n");
    };
    if wanted("methods") {
        command("methods");
        for mass in [MassModel::Modified, MassModel::Consistent] {
            println!("\n{mass:?} mass:\n");
            print!("{}", tables::method_comparison(mass)?.0.markdown());
        }
    }
    if wanted("accuracy") {
        command("accuracy");
        let rod = build_rod(&RodSpec {
            mass: MassModel::Modified,
            ..RodSpec::canonical()
        })?;
        let settings = SolverSettings::with_harmonics(20);
        let study = accuracy_cost(&rod.structure, rod.omega(), &settings, None)?;
        print!("{}", tables::cheapest_settings(&study).markdown());
    }
    if wanted("sweeps") {
        command("sweeps");
        print!("{}", tables::sweeps(&tables::sweep_cases())?.markdown());
    }
    if wanted("from-zero") {
        command("from-zero");
        let groups = public_grid(&[0.1, 0.2, 0.4])?;
        let run = |g: GlobalizationChoice| -> Vec<tables::GroupSummary> {
            groups
                .iter()
                .map(|(name, cases)| tables::solve_group(name, cases, g))
                .collect()
        };
        let (auto, hybrid) = (
            run(GlobalizationChoice::Auto),
            run(GlobalizationChoice::Hybrid),
        );
        print!("{}", tables::from_zero_grid(&auto, &hybrid).markdown());
    }
    if wanted("performance") {
        command("performance");
        print!("{}", tables::performance()?.markdown());
    }
    if wanted("hard") {
        command("hard");
        let groups: Vec<tables::GroupSummary> = hard_cases()?
            .iter()
            .map(|(name, cases)| tables::solve_group(name, cases, GlobalizationChoice::Auto))
            .collect();
        print!("{}", tables::from_zero_hard(&groups).markdown());
    }
    Ok(())
}
