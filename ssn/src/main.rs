//! `ssn`: periodic vibrations of structures with unilateral contact, from scene files.
//!
//! Without a subcommand it reproduces the paper's figures into `./out/`.

use std::path::{Path, PathBuf};
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use ssn::cli::{self, CliError, RunArgs, SweepArgs};
use ssn::{figures, io};

const EXIT_CODES: &str = "\
Examples:
  ssn                                         reproduce the paper's figures into ./out/
  ssn solve scenes/paper_fig1_modified_mass.toml --json
  ssn sweep scenes/paper_fig2.toml --csv fig2.csv --svg fig2.svg
  ssn compare scenes/paper_fig1_modified_mass.toml --out out/compare
  ssn scene-check scenes/two_contacts.toml
  ssn export-model scenes/paper_fig1.toml out/rod   (matrices and a [model] scene)

Exit codes:
  0  converged (or, for scene-check, a valid scene)
  1  the solver ran but did not converge (its JSON is still printed, with converged = false)
  2  bad input (scene file, option): the message names the file, the key and what is allowed
  3  an output file or directory could not be written (nothing half-written is left)

Limits (a run beyond either is refused up front with exit code 2, naming the keys to reduce):
  SSN_WORK_LIMIT    operations a run may take, default 1e12 (about 43 s on a 2-core machine
                    at 2.3e10 per second); SSN_WORK_LIMIT=1 shows any run's estimate unrun
  SSN_MEMORY_LIMIT  bytes a run may use, default the memory available (MemAvailable)";

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
    /// Output directory of the default run [default: out] (`ssn compare` takes its own
    /// --out; the other commands write the files named by --csv, --svg and --state).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Nothing on stdout or stderr but errors (no progress, no text summary; `--json` is
    /// still printed).
    #[arg(long, short, global = true)]
    quiet: bool,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Solve one periodic response at the scene's forcing frequency.
    #[command(
        after_help = "Examples:\n  ssn solve scenes/paper_fig1_modified_mass.toml\n  \
        ssn solve scenes/paper_fig1.toml --json --csv tip.csv --svg tip.svg\n  \
        ssn solve SCENE.toml --state state.json     (write the harmonic coefficients)\n  \
        ssn solve SCENE.toml --start state.json     (Newton from them)\n  \
        ssn solve SCENE.toml --start solutions.json --entry 2   (from ssn solutions --json)\n\n\
        JSON fields: scene, method, harmonics (HB only), time_samples, lcp_scheme (LCP\n  \
        only), omega, omega_ratio, converged, termination, diagnosis (when known),\n  \
        iterations, residual_norm, effective_tolerance, strategy and attempts (Newton\n  \
        methods), solve_seconds, tip_max, tip_min,\n  \
        max_penetration, contact_force_mean (sum over the contacts), contacts [{node, dof,\n  \
        gap, force_mean, max_penetration, contact_fraction, displacement_min,\n  \
        displacement_max}], friction [{point, stick_fraction, force_amplitude,\n  \
        slip_velocity_amplitude, slip_limit_max, force, slip_velocity}], c (SSN-HB),\n  \
        counters {residual_evaluations,\n  \
        jacobian_evaluations, factorizations, linear_solves, ffts, krylov_iterations,\n  \
        ...}, started_from\n  \
        {file, entry, omega_ratio, note} (with --start)\n\n\
        State file (--state): format, version, method, harmonics, dofs, contacts, omega,\n  \
        omega_ratio, layout, displacement [(2H+1) dofs], contact_force [(2H+1) contacts]\n  \
        (ssn-hb), converged, residual_norm\n\n"
    )]
    Solve(cli::SolveArgs),
    /// Follow the response in frequency (pseudo-arclength continuation) over the scene's
    /// [sweep] range.
    #[command(
        after_help = "Examples:\n  ssn sweep scenes/paper_fig2.toml\n  \
        ssn sweep scenes/paper_fig2.toml --json --csv fig2.csv --svg fig2.svg\n\n\
        JSON fields: points, omega, omega_ratio, tip_max, tip_min, amplitude, stable,\n  \
        floquet_max_abs, contact_force_mean (sum over the contacts), max_penetration,\n  \
        contacts (per point, the list of ssn solve), friction (per point: point,\n  \
        stick_fraction, force_amplitude, slip_velocity_amplitude, slip_limit_max),\n  \
        frictional_contacts (per point, per 3-D contact: point, max_normal_force,\n  \
        max_tangential_force, dissipated_energy, stick_fraction, slip_fraction,\n  \
        separated_fraction) (arrays in branch order),\n  \
        stability_note, events [{kind, omega, omega_ratio, index}], folds (omega where the\n  \
        branch turns), corner_folds (reversals of less than 5e-3 omega_1: corners),\n  \
        converged, termination, solve_seconds, counters\n\n\
        CSV: one row per point; contact k (from 0) adds contact{k}_force_mean,\n  \
        contact{k}_max_penetration, contact{k}_contact_fraction, contact{k}_displacement_min,\n  \
        contact{k}_displacement_max; 3-D contact p (from 1) adds\n  \
        contact3d_{p}_max_normal_force, _max_tangential_force, _dissipated_energy,\n  \
        _stick_fraction, _slip_fraction, _separated_fraction\n\n",
        mut_arg("scene", |a| a.help("Scene file (TOML) with a [sweep] section")),
        mut_arg("json", |a| a.help("Print the branch as JSON on stdout")),
        mut_arg("csv", |a| a.help("Write the branch as CSV")),
        mut_arg("svg", |a| a.help("Write the frequency response as SVG"))
    )]
    Sweep(SweepArgs),
    /// Every periodic solution at the scene's forcing frequency, with its stability (follows
    /// the branch through the frequency and corrects each crossing there).
    #[command(
        after_help = "Example:\n  ssn solutions SCENE.toml --json --csv solutions.csv --svg solutions.svg\n\n\
        JSON fields: omega, omega_ratio, window, branch_points, branch_converged, crossings,\n  \
        failed_corrections, seconds, solutions [{tip_min, tip_max, contact_force_mean,\n  \
        max_penetration, contacts, friction, stable, floquet_max_abs, stability_note,\n  \
        iterations,\n  \
        residual_norm, state}]; start a solve from solution K with\n  \
        ssn solve SCENE.toml --start solutions.json --entry K\n\n",
        mut_arg("json", |a| a.help("Print the solutions as JSON on stdout")),
        mut_arg("csv", |a| a.help("Write one CSV row per solution")),
        mut_arg("svg", |a| a.help("Write the tip over one period of every solution as SVG"))
    )]
    Solutions(RunArgs),
    /// The backbone of a nonlinear mode (EPMC on SSN-HB): frequency, damping ratio and
    /// energy against the observed dof's amplitude over the scene's [modes] range.
    #[command(
        after_help = "Example:\n  ssn modes SCENE.toml --json --csv backbone.csv --svg backbone.svg\n\n\
        Scene: [modes] mode (default 1), amplitude_from and amplitude_to, or energy_from\n  \
        and energy_to, max_points; solver.method ssn-hb (others are refused).\n\n\
        JSON fields: scene, mode, linear {omega, damping_ratio}, observed_dof, harmonics,\n  \
        damping_convention, amplitude_measure, points [{amplitude, energy, omega,\n  \
        omega_ratio, damping_ratio, modal_damping, displacement_max, displacement_min,\n  \
        max_penetration, contacts [{force_mean}]}], folds, converged, termination,\n  \
        solve_seconds\n\n",
        mut_arg("json", |a| a.help("Print the backbone as JSON on stdout")),
        mut_arg("csv", |a| a.help("Write one CSV row per backbone point")),
        mut_arg("svg", |a| a.help("Write the frequency and damping against the amplitude as SVG"))
    )]
    Modes(RunArgs),
    /// Accuracy against cost: every method over its discretisation settings, error against a
    /// converged reference versus wall time (table, CSV and a log-log SVG in --out).
    #[command(
        after_help = "Example:\n  ssn compare scenes/paper_fig1_modified_mass.toml --out out/compare\n\n"
    )]
    Compare {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Requested relative accuracy on the tip minimum: the cheapest setting of each
        /// method reaching it is reported.
        #[arg(long, default_value_t = 1e-3)]
        accuracy: f64,
        /// Output directory of the table, CSV and SVG [default: out].
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run a study: a scene and what varies (a grid of scene keys, a list of cases, seeded
    /// random samples), each case a solve, sweep or solutions run, on every core; one row
    /// per case in DIR/results.csv (and .parquet), each case's JSON in DIR/cases/.
    #[command(
        after_help = "Examples:\n  ssn study scenes/paper_fig2.toml GAPS.toml --out out/gaps\n  \
        ssn study SCENE.toml STUDY.toml --out DIR --shard 3/8   (one task of a job array)\n  \
        ssn study merge DIR                                       (when every shard is done)\n\n\
        A run into a directory that holds records of the same study skips the cases done.\n\
        Exit code 1 when some case did not converge (the table is written all the same).\n\n"
    )]
    Study(ssn::study::command::StudyArgs),
    /// Write a scene's structure as Matrix Market files (M, K, D, f) and a [model] scene
    /// that solves the same problem.
    #[command(
        after_help = "Example:\n  ssn export-model scenes/paper_fig1_modified_mass.toml out/rod\n  \
        ssn solve out/rod/scene.toml\n\n"
    )]
    ExportModel {
        /// Scene file (TOML).
        scene: PathBuf,
        /// Directory to write M.mtx, K.mtx, D.mtx (when damped), f.mtx and scene.toml into.
        dir: PathBuf,
    },
    /// Validate a scene and print the resolved model (natural frequencies, effects present).
    #[command(after_help = "Example:\n  ssn scene-check scenes/two_contacts.toml\n\n")]
    SceneCheck {
        /// Scene file (TOML).
        scene: PathBuf,
    },
}

fn main() -> ExitCode {
    io::guard_standard_streams();
    io::remove_on_interrupt();
    let args = match Cli::try_parse() {
        Ok(args) => args,
        Err(e) => return clap_exit(&e),
    };
    io::set_quiet(args.quiet);
    let default_out = || PathBuf::from("out");
    let result = match &args.command {
        None => {
            let out = args.out.clone().unwrap_or_else(default_out);
            in_new_directory(&out, || io::all_or_nothing(|| figures::default_run(&out)))
        }
        // `ssn --out DIR compare SCENE` and `ssn compare SCENE --out DIR` both work.
        Some(Command::Compare {
            scene,
            accuracy,
            out,
        }) => {
            let out = out.clone().or(args.out.clone()).unwrap_or_else(default_out);
            in_new_directory(&out, || {
                io::all_or_nothing(|| cli::compare(scene, &out, *accuracy))
            })
        }
        Some(command) if args.out.is_some() => Err(CliError::BadInput(format!(
            "--out applies only to the default run and `ssn compare`; `ssn {}` writes the \
             files named by --csv and --svg",
            command.name()
        ))),
        Some(Command::SceneCheck { scene }) => cli::scene_check(scene),
        Some(Command::ExportModel { scene, dir }) => {
            in_new_directory(dir, || cli::export_model(scene, dir))
        }
        Some(Command::Solve(solve)) => cli::solve(solve),
        Some(Command::Sweep(sweep)) => cli::sweep(sweep),
        Some(Command::Solutions(run)) => ssn::solutions::command(run),
        Some(Command::Modes(run)) => ssn::modes::command(run),
        Some(Command::Study(study)) => ssn::study::command::command(study),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(CliError::NotConverged) => ExitCode::from(1),
        Err(CliError::BadInput(m) | CliError::TooLarge(m)) => {
            io::write_stderr(&format!("error: {}\n", io::printable_message(&m)));
            ExitCode::from(2)
        }
        Err(CliError::Output(m)) => {
            io::write_stderr(&format!("error: {}\n", io::printable_message(&m)));
            ExitCode::from(3)
        }
    }
}

/// Runs `run`, which writes into the directory `out`; when `out` did not exist before and
/// the run fails or is interrupted, the directories it created (from the outermost one
/// that did not exist) are removed with what was written into them, so a failed run
/// leaves nothing behind.
fn in_new_directory(
    out: &Path,
    run: impl FnOnce() -> Result<(), CliError>,
) -> Result<(), CliError> {
    // The outermost ancestor of `out` that does not exist yet (the run creates it).
    let created = out
        .ancestors()
        .filter(|a| !a.as_os_str().is_empty())
        .take_while(|a| std::fs::symlink_metadata(a).is_err())
        .last()
        .map(Path::to_path_buf);
    if let Some(created) = &created {
        io::register_cleanup(created);
    }
    let result = run();
    if let Some(created) = created {
        io::unregister_cleanup(&created);
        if result.is_err() {
            let _ = std::fs::remove_dir_all(created);
        }
    }
    result
}

impl Command {
    fn name(&self) -> &'static str {
        match self {
            Command::Solve(_) => "solve",
            Command::Sweep(_) => "sweep",
            Command::Solutions(_) => "solutions",
            Command::Modes(_) => "modes",
            Command::ExportModel { .. } => "export-model",
            Command::Compare { .. } => "compare",
            Command::SceneCheck { .. } => "scene-check",
            Command::Study(_) => "study",
        }
    }
}

/// Help and version go to standard output (exit code 0, or 3 when it cannot be written);
/// a usage error goes to standard error (exit code 2).
fn clap_exit(e: &clap::Error) -> ExitCode {
    let text = e.render().to_string();
    if e.use_stderr() {
        io::write_stderr(&text);
        ExitCode::from(2)
    } else {
        match io::write_stdout(&text) {
            Ok(()) => ExitCode::SUCCESS,
            Err(err) => {
                io::write_stderr(&format!("error: {err}\n"));
                ExitCode::from(3)
            }
        }
    }
}
