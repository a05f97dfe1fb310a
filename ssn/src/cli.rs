//! The `ssn` command-line program's commands, as library functions (so tests and examples
//! can call them): `solve`, `sweep`, `compare`, `scene-check` and `export-model`, their JSON documents and
//! printed summaries. The default run (the paper's figures) is in [`crate::figures`].
//!
//! Every command maps its failure onto [`CliError`], whose variants are the documented exit
//! codes: 1 when the solver ran and did not converge (its output is still printed), 2 for
//! bad input (the message names the file, the key and what is allowed), 3 when an output
//! could not be written (nothing half-written is left).

use std::fmt::Display;
use std::path::{Path, PathBuf};

use serde_json::{json, Value};

use crate::describe::describe;
pub use crate::exit::CliError;
use crate::io::{printable, write_text, OutputSet};
use crate::output::{
    csv_table, line_plot_svg, prepare_directory, stability_key, stability_series, PlotSpec, Series,
};
use crate::progress::progress_spinner;
use crate::scene::{Override, Scene, SweepSettings};
use crate::state::{read_state, HbState, StateShape};
pub use crate::work::Workload;
use semismooth_contact::import::LANCZOS_MIN_DOFS;
use semismooth_contact::jenkins::expand_tangential_stiffness;
use semismooth_contact::matrix_market::{build_imported, build_imported_with};
use semismooth_contact::model::{StructuralModel, Structure};
use semismooth_contact::reduction::{lowest_frequencies, CraigBampton};
use semismooth_contact::rod::{build_rod, natural_frequencies, ModelError};
use semismooth_contact::solve::{RunError, Solution};
use semismooth_contact::sweep::doubling::PeriodTwoOutcome;
use semismooth_contact::sweep::fold_accuracy::{refine_folds, FoldAccuracy, MAX_FOLD_HARMONICS};
use semismooth_contact::sweep::{FrequencyResponse, SweepProgress};

/// Bad input found in the scene file `path`: the message starts with the file.
fn input_error(path: &Path, e: impl Display) -> CliError {
    CliError::BadInput(format!("{}: {e}", path.display()))
}

/// A run of the scene `path` refused up front: its memory or work estimate is above the
/// limit (the message says by how much and how to lift it).
fn too_large(path: &Path, e: impl Display) -> CliError {
    CliError::TooLarge(format!("{}: {e}", path.display()))
}

/// A scene ready to run: the scene, its structure and its `[forcing]` frequency resolved
/// once against the structure's `omega_1` ([`Scene::omega`]).
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The validated scene.
    pub scene: Scene,
    /// Its structure (no frequency).
    pub structure: Structure,
    /// The forcing frequency every run of the scene takes.
    pub omega: f64,
}

/// Loads a scene and builds its structure (the rod of a `[rod]` scene, the Matrix Market
/// files of a `[model]` scene; `[output] dof` chooses the observed dof), after checking
/// that one run of its method fits in memory ([`crate::limits`]), and resolves its forcing
/// frequency.
pub fn load(path: &Path) -> Result<Loaded, CliError> {
    load_for(path, Workload::Solve)
}

/// [`load`], with the memory and work estimates of the command's `workload` (a branch
/// for `sweep` and `solutions`, several runs for `compare`).
pub fn load_for(path: &Path, workload: Workload) -> Result<Loaded, CliError> {
    load_with(path, &[], workload)
}

/// [`load_for`] with `overrides` (`--set key=value`) applied to the scene before it is
/// validated ([`Scene::from_toml_with`]).
pub fn load_with(
    path: &Path,
    overrides: &[Override],
    workload: Workload,
) -> Result<Loaded, CliError> {
    prepare(scene_with(path, overrides)?, workload, None)
}

/// The scene at `path` with `overrides`; the file's discretisation keys an accuracy
/// override replaced, and sweep bounds replaced by bounds in another unit, are said on
/// standard error (unless `--quiet`).
fn scene_with(path: &Path, overrides: &[Override]) -> Result<Scene, CliError> {
    let (scene, replaced) =
        Scene::from_path_noting(path, overrides).map_err(|e| CliError::BadInput(e.to_string()))?;
    let (sweep, discretisation): (Vec<String>, Vec<String>) =
        replaced.into_iter().partition(|k| k.starts_with("sweep."));
    const CHOSEN: &str = ": the accuracy target chooses the discretisation";
    let notes = [
        (discretisation, "--set solver.accuracy replaces", CHOSEN),
        (sweep, "the sweep bounds set replace", ""),
    ];
    for (keys, what, why) in notes {
        if !keys.is_empty() && !crate::io::quiet() {
            eprintln!("note: {what} the scene's {}{why}", keys.join(", "));
        }
    }
    Ok(scene)
}

pub use crate::scene::MatrixSource;

/// Builds a validated scene's structure as [`load`] does (the memory and work limits of
/// `workload` checked first), reading the `[model]`'s matrices from `matrices` when given,
/// else from their files.
pub fn prepare(
    scene: Scene,
    workload: Workload,
    matrices: Option<MatrixSource>,
) -> Result<Loaded, CliError> {
    prepare_keeping_reduction(scene, workload, matrices).map(|(loaded, _)| loaded)
}

/// [`load_with`], keeping the scene's reduction (its transform recovers the full model's
/// displacement) beside the reduced structure.
pub fn load_keeping_reduction(
    path: &Path,
    overrides: &[Override],
    workload: Workload,
) -> Result<(Loaded, Option<CraigBampton>), CliError> {
    prepare_keeping_reduction(scene_with(path, overrides)?, workload, None)
}

/// [`prepare`], and the scene's reduction when it has one (not for `Workload::Check`).
fn prepare_keeping_reduction(
    mut scene: Scene,
    workload: Workload,
    matrices: Option<MatrixSource>,
) -> Result<(Loaded, Option<CraigBampton>), CliError> {
    let path = scene.path.clone();
    let path = path.as_path();
    let compare = workload == Workload::Compare;
    let solves = !matches!(workload, Workload::Check | Workload::Export);
    let limit = crate::limits::memory_limit().map_err(CliError::BadInput)?;
    let work_limit = crate::limits::work_limit().map_err(CliError::BadInput)?;
    // A rod is estimated before it is built; an imported model once its size is read.
    let rod_need = match solves {
        true => crate::limits::rod_scene_memory(&scene, compare),
        false => {
            (scene.model.is_none()).then(|| crate::limits::model_only_memory(scene.rod.elements))
        }
    };
    if let Some(need) = rod_need {
        crate::limits::check(&need, limit).map_err(|e| too_large(path, e))?;
    }
    if scene.model.is_none() {
        let (n, m) = (scene.rod.elements, scene.rod.contacts.len());
        let work = crate::work::scene_work(&scene, n, m, workload);
        crate::limits::check_work(&work, work_limit).map_err(|e| too_large(path, e))?;
    }
    let structure = match &scene.model {
        // Import errors name the scene or the matrix file themselves.
        Some(spec) => {
            let structure = match (matrices, &scene.bladed_disk) {
                (Some(read), _) => build_imported_with(spec, read),
                (None, Some(mistuning)) => {
                    let disk = crate::scene::bladed_disk_matrices(mistuning);
                    build_imported_with(spec, |path: &Path| {
                        let found = disk.iter().find(|(name, _)| name == path);
                        Ok(found.expect("the disk's spec names its matrices").1.clone())
                    })
                }
                (None, None) => build_imported(spec),
            }
            .map_err(|e| CliError::BadInput(e.to_string()))?;
            let mut structure = structure;
            let parts = &scene.load_parts;
            crate::scene::add_load_parts(parts, spec.amplitude, &mut structure.model, matrices)
                .map_err(CliError::BadInput)?;
            let mut structure = scene.apply_cyclic(structure).map_err(CliError::BadInput)?;
            structure.model = expand_tangential_stiffness(structure.model)
                .map_err(|e| CliError::BadInput(e.to_string()))?;
            if solves {
                let need = crate::limits::structure_memory(&structure, &scene.solver, compare);
                crate::limits::check(&need, limit).map_err(|e| too_large(path, e))?;
            }
            let (n, m) = (structure.model.dofs(), structure.model.contacts.len());
            scene.resolve_sweep_unit(structure.omega_1);
            let omega_1 = Some(structure.omega_1);
            let work = crate::work::scene_work_at(&scene, (n, m), omega_1, workload);
            crate::limits::check_work(&work, work_limit).map_err(|e| too_large(path, e))?;
            structure
        }
        None => {
            let mut rod = build_rod(&scene.rod)
                .map_err(|e| input_error(path, e))?
                .structure;
            if let Some(dof) = scene.output_dof {
                rod.observed_dof = dof;
            }
            rod
        }
    };
    scene.resolve_sweep_unit(structure.omega_1);
    let omega = scene.omega(structure.omega_1);
    check_scales(&scene, structure.omega_1, omega).map_err(|e| input_error(path, e))?;
    check_resonance(&scene, &structure, omega).map_err(|e| input_error(path, e))?;
    // scene-check reduces the structure itself, to print both models' frequencies.
    let reduction = match (&scene.reduction, workload) {
        (Some(spec), w) if w != Workload::Check => Some(
            crate::reduce::reduce(&scene, spec, &structure, omega)
                .map_err(|e| input_error(path, e))?,
        ),
        _ => None,
    };
    let structure = reduction
        .as_ref()
        .map_or(structure, |r| r.structure.clone());
    let loaded = Loaded {
        scene,
        structure,
        omega,
    };
    Ok((loaded, reduction))
}

/// Largest ratio of a forcing or sweep frequency to `omega_1` (and smallest, inverted):
/// beyond it `(H omega)^2 M` leaves the floating-point range or the period the time steps.
pub const MAX_FREQUENCY_RATIO: f64 = 1e6;

/// Largest damping ratio at `omega_1` (`zeta`, or `alpha / (2 omega_1) + beta omega_1 / 2`).
pub const MAX_DAMPING_RATIO: f64 = 1e6;

/// Refuses frequencies and damping out of scale with the structure's `omega_1` (their
/// products overflow into infinite matrices): the message names the key and the value.
fn check_scales(scene: &Scene, omega_1: f64, omega: f64) -> Result<(), String> {
    use semismooth_contact::rod::{DampingSpec, FrequencySpec};
    let range = 1.0 / MAX_FREQUENCY_RATIO..=MAX_FREQUENCY_RATIO;
    let ratio = omega / omega_1;
    if !range.contains(&ratio) {
        let (key, value) = match scene.frequency() {
            FrequencySpec::Ratio(r) => ("forcing.omega_ratio", r),
            FrequencySpec::Absolute(w) => ("forcing.omega", w),
        };
        return Err(format!(
            "invalid `{key}` = {value:e} (omega / omega_1 = {ratio:e}): allowed frequencies \
             between {:e} and {:e} times omega_1 = {omega_1:e}",
            range.start(),
            range.end()
        ));
    }
    if let Some(sweep) = &scene.sweep {
        let bounds = [sweep.omega_ratio_from, sweep.omega_ratio_to];
        for (key, r) in scene.sweep_keys.into_iter().zip(bounds) {
            if !range.contains(&r) {
                return Err(format!(
                    "invalid `{key}`: {r:e} times omega_1 = {omega_1:e}: allowed {:e}..={:e} \
                     times omega_1",
                    range.start(),
                    range.end()
                ));
            }
        }
    }
    let damping = match &scene.model {
        Some(spec) => spec.damping,
        None => scene.rod.damping,
    };
    let (keys, zeta) = match damping {
        Some(DampingSpec::StiffnessProportional { zeta }) => ("damping.zeta", zeta),
        Some(DampingSpec::Rayleigh { alpha, beta }) => (
            "damping.alpha and damping.beta",
            alpha / (2.0 * omega_1) + beta * omega_1 / 2.0,
        ),
        None => ("", 0.0),
    };
    if zeta.is_nan() || zeta > MAX_DAMPING_RATIO {
        return Err(format!(
            "invalid `{keys}`: a damping ratio of {zeta:e} at omega_1 = {omega_1:e}: allowed at \
             most {MAX_DAMPING_RATIO:e}"
        ));
    }
    Ok(())
}

/// Amplification of the undamped linear response over the static one above which a
/// structure without damping and contact is taken as forced at a natural frequency (a
/// damping ratio of 1e-9 bounds the resonant amplification near 5e8).
pub const RESONANCE_AMPLIFICATION: f64 = 1e9;

/// Refuses an undamped structure without contact forced at a natural frequency: it has no
/// periodic solution (the response grows without bound), so nothing is run.
fn check_resonance(scene: &Scene, structure: &Structure, omega: f64) -> Result<(), String> {
    let model = &structure.model;
    // A reduced cyclic sector's undamped response depends on its couplings, which the
    // amplification check does not read.
    if !model.contacts.is_empty() || model.damping.is_some() || model.cyclic.is_some() {
        return Ok(());
    }
    match model.undamped_amplification(omega) {
        Some(a) if a.is_nan() || a > RESONANCE_AMPLIFICATION => {
            let key = match scene.frequency() {
                semismooth_contact::rod::FrequencySpec::Ratio(_) => "forcing.omega_ratio",
                semismooth_contact::rod::FrequencySpec::Absolute(_) => "forcing.omega",
            };
            Err(format!(
                "invalid `{key}`: omega / omega_1 = {} is a natural frequency of the undamped \
                 structure without contact (its response would be {a:.1e} times the static \
                 one): there is no periodic solution; allowed a frequency off the natural \
                 frequencies, or add [damping] or a contact",
                omega / structure.omega_1
            ))
        }
        _ => Ok(()),
    }
}

/// Claims the files a `[model]` scene names (its matrices and load vector) as inputs of
/// `set`: no output may replace them.
pub(crate) fn claim_model_files(set: &mut OutputSet, scene: &Scene) -> Result<(), CliError> {
    if let (Some(spec), None) = (&scene.model, &scene.bladed_disk) {
        let mut files = vec![
            (&spec.mass, "[model] mass"),
            (&spec.stiffness, "[model] stiffness"),
        ];
        if spec.load_dof.is_none() {
            files.push((&spec.forcing_vector, "[forcing] vector"));
        }
        if let Some(d) = &spec.damping_matrix {
            files.push((d, "[model] damping"));
        }
        for (path, key) in files {
            set.input(path, &format!("the scene's {key} file"))?;
        }
    }
    Ok(())
}

/// What `ssn solve` and `ssn sweep` read and write: the scene, and the optional outputs
/// (the help texts are those of `solve`; `main` words them for `sweep`).
#[derive(Debug, Clone, clap::Args)]
pub struct RunArgs {
    /// Scene file (TOML).
    pub scene: PathBuf,
    /// Print the result as JSON on stdout.
    #[arg(long)]
    pub json: bool,
    /// Write the tip displacement and contact force over one period as CSV (`-`: standard
    /// output).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write a plot of the tip displacement over one period as SVG (`-`: standard output).
    #[arg(long)]
    pub svg: Option<PathBuf>,
    /// Replace a scene key before the scene is checked, e.g. `--set
    /// forcing.omega_ratio=1.1 --set solver.harmonics=40` (repeatable; the keys, defaults
    /// and errors of the scene file; `contact.point.0.gap` indexes a list).
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = parse_override)]
    pub set: Vec<Override>,
}

/// `--set KEY=VALUE` as an [`Override`].
fn parse_override(text: &str) -> Result<Override, String> {
    Override::parse(text).map_err(|e| e.to_string())
}

/// What `ssn sweep` reads and writes: [`RunArgs`], and whether the points get their
/// stability.
#[derive(Debug, Clone, clap::Args)]
pub struct SweepArgs {
    /// The scene and the outputs every run has.
    #[command(flatten)]
    pub run: RunArgs,
    /// Skip the Floquet multipliers of the points (as `[sweep] stability = false`): every
    /// point is undecided, the branch costs only its continuation.
    #[arg(long)]
    pub no_stability: bool,
}

/// What `ssn solve` reads and writes: [`RunArgs`], and the harmonic-balance state to write
/// or to start from ([`crate::state`]).
#[derive(Debug, Clone, clap::Args)]
pub struct SolveArgs {
    /// The scene and the outputs every run has.
    #[command(flatten)]
    pub run: RunArgs,
    /// Write the solution's harmonic coefficients as JSON (method, harmonics, dofs,
    /// contacts, omega and the coefficients: a state for --start; `-`: standard output).
    #[arg(long)]
    pub state: Option<PathBuf>,
    /// Start Newton from a state written by --state, or from one solution of
    /// `ssn solutions --json` (choose it with --entry). Only harmonics may differ: the state
    /// is then lifted (zero higher harmonics) or truncated.
    #[arg(long)]
    pub start: Option<PathBuf>,
    /// The solution of an `ssn solutions --json` file to start from (1 = the first listed).
    #[arg(long, requires = "start", allow_hyphen_values = true, value_parser = entry_number)]
    pub entry: Option<usize>,
    /// Write the periodic response on the `[model] mesh` for ParaView into this directory:
    /// `response_000.vtu`, ... at instants of the period, and `response.pvd` to animate them.
    #[arg(long)]
    pub vtu: Option<PathBuf>,
    /// Instants of the period written by --vtu (t_k = k T / N).
    #[arg(long, requires = "vtu", default_value_t = crate::paraview::DEFAULT_FRAMES)]
    pub vtu_frames: usize,
}

/// `--entry K`: a solution counted from 1 (a negative or zero `K` is named as such, not
/// taken for an option).
fn entry_number(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(k) if k >= 1 => Ok(k),
        _ => Err(format!(
            "`{}`: allowed 1, 2, ... (the solutions of the file, counted from 1)",
            printable(text)
        )),
    }
}

/// The curve of a run's SVG: titled by the scene, or `untitled` when it has no title.
struct Plot {
    untitled: &'static str,
    x_label: &'static str,
    y_label: &'static str,
    series: Vec<Series>,
}

impl RunArgs {
    /// Claims the run's outputs before it starts: the scene is an input no output may
    /// replace, standard output carries the JSON (or the text summary unless `--quiet`),
    /// and every file target must be new or a regular file.
    pub(crate) fn plan(&self) -> Result<OutputSet, CliError> {
        let mut set = OutputSet::new();
        set.input(&self.scene, "the scene")?;
        if self.json {
            set.stdout("--json")?;
        } else if !crate::io::quiet() {
            set.stdout("the text summary (add --quiet or --json)")?;
        }
        if let Some(csv) = &self.csv {
            set.target(csv, "--csv")?;
        }
        if let Some(svg) = &self.svg {
            set.target(svg, "--svg")?;
        }
        Ok(set)
    }

    /// Queues the requested outputs: the CSV of `columns` under `headers`, and the SVG of
    /// `plot` (built only when an SVG is requested).
    fn queue_outputs(
        &self,
        set: &mut OutputSet,
        scene: &Scene,
        headers: &[&str],
        columns: &[&[f64]],
        plot: impl FnOnce() -> Plot,
    ) -> Result<(), CliError> {
        if let Some(csv) = &self.csv {
            set.add(csv, csv_table(headers, columns).into_bytes());
        }
        if let Some(svg) = &self.svg {
            let plot = plot();
            let spec = PlotSpec {
                title: scene.title.clone().unwrap_or_else(|| plot.untitled.into()),
                x_label: plot.x_label.into(),
                y_label: plot.y_label.into(),
                log_log: false,
            };
            set.add(svg, line_plot_svg(&spec, &plot.series)?.into_bytes());
        }
        Ok(())
    }

    /// Writes the outputs (all or none), then the result on standard output, as JSON
    /// (`--json`) or as the text `text` returns (nothing with `--quiet`), and maps
    /// convergence onto the outcome.
    pub(crate) fn finish(
        &self,
        mut set: OutputSet,
        json: impl FnOnce() -> Value,
        text: impl FnOnce() -> String,
        converged: bool,
    ) -> Result<(), CliError> {
        if self.json {
            let doc = serde_json::to_string_pretty(&json())
                .map_err(|e| CliError::Output(format!("cannot format the JSON: {e}")))?;
            set.add(
                Path::new(crate::io::STDOUT_NAME),
                format!("{doc}\n").into_bytes(),
            );
        }
        if !self.json && !crate::io::quiet() {
            // The summary goes with the files: a summary that cannot be written leaves none.
            set.add(Path::new(crate::io::STDOUT_NAME), text().into_bytes());
        }
        set.commit()?;
        if converged {
            Ok(())
        } else {
            Err(CliError::NotConverged)
        }
    }
}

/// `ssn solve SCENE`: one periodic response; text or JSON on stdout, optional CSV/SVG, and
/// the harmonic-balance state with `--state`; Newton starts from `--start` when given.
pub fn solve(solve_args: &SolveArgs) -> Result<(), CliError> {
    let args = &solve_args.run;
    let mut outputs = args.plan()?;
    // The start is an input: no output may replace it.
    if let Some(start) = &solve_args.start {
        outputs.input(start, "the --start state")?;
    }
    if let Some(state) = &solve_args.state {
        outputs.target(state, "--state")?;
    }
    let (loaded, reduction) = load_keeping_reduction(&args.scene, &args.set, Workload::Solve)?;
    let Loaded {
        scene,
        structure: rod,
        omega,
    } = loaded;
    claim_model_files(&mut outputs, &scene)?;
    let picture = match &solve_args.vtu {
        Some(dir) => Some(crate::paraview::plan(
            &mut outputs,
            &scene,
            dir,
            solve_args.vtu_frames,
        )?),
        None => None,
    };
    let shape = StateShape {
        method: scene.solver.method,
        harmonics: scene.solver.harmonics,
        dofs: rod.model.dofs(),
        contacts: rod.model.contacts.len(),
    };
    let start = read_start(solve_args, &scene, shape)?;
    // Time marching to a steady state is the long one: a spinner while it runs.
    let bar = if scene.solver.method.marches() {
        progress_spinner("time marching to a steady state")
    } else {
        indicatif::ProgressBar::hidden()
    };
    let solution = semismooth_contact::solve(
        &rod,
        omega,
        &scene.solver,
        start.as_ref().map(|s| s.unknowns.as_slice()),
    )
    .map_err(|e| input_error(&args.scene, e))?;
    bar.finish_and_clear();
    let mut columns: Vec<&[f64]> = vec![&solution.times, &solution.observed];
    let mut headers = vec!["t".to_string(), "u_tip".to_string()];
    for (i, f) in solution.contact_forces.iter().enumerate() {
        columns.push(f);
        headers.push(format!("lambda_{i}"));
    }
    for (i, f) in solution.contact_force_series.iter().enumerate() {
        columns.push(f);
        headers.push(format!("lambda_series_{i}"));
    }
    frictional_columns(&solution, &mut columns, &mut headers);
    let headers: Vec<&str> = headers.iter().map(String::as_str).collect();
    args.queue_outputs(&mut outputs, &scene, &headers, &columns, || {
        solve_plot(&solution, &rod)
    })?;
    if let Some(path) = &solve_args.state {
        outputs.add(path, state_document(&solution, shape)?.into_bytes());
    }
    if let (Some(dir), Some(picture)) = (&solve_args.vtu, &picture) {
        let frames = (dir.as_path(), solve_args.vtu_frames);
        let reduced = reduction.as_ref();
        crate::paraview::queue(&mut outputs, frames, picture, &solution, shape, reduced)?;
    }
    args.finish(
        outputs,
        || {
            let mut v = crate::json::solution_json(&args.scene, &solution);
            if let Some(amplitudes) = crate::json::blade_amplitudes(&rod, &solution) {
                v["blade_amplitudes"] = amplitudes;
            }
            if let Some(s) = &start {
                v["started_from"] = s.to_json();
            }
            v
        },
        || {
            let mut t = crate::words::solution_text(&solution, &scene.solver);
            if let Some(s) = &start {
                t += &format!("started from      {}\n", s.describe());
            }
            t
        },
        // An accuracy target not met is a run that did not converge (exit code 1).
        solution.converged() && solution.search.as_ref().is_none_or(|s| s.met()),
    )
}

/// The CSV columns of each 3-D frictional contact `p` (1-based) at the solution's times:
/// `contact3d_{p}_normal`, `_t1`, `_t2` (forces) and `_v1`, `_v2` (slip velocities).
fn frictional_columns<'a>(
    solution: &'a Solution,
    columns: &mut Vec<&'a [f64]>,
    headers: &mut Vec<String>,
) {
    let times = solution.times.len();
    for p in &solution.frictional_contacts {
        let series = [
            ("normal", &p.normal_force),
            ("t1", &p.tangential_force[0]),
            ("t2", &p.tangential_force[1]),
            ("v1", &p.slip_velocity[0]),
            ("v2", &p.slip_velocity[1]),
        ];
        for (name, values) in series.into_iter().filter(|(_, v)| v.len() == times) {
            columns.push(values);
            headers.push(format!("contact3d_{}_{name}", p.point + 1));
        }
    }
}

/// The SVG of a solve: the tip over one period, with the obstacles of `rod`.
fn solve_plot(solution: &Solution, rod: &Structure) -> Plot {
    let period = 2.0 * std::f64::consts::PI / solution.omega;
    let t: Vec<f64> = solution.times.iter().map(|t| t / period).collect();
    let mut series = vec![Series::new(
        crate::words::describe_method(solution),
        t.clone(),
        solution.observed.clone(),
    )];
    series.extend(crate::figures::obstacle_lines(rod, 0.0, 1.0));
    Plot {
        untitled: "tip displacement",
        x_label: "time t / T (T: forcing period)",
        y_label: "tip displacement u_tip",
        series,
    }
}

/// The state `--start` names, read for the unknowns of `shape` (`None` without it), after
/// checking that `--state` and `--start` fit the scene's method and its accuracy target.
fn read_start(
    solve_args: &SolveArgs,
    scene: &Scene,
    shape: StateShape,
) -> Result<Option<StartedFrom>, CliError> {
    let path = &solve_args.run.scene;
    for (given, option) in [
        (solve_args.state.is_some(), "--state"),
        (solve_args.start.is_some(), "--start"),
    ] {
        if given {
            crate::state::check_method(shape.method, option).map_err(|e| input_error(path, e))?;
        }
    }
    if solve_args.start.is_some() && scene.solver.accuracy.is_some() {
        return Err(input_error(
            path,
            "--start with solver.accuracy: the search chooses the harmonics and solves from zero (remove one of the two)",
        ));
    }
    let Some(path) = &solve_args.start else {
        return Ok(None);
    };
    let state = read_state(path, solve_args.entry).map_err(CliError::BadInput)?;
    let (x, note) = state.unknowns_for(shape).map_err(|e| {
        CliError::BadInput(format!("{}: {e}", printable(&path.display().to_string())))
    })?;
    Ok(Some(StartedFrom {
        file: printable(&path.display().to_string()),
        entry: solve_args.entry,
        omega_ratio: state.omega / state.omega_1,
        note,
        unknowns: x,
    }))
}

/// The `--state` file of `solution` (unknowns of `shape`, with an accuracy target at the
/// search's harmonics): the state, whether it converged and its residual norm.
fn state_document(solution: &Solution, shape: StateShape) -> Result<String, CliError> {
    let shape = StateShape {
        harmonics: solution.harmonics.unwrap_or(shape.harmonics),
        ..shape
    };
    let mut doc =
        HbState::from_unknowns(shape, solution.omega, solution.omega_1, &solution.state).to_json();
    doc["converged"] = json!(solution.converged());
    doc["residual_norm"] = crate::json::finite_or_null(solution.residual_norm);
    let text = serde_json::to_string_pretty(&doc)
        .map_err(|e| CliError::Output(format!("cannot format the state: {e}")))?;
    Ok(format!("{text}\n"))
}

/// The state `ssn solve --start` began from.
struct StartedFrom {
    file: String,
    entry: Option<usize>,
    omega_ratio: f64,
    note: Option<String>,
    unknowns: Vec<f64>,
}

impl StartedFrom {
    fn to_json(&self) -> Value {
        json!({
            "file": self.file,
            "entry": self.entry,
            "omega_ratio": self.omega_ratio,
            "note": self.note,
        })
    }

    fn describe(&self) -> String {
        format!(
            "{}{} (a state at omega/omega_1 = {:.6}){}",
            self.file,
            self.entry
                .map(|k| format!(", entry {k}"))
                .unwrap_or_default(),
            self.omega_ratio,
            self.note
                .as_ref()
                .map(|n| format!("; {n}"))
                .unwrap_or_default()
        )
    }
}

/// `ssn sweep SCENE`: the frequency response over the scene's `[sweep]` range by
/// pseudo-arclength continuation; text or JSON on stdout, optional CSV/SVG.
pub fn sweep(sweep_args: &SweepArgs) -> Result<(), CliError> {
    let args = &sweep_args.run;
    let mut outputs = args.plan()?;
    let Loaded {
        scene,
        structure: rod,
        ..
    } = load_with(&args.scene, &args.set, Workload::Branch)?;
    claim_model_files(&mut outputs, &scene)?;
    let Some(mut settings) = scene.sweep.clone() else {
        return Err(input_error(
            &args.scene,
            "no [sweep] section: add omega_ratio_from and omega_ratio_to (units of omega_1)",
        ));
    };
    settings.stability &= !sweep_args.no_stability;
    let started = std::time::Instant::now();
    let (response, fold_accuracy) =
        run_sweep(&rod, &scene, &settings).map_err(|e| input_error(&args.scene, e))?;
    let seconds = started.elapsed().as_secs_f64();
    let ratio = response.omega_ratio();
    let table = crate::sweep_table::sweep_columns(&response);
    let headers: Vec<&str> = table.iter().map(|(name, _)| name.as_str()).collect();
    let columns: Vec<&[f64]> = table.iter().map(|(_, values)| values.as_slice()).collect();
    args.queue_outputs(&mut outputs, &scene, &headers, &columns, || {
        sweep_plot(&scene, &response, &ratio)
    })?;
    let folds_met = fold_accuracy.iter().flatten().all(|f| f.met());
    args.finish(
        outputs,
        || {
            let mut json = crate::json::response_json(&response);
            if let Some(folds) = &fold_accuracy {
                json["fold_accuracy"] = crate::json::fold_accuracy_json(folds, rod.omega_1);
            }
            json
        },
        || crate::words::sweep_text(&response, fold_accuracy.as_deref(), rod.omega_1, seconds),
        response.converged() && folds_met,
    )
}

/// The frequency response of `rod` over `settings` with a spinner telling the progress,
/// and with an accuracy target its folds located again with the harmonics it needs.
fn run_sweep(
    rod: &Structure,
    scene: &Scene,
    settings: &SweepSettings,
) -> Result<(FrequencyResponse, Option<Vec<FoldAccuracy>>), RunError> {
    let bar = progress_spinner("sweep");
    let progress = |p: SweepProgress| {
        match p {
            SweepProgress::Branch {
                points,
                omega_ratio,
            } => bar.set_message(format!(
                "sweep: {points} points, omega/omega_1 = {omega_ratio:.4}"
            )),
            SweepProgress::Stability { done, total } => {
                bar.set_message(format!("stability: {done} of {total} points"))
            }
            _ => {}
        }
        bar.tick();
    };
    let response = semismooth_contact::sweep::frequency_response(
        rod,
        &scene.solver,
        settings,
        Some(&progress),
    )?;
    let fold_accuracy = match scene.solver.accuracy {
        Some(target) if response.converged() => {
            bar.set_message("folds to the accuracy target");
            Some(refine_folds(
                rod,
                &scene.solver,
                settings,
                &response,
                (target, MAX_FOLD_HARMONICS),
            )?)
        }
        _ => None,
    };
    bar.finish_and_clear();
    Ok((response, fold_accuracy))
}

/// The SVG of a sweep: the amplitude against the frequency ratio `ratio`, by stability.
fn sweep_plot(scene: &Scene, response: &FrequencyResponse, ratio: &[f64]) -> Plot {
    let harmonics = response.harmonics();
    let label = match (harmonics.iter().min(), harmonics.iter().max()) {
        (Some(lo), Some(hi)) if lo != hi => {
            format!("{} H = {lo} to {hi}", scene.solver.method.name())
        }
        _ => format!(
            "{} H = {}",
            scene.solver.method.name(),
            scene.solver.harmonics
        ),
    };
    let stable = &response.stable();
    let mut series = stability_series(&label, 0, ratio, &response.amplitudes(), stable);
    let mut verdicts = stable.clone();
    // The period-2 branches born at period doublings, each in a colour of its own.
    for (k, outcome) in response.period_two.iter().enumerate() {
        if let PeriodTwoOutcome::Followed(b) = outcome {
            let branch = &b.response;
            let label = format!(
                "period 2 from omega / omega_1 = {:.4}",
                b.from.omega / response.omega_1
            );
            let stable = branch.stable();
            series.extend(stability_series(
                &label,
                k + 1,
                &branch.omega_ratio(),
                &branch.amplitudes(),
                &stable,
            ));
            verdicts.extend(stable);
        }
    }
    series.extend(stability_key(&verdicts));
    Plot {
        untitled: "frequency response",
        x_label: "forcing frequency omega / omega_1",
        y_label: "tip amplitude max_t |u_tip(t)|",
        series,
    }
}

/// `ssn compare SCENE`: accuracy against cost of every applicable method on the scene's rod
/// (error of the tip minimum against a converged reference versus wall time); prints the
/// table and the cheapest setting of each method for `accuracy`, writes
/// `accuracy_cost.csv` and `accuracy_cost.svg` into `out`.
pub fn compare(path: &Path, out: &Path, accuracy: f64) -> Result<(), CliError> {
    if !(accuracy.is_finite() && accuracy > 0.0) {
        return Err(CliError::BadInput(format!(
            "invalid --accuracy {accuracy}: allowed a finite number > 0 (relative error of the tip minimum)"
        )));
    }
    let Loaded {
        scene,
        structure: rod,
        omega,
    } = load_for(path, Workload::Compare)?;
    prepare_directory(out)?;
    // Every target is checked before the study runs (the files are written after it).
    let mut targets = OutputSet::new();
    targets.input(path, "the scene")?;
    claim_model_files(&mut targets, &scene)?;
    for name in crate::accuracy_cost::STUDY_FILES {
        targets.target(&out.join(name), "ssn compare --out")?;
    }
    let bar = progress_spinner("compare");
    let say = |line: &str| {
        bar.set_message(line.to_string());
        bar.tick();
    };
    let study = crate::accuracy_cost::accuracy_cost(&rod, omega, &scene.solver, Some(&say))
        .map_err(|e| input_error(path, e))?;
    say("each method's own search for the accuracy");
    let chosen = (accuracy < 1.0)
        .then(|| {
            crate::accuracy_targets::self_chosen_lines(
                &rod,
                omega,
                &scene.solver,
                accuracy,
                study.reference.tip_min,
                &study.skipped,
            )
        })
        .transpose()
        .map_err(|e| input_error(path, e))?
        .unwrap_or_default();
    bar.finish_and_clear();
    study.write_files(out)?;
    let skipped: String = (study.skipped.iter())
        .map(|(method, why)| format!("{} skipped: does not apply ({why})\n", method.name()))
        .collect();
    write_text(&format!(
        "{skipped}{}\nCheapest setting of each method for a relative accuracy of {accuracy:e} on the tip \
         minimum:\n{}\nThe setting each method chooses itself for {accuracy:e} (its estimate, on \
         the tip extremes and mean contact forces, without the reference):\n{chosen}\nWrote \
         {}/accuracy_cost.csv and accuracy_cost.svg\n",
        study.table(),
        study.cheapest_table(accuracy),
        printable(&out.display().to_string())
    ))?;
    Ok(())
}

/// `ssn export-model SCENE DIR`: writes the scene's structure as Matrix Market files and a
/// `[model]` scene (`DIR/scene.toml`) that solves the same problem.
pub fn export_model(path: &Path, dir: &Path) -> Result<(), CliError> {
    let Loaded {
        scene, structure, ..
    } = load_for(path, Workload::Export)?;
    prepare_directory(dir)?;
    // All files or none: every target is claimed before anything is written.
    let mut set = OutputSet::new();
    set.input(path, "the scene")?;
    claim_model_files(&mut set, &scene)?;
    let mut written = String::new();
    for (name, text) in crate::import::export_files(&scene, &structure) {
        let target = dir.join(&name);
        set.target(&target, "export-model")?;
        set.add(&target, text.into_bytes());
        written += &format!("wrote {}\n", printable(&target.display().to_string()));
    }
    set.commit()?;
    write_text(&written)?;
    Ok(())
}

/// `ssn scene-check SCENE`: validates the scene and prints the resolved model with up to
/// five natural frequencies (massless dofs have none: a modified-mass rod has one fewer).
pub fn scene_check(path: &Path) -> Result<(), CliError> {
    let Loaded {
        scene,
        structure: rod,
        omega,
    } = load_for(path, Workload::Check)?;
    let modes = first_frequencies(&rod.model).map_err(|e| input_error(path, e))?;
    let mut text = describe(&scene, &rod, omega, &modes);
    if let Some(spec) = &scene.reduction {
        let reduced =
            crate::reduce::reduce(&scene, spec, &rod, omega).map_err(|e| input_error(path, e))?;
        let model = &reduced.structure.model;
        let count = modes.len().min(model.dofs());
        let reduced_modes = natural_frequencies(model, count).map_err(|e| input_error(path, e))?;
        text.push_str(&crate::reduce::reduction_lines(
            spec.method,
            &reduced,
            &modes,
            &reduced_modes,
        ));
    }
    write_text(&text)?;
    Ok(())
}

/// Up to five lowest natural frequencies of `model`: shift-invert Lanczos on a sparse
/// Cholesky above [`LANCZOS_MIN_DOFS`] dofs (a 3-D model), subspace iteration below.
fn first_frequencies(model: &StructuralModel) -> Result<Vec<f64>, String> {
    if model.dofs() > LANCZOS_MIN_DOFS {
        return lowest_frequencies(model, 5).map_err(|e| e.to_string());
    }
    match natural_frequencies(model, 5.min(model.dofs())) {
        Err(ModelError::TooManyModes { available, .. }) => natural_frequencies(model, available),
        other => other,
    }
    .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use crate::words::folds_summary;

    #[test]
    fn few_folds_are_listed_and_many_are_summarised_by_count_and_range() {
        assert_eq!(folds_summary(&[], 2.0), "none");
        assert_eq!(folds_summary(&[2.1, 2.05], 2.0), "1.0500, 1.0250");
        let many: Vec<f64> = (0..20).map(|k| 2.0 + 0.001 * k as f64).collect();
        assert_eq!(
            folds_summary(&many, 2.0),
            "20 between 1.0000 and 1.0095 (first 1.0000, last 1.0095; all in --json)"
        );
    }
}
