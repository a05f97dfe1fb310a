//! `ssn`: periodic vibrations of structures with unilateral contact, from scene files.
//!
//! Without a subcommand it reproduces the paper's figures into `./out/`.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use semismooth_problems::cli::{self, CliError, RunArgs};
use semismooth_problems::figures;

const EXIT_CODES: &str = "\
Examples:
  ssn                                         reproduce the paper's figures into ./out/
  ssn solve problems/scenes/paper_fig1_modified_mass.toml --json
  ssn sweep problems/scenes/paper_fig2.toml --csv fig2.csv --svg fig2.svg
  ssn compare problems/scenes/paper_fig1_modified_mass.toml --out out/compare
  ssn scene-check problems/scenes/two_contacts.toml
  ssn export-model problems/scenes/paper_fig1.toml out/rod   (matrices and a [model] scene)

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
        converged, termination, iterations, residual_norm, effective_tolerance,\n  \
        solve_seconds, tip_max, tip_min,\n  \
        max_penetration, contact_force_mean, c (SSN-HB), counters {residual_evaluations,\n  \
        jacobian_evaluations, factorizations, linear_solves, ffts, ...}\n\n"
    )]
    Solve(RunArgs),
    /// Follow the response in frequency (pseudo-arclength continuation) over the scene's
    /// [sweep] range.
    #[command(
        after_help = "Examples:\n  ssn sweep problems/scenes/paper_fig2.toml\n  \
        ssn sweep problems/scenes/paper_fig2.toml --json --csv fig2.csv --svg fig2.svg\n\n\
        JSON fields: points, omega, tip_max, tip_min, amplitude (arrays in branch order),\n  \
        folds (omega where the branch turns), converged, termination, solve_seconds, counters\n\n",
        mut_arg("scene", |a| a.help("Scene file (TOML) with a [sweep] section")),
        mut_arg("json", |a| a.help("Print the branch as JSON on stdout")),
        mut_arg("csv", |a| a.help("Write the branch as CSV")),
        mut_arg("svg", |a| a.help("Write the frequency response as SVG"))
    )]
    Sweep(RunArgs),
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
    /// Write a scene's structure as Matrix Market files (M, K, D, f) and a [model] scene
    /// that solves the same problem.
    #[command(
        after_help = "Example:\n  ssn export-model problems/scenes/paper_fig1_modified_mass.toml out/rod\n  \
        ssn solve out/rod/scene.toml\n\n"
    )]
    ExportModel {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Directory to write M.mtx, K.mtx, D.mtx (when damped), f.mtx and scene.toml into.
        dir: PathBuf,
    },
    /// Validate a scene and print the resolved model (natural frequencies, effects present).
    #[command(after_help = "Example:\n  ssn scene-check problems/scenes/two_contacts.toml\n\n")]
    SceneCheck {
        /// Scene file (TOML).
        scene: PathBuf,
    },
}

fn main() -> ExitCode {
    let args = Cli::parse();
    let result = match &args.command {
        None => figures::default_run(&args.out, args.quiet),
        Some(Command::SceneCheck { scene }) => cli::scene_check(scene),
        Some(Command::ExportModel { scene, dir }) => cli::export_model(scene, dir),
        Some(Command::Solve(run)) => cli::solve(run, args.quiet),
        Some(Command::Sweep(run)) => cli::sweep(run, args.quiet),
        Some(Command::Compare { scene, accuracy }) => {
            cli::compare(scene, &args.out, *accuracy, args.quiet)
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::NotConverged) => ExitCode::from(1),
        Err(CliError::BadInput(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(2)
        }
        Err(CliError::Output(m)) => {
            eprintln!("error: {m}");
            ExitCode::from(3)
        }
    }
}
