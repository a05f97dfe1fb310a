//! Accuracy versus cost of every method on the canonical rod with the modified mass
//! (massless contact node), or on a scene given as the first argument: the table, the
//! cheapest setting of each method for 1e-3 and 1e-4 relative accuracy on the tip minimum,
//! and `accuracy_cost.csv` / `accuracy_cost.svg` in `out/accuracy_cost/`.
//!
//! `cargo run --release --example accuracy_cost [SCENE.toml]`

mod common;

use std::path::PathBuf;

use semismooth_contact::rod::{build_rod, MassModel, RodSpec};
use semismooth_contact::settings::SolverSettings;
use ssn::accuracy_cost::accuracy_cost;
use ssn::output::prepare_directory;

fn main() -> std::process::ExitCode {
    common::exit_code(run())
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    faer::set_global_parallelism(faer::Par::Seq);
    let (rod, omega, base) = match std::env::args().nth(1) {
        // A rod or a [model] scene, as `ssn compare` reads it.
        Some(path) => {
            use ssn::cli::{load, CliError, Loaded};
            let Loaded {
                scene,
                structure,
                omega,
            } = load(path.as_ref()).map_err(|e: CliError| e.to_string())?;
            (structure, omega, scene.solver)
        }
        None => {
            let spec = RodSpec {
                mass: MassModel::Modified,
                ..RodSpec::canonical()
            };
            let rod = build_rod(&spec)?;
            let omega = rod.omega();
            (rod.structure, omega, SolverSettings::with_harmonics(20))
        }
    };
    let progress = |s: &str| eprintln!("  {s}");
    let study = accuracy_cost(&rod, omega, &base, Some(&progress))?;
    println!("{}", study.table());
    for accuracy in [1e-3, 1e-4] {
        println!("cheapest setting for {accuracy:.0e} on the tip minimum:");
        print!("{}", study.cheapest_table(accuracy));
    }
    // The table of `docs/accuracy-cost.md` (`ms`: wall time of one cold solve, the problem already built).
    print!("\n{}", ssn::tables::cheapest_settings(&study).markdown());
    let out = PathBuf::from("out/accuracy_cost");
    prepare_directory(&out)?;
    study.write_files(&out)?;
    println!(
        "\nWrote {0}/accuracy_cost.csv and {0}/accuracy_cost.svg",
        out.display()
    );
    Ok(())
}
