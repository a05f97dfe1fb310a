//! Loading a scene: the scene read and validated, its structure built (the rod, or the
//! imported matrices with their load parts, cyclic coupling and reduction), its memory and
//! work checked against the limits, and its forcing frequency resolved, for the commands,
//! the study runner and the Python package alike.

use std::fmt::Display;
use std::path::Path;

pub use crate::exit::CliError;
use crate::io::OutputSet;
use crate::scene::{Override, Scene};
pub use crate::work::Workload;
use semismooth_contact::jenkins::expand_tangential_stiffness;
use semismooth_contact::matrix_market::{build_imported, build_imported_with};
use semismooth_contact::model::Structure;
use semismooth_contact::reduction::CraigBampton;
use semismooth_contact::rod::build_rod;

/// Why a scene could not be loaded: bad input, or a run refused up front as too large
/// (the application's one error type, whose variants `main` maps onto exit codes).
pub type LoadError = CliError;

/// Bad input found in the scene file `path`: the message starts with the file.
pub(crate) fn input_error(path: &Path, e: impl Display) -> CliError {
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
pub fn claim_model_files(set: &mut OutputSet, scene: &Scene) -> Result<(), CliError> {
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
