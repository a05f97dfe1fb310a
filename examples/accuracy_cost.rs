//! Accuracy versus cost of every method on the canonical rod with the modified mass
//! (massless contact node), or on a scene given as the first argument: the table, the
//! cheapest setting of each method for 1e-3 and 1e-4 relative accuracy on the tip minimum,
//! and `accuracy_cost.csv` / `accuracy_cost.svg` in `out/accuracy_cost/`.
//!
//! `cargo run --release --example accuracy_cost [SCENE.toml]`

use std::path::PathBuf;

use semismooth_problems::figures::default_settings;
use semismooth_problems::output::prepare_directory;
use semismooth_problems::rod::{build_rod, MassModel, RodSpec};
use semismooth_problems::scene::Scene;
use semismooth_problems::study::accuracy_cost;

fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    faer::set_global_parallelism(faer::Par::Seq);
    let (spec, base) = match std::env::args().nth(1) {
        Some(path) => {
            let scene = Scene::from_path(&path)?;
            (scene.rod, scene.solver)
        }
        None => (
            RodSpec {
                mass: MassModel::Modified,
                ..RodSpec::canonical()
            },
            default_settings(20),
        ),
    };
    let rod = build_rod(&spec)?;
    let progress = |s: &str| eprintln!("  {s}");
    let study = accuracy_cost(&rod, &base, Some(&progress))?;
    println!("{}", study.table());
    for accuracy in [1e-3, 1e-4] {
        println!("cheapest setting for {accuracy:.0e} on the tip minimum:");
        print!("{}", study.cheapest_table(accuracy));
    }
    let out = PathBuf::from("out/accuracy_cost");
    prepare_directory(&out)?;
    study.write_files(&out)?;
    println!(
        "\nWrote {0}/accuracy_cost.csv and {0}/accuracy_cost.svg",
        out.display()
    );
    Ok(())
}
