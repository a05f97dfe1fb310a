//! `ssn`: periodic vibrations of structures with unilateral contact, from scene files.
//!
//! Without a subcommand it reproduces the paper's figures into `./out/`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use semismooth_problems::rod::{build_rod, natural_frequencies};
use semismooth_problems::scene::Scene;

const EXIT_CODES: &str = "\
Examples:
  ssn                                         reproduce the paper's figures into ./out/
  ssn solve problems/scenes/paper_fig1_modified_mass.toml --json
  ssn sweep problems/scenes/paper_fig2.toml --csv fig2.csv --svg fig2.svg
  ssn compare problems/scenes/paper_fig1_modified_mass.toml --out out/compare
  ssn scene-check problems/scenes/two_contacts.toml

Exit codes:
  0  converged (or, for scene-check, a valid scene)
  1  the solver ran but did not converge (its JSON is still printed, with converged = false)
  2  bad input (scene file, option): the message names the file, the key and what is allowed
  3  an output file or directory could not be written (nothing half-written is left)";

#[derive(Parser, Debug)]
#[command(
    name = "ssn",
    version,
    about = "Periodic vibrations of structures with unilateral contact (semismooth Newton \
             harmonic balance, penalty HB, periodic LCP, time marching)",
    long_about = "Periodic vibrations of structures with unilateral contact.\n\n\
        Without a subcommand, reproduces the paper's Fig. 1 (tip displacement over a period, \
        H = 10/15/20 against the time-marching reference) and Fig. 2 (frequency responses \
        for gaps 0.25/0.5/0.75 and the linear rod), writing SVG and CSV files to ./out/.",
    after_help = EXIT_CODES
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Output directory of the default run.
    #[arg(long, default_value = "out", global = true)]
    out: PathBuf,
    /// No progress display.
    #[arg(long, short, global = true)]
    quiet: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Solve one periodic response at the scene's forcing frequency.
    #[command(
        after_help = "Examples:\n  ssn solve problems/scenes/paper_fig1_modified_mass.toml\n  \
        ssn solve problems/scenes/paper_fig1.toml --json --csv tip.csv --svg tip.svg\n\n\
        JSON fields: scene, method, harmonics (HB only), time_samples, omega, omega_ratio,\n  \
        converged, termination, iterations, residual_norm, solve_seconds, tip_max, tip_min,\n  \
        max_penetration, contact_force_mean, c (SSN-HB), counters {residual_evaluations,\n  \
        jacobian_evaluations, factorizations, linear_solves, ffts, ...}\n\n"
    )]
    Solve {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Print the result as JSON on stdout.
        #[arg(long)]
        json: bool,
        /// Write the tip displacement and contact force over one period as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Write a plot of the tip displacement over one period as SVG.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// Follow the response in frequency (pseudo-arclength continuation) over the scene's
    /// [sweep] range.
    #[command(
        after_help = "Examples:\n  ssn sweep problems/scenes/paper_fig2.toml\n  \
        ssn sweep problems/scenes/paper_fig2.toml --json --csv fig2.csv --svg fig2.svg\n\n\
        JSON fields: points, omega, tip_max, tip_min, amplitude (arrays in branch order),\n  \
        folds (omega where the branch turns), converged, termination, solve_seconds, counters\n\n"
    )]
    Sweep {
        /// Scene file (TOML) with a [sweep] section.
        scene: PathBuf,
        /// Print the branch as JSON on stdout.
        #[arg(long)]
        json: bool,
        /// Write the branch as CSV.
        #[arg(long)]
        csv: Option<PathBuf>,
        /// Write the frequency response as SVG.
        #[arg(long)]
        svg: Option<PathBuf>,
    },
    /// Accuracy against cost: every method over its discretisation settings, error against a
    /// converged reference versus wall time (table, CSV and a log-log SVG in --out).
    #[command(
        after_help = "Example:\n  ssn compare problems/scenes/paper_fig1_modified_mass.toml --out out/compare\n\n"
    )]
    Compare {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Requested relative accuracy on the tip minimum: the cheapest setting of each
        /// method reaching it is reported.
        #[arg(long, default_value_t = 1e-3)]
        accuracy: f64,
    },
    /// Validate a scene and print the resolved model (natural frequencies, effects present).
    #[command(after_help = "Example:\n  ssn scene-check problems/scenes/two_contacts.toml\n\n")]
    SceneCheck {
        /// Scene file (TOML).
        scene: PathBuf,
    },
}

/// Outcome of a command, mapped onto the documented exit codes.
enum Failure {
    NotConverged,
    BadInput(String),
    Output(String),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        None => semismooth_problems::cli::default_run(&cli.out, cli.quiet).map(|_| ()),
        Some(Command::SceneCheck { scene }) => scene_check(scene),
        Some(Command::Solve {
            scene,
            json,
            csv,
            svg,
        }) => {
            semismooth_problems::cli::solve(scene, *json, csv.as_deref(), svg.as_deref(), cli.quiet)
        }
        Some(Command::Sweep {
            scene,
            json,
            csv,
            svg,
        }) => {
            semismooth_problems::cli::sweep(scene, *json, csv.as_deref(), svg.as_deref(), cli.quiet)
        }
        Some(Command::Compare { scene, accuracy }) => {
            semismooth_problems::cli::compare(scene, &cli.out, *accuracy, cli.quiet)
        }
    }
    .map_err(|e| match e {
        semismooth_problems::cli::CliError::NotConverged => Failure::NotConverged,
        semismooth_problems::cli::CliError::BadInput(m) => Failure::BadInput(m),
        semismooth_problems::cli::CliError::Output(m) => Failure::Output(m),
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::NotConverged) => ExitCode::from(1),
        Err(Failure::BadInput(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(2)
        }
        Err(Failure::Output(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(3)
        }
    }
}

fn scene_check(path: &std::path::Path) -> Result<(), semismooth_problems::cli::CliError> {
    use semismooth_problems::cli::CliError;
    let scene = Scene::from_path(path).map_err(|e| CliError::BadInput(e.to_string()))?;
    let rod = build_rod(&scene.rod)
        .map_err(|e| CliError::BadInput(format!("{}: {e}", path.display())))?;
    // Up to five modes; massless dofs have none (a modified-mass rod has one fewer).
    let modes = match natural_frequencies(&rod.model, 5.min(rod.model.dofs())) {
        Err(semismooth_problems::rod::ModelError::TooManyModes { available, .. }) => {
            natural_frequencies(&rod.model, available)
        }
        other => other,
    }
    .map_err(|e| CliError::BadInput(format!("{}: {e}", path.display())))?;
    print!(
        "{}",
        semismooth_problems::cli::describe(&scene, &rod, &modes)
    );
    Ok(())
}
