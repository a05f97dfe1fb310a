//! Scenes: TOML problem descriptions, validated into a rod spec and solver settings.
//!
//! Only what a scene declares is simulated: no `[damping]` section means no damping matrix,
//! no `[contact]` section means a linear problem. Every key, its unit, default and allowed
//! values are listed in README.md ("Scene format"); unknown keys are errors.
//!
//! ```toml
//! [rod]
//! elements = 20              # required, integer >= 1
//! mass = "modified"          # consistent | lumped | modified (default consistent)
//! [damping]
//! zeta = 0.01                # or alpha/beta (Rayleigh)
//! [forcing]
//! amplitude = 0.04
//! omega_ratio = 1.0          # or omega (absolute)
//! [contact]
//! gap = 0.5                  # tip contact; or [[contact.point]] node/gap entries
//! [solver]
//! method = "ssn-hb"
//! harmonics = 20
//! ```

use std::path::{Path, PathBuf};

use serde::Deserialize;

use semismooth_contact::matrix_market::{
    DofContact, DofFriction, DofMapFile, MatrixFormat, ModelSpec,
};
use semismooth_contact::rod::{
    DampingSpec, FrequencySpec, LoadKind, MassModel, RodContact, RodSpec,
};

mod check;
mod contacts;
mod cyclic;
mod disk;
mod formats;
mod frictional;
mod load_parts;
mod nodes;
mod overrides;
mod reduction;
mod sweep_units;

pub use cyclic::{CyclicSpec, EngineOrderSpec, MAX_SECTORS};
pub use disk::{bladed_disk_matrices, MAX_BLADES};
pub use load_parts::{add_load_parts, LoadPart, MatrixSource};
pub use reduction::{ModeSelection, ReductionMethod, ReductionSpec, MAX_REDUCTION_MODES};
pub use sweep_units::SweepUnit;

pub use overrides::{
    normal_key, parse_value, read_scene_text, Override, OverrideError, MAX_KEY_PARTS,
};

pub use semismooth_contact::settings::{
    default_hb_time_samples, GlobalizationChoice, LcpScheme, LinearSolverChoice, Method,
    SolverSettings, SweepSettings, DEFAULT_RELATIVE_PENALTY,
};

/// Why a scene could not be used: the input-file errors (the file; for a bad value also
/// the key, the value found and what is allowed).
pub type SceneError = crate::input_file::InputFileError;

/// A validated scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Where it came from (`<built-in>` for scenes built in code).
    pub path: PathBuf,
    /// Optional title (`title = "..."`).
    pub title: Option<String>,
    /// The rod of a `[rod]` scene (for a `[model]` scene: unused, the canonical rod).
    pub rod: RodSpec,
    /// The imported structure of a `[model]` scene (`None` for a `[rod]` scene).
    pub model: Option<ModelSpec>,
    /// The `[model] mesh` input deck (node coordinates and elements), if given.
    pub mesh: Option<PathBuf>,
    /// The blade stiffness deviations of a `[bladed_disk]` scene, one per blade (`None`
    /// otherwise); its `model` names the disk's matrices ([`bladed_disk_matrices`]).
    pub bladed_disk: Option<Vec<f64>>,
    /// `[output] dof`, 0-based: the dof that `tip_*` outputs and plots describe (default: the
    /// rod's tip; for a `[model]` scene the first contact dof).
    pub output_dof: Option<usize>,
    /// The load parts of a `[model]` scene beyond its cosine `vector` (`[forcing]
    /// vector_sin`, `static`, `[[forcing.harmonic]]`), added when its structure is built.
    pub load_parts: Vec<LoadPart>,
    /// `[forcing] engine_order` on a full model: the sectors' load delays.
    pub engine_order: Option<EngineOrderSpec>,
    /// `[cyclic]`: the `[model]` is one sector of a tuned disk.
    pub cyclic: Option<CyclicSpec>,
    /// Solver settings.
    pub solver: SolverSettings,
    /// Frequency sweep, if declared (its bounds in `sweep_unit` until the run resolves them
    /// to ratios of `omega_1`: [`Scene::resolve_sweep_unit`]).
    pub sweep: Option<SweepSettings>,
    /// The unit of the `[sweep]` bounds as given.
    pub sweep_unit: SweepUnit,
    /// The keys the `[sweep]` bounds were given with (kept once they are resolved to
    /// ratios), for messages.
    pub sweep_keys: [&'static str; 2],
    /// Nonlinear mode (`ssn modes`), if declared.
    pub modes: Option<ModesSettings>,
    /// The reduction of the structure before it is solved (`[reduction]`), if declared.
    pub reduction: Option<ReductionSpec>,
}

/// `[modes]`: which linear mode the backbone starts from and the range of the observed
/// dof's amplitude (the cosine part of its harmonic 1, the phase making the sine part zero)
/// or of the energy.
#[derive(Debug, Clone, PartialEq)]
pub struct ModesSettings {
    /// Which linear mode (1: the lowest natural frequency).
    pub mode: usize,
    /// The amplitude of the first point (NaN with `energy_range`).
    pub amplitude_from: f64,
    /// The amplitude of the last point (NaN with `energy_range`).
    pub amplitude_to: f64,
    /// `energy_from`, `energy_to`: the energy range in place of the amplitudes.
    pub energy_range: Option<(f64, f64)>,
    /// Largest number of points.
    pub max_points: usize,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    title: Option<String>,
    rod: Option<RawRod>,
    model: Option<RawModel>,
    bladed_disk: Option<disk::RawBladedDisk>,
    cyclic: Option<cyclic::RawCyclic>,
    damping: Option<RawDamping>,
    forcing: Option<RawForcing>,
    obstacle: Option<RawObstacle>,
    contact: Option<RawContact>,
    friction: Option<RawFrictionSection>,
    output: Option<RawOutput>,
    #[serde(default)]
    solver: RawSolver,
    sweep: Option<RawSweep>,
    modes: Option<RawModes>,
    reduction: Option<reduction::RawReduction>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRod {
    elements: i64,
    length: Option<f64>,
    axial_stiffness: Option<f64>,
    mass_per_length: Option<f64>,
    #[serde(default)]
    mass: RawMass,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawModel {
    format: Option<RawMatrixFormat>,
    mass: String,
    stiffness: String,
    damping: Option<String>,
    dof_map: Option<String>,
    mesh: Option<String>,
}

#[derive(Debug, Deserialize, Clone, Copy)]
#[serde(rename_all = "kebab-case")]
enum RawMatrixFormat {
    MatrixMarket,
    Calculix,
    Abaqus,
    NastranDmig,
    HarwellBoeing,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOutput {
    dof: Option<i64>,
    node: Option<i64>,
    component: Option<i64>,
}

#[derive(Debug, Deserialize, Default, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum RawMass {
    #[default]
    Consistent,
    Lumped,
    Modified,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDamping {
    model: Option<RawDampingModel>,
    zeta: Option<f64>,
    alpha: Option<f64>,
    beta: Option<f64>,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
enum RawDampingModel {
    StiffnessProportional,
    Rayleigh,
}

#[derive(Debug, Deserialize, Default, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum RawLoad {
    #[default]
    Distributed,
    Tip,
}

/// `[obstacle]`: the period of a scene driven by its moving obstacles alone.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawObstacle {
    omega: f64,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawForcing {
    /// No load at all (a `[model]` scene driven by its moving obstacles): not a key.
    #[serde(skip)]
    load_free: bool,
    load: Option<RawLoad>,
    vector: Option<String>,
    node: Option<i64>,
    component: Option<i64>,
    vector_sin: Option<String>,
    #[serde(rename = "static")]
    constant: Option<String>,
    harmonic: Option<Vec<load_parts::RawForcingHarmonic>>,
    amplitude: f64,
    omega_ratio: Option<f64>,
    omega: Option<f64>,
    engine_order: Option<i64>,
    sector_dofs: Option<Vec<Vec<i64>>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawContact {
    gap: Option<f64>,
    node: Option<i64>,
    point: Option<Vec<RawContactPoint>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawContactPoint {
    node: Option<i64>,
    component: Option<i64>,
    dof: Option<i64>,
    gap: f64,
    direction: Option<i64>,
    dofs: Option<Vec<i64>>,
    nodes: Option<Vec<i64>>,
    components: Option<Vec<i64>>,
    coefficients: Option<Vec<f64>>,
    friction: Option<f64>,
    tangent_dofs: Option<Vec<i64>>,
    tangent_nodes: Option<Vec<i64>>,
    tangent_components: Option<Vec<i64>>,
    tangent_coefficients: Option<Vec<f64>>,
    tangent2_dofs: Option<Vec<i64>>,
    tangent2_coefficients: Option<Vec<f64>>,
    normal: Option<formats::RawNormal>,
    axis: Option<Vec<f64>>,
    axis_origin: Option<Vec<f64>>,
    tangents: Option<Vec<Vec<f64>>>,
    tangential_stiffness: Option<f64>,
    gap_cos: Option<Vec<f64>>,
    gap_sin: Option<Vec<f64>>,
    sliding_velocity: Option<Vec<f64>>,
    neighbour_dofs: Option<Vec<i64>>,
    neighbour_coefficients: Option<Vec<f64>>,
    tangent_neighbour_dofs: Option<Vec<i64>>,
    tangent_neighbour_coefficients: Option<Vec<f64>>,
    tangent2_neighbour_dofs: Option<Vec<i64>>,
    tangent2_neighbour_coefficients: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFrictionSection {
    point: Option<Vec<RawFrictionPoint>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFrictionPoint {
    node: Option<i64>,
    component: Option<i64>,
    dof: Option<i64>,
    dofs: Option<Vec<i64>>,
    nodes: Option<Vec<i64>>,
    components: Option<Vec<i64>>,
    coefficients: Option<Vec<f64>>,
    normal_load: Option<f64>,
    friction: Option<f64>,
    neighbour_dofs: Option<Vec<i64>>,
    neighbour_coefficients: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct RawSolver {
    #[serde(default)]
    method: Method,
    harmonics: Option<i64>,
    time_samples: Option<i64>,
    c: Option<f64>,
    penalty_stiffness: Option<f64>,
    friction_regularisation: Option<f64>,
    #[serde(default)]
    linear_solver: LinearSolverChoice,
    max_iterations: Option<i64>,
    #[serde(default)]
    globalization: GlobalizationChoice,
    tolerance: Option<f64>,
    steps_per_period: Option<i64>,
    max_periods: Option<i64>,
    march_tolerance: Option<f64>,
    restitution: Option<f64>,
    #[serde(default)]
    lcp_scheme: LcpScheme,
    accuracy: Option<f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSweep {
    omega_ratio_from: Option<f64>,
    omega_ratio_to: Option<f64>,
    omega_from: Option<f64>,
    omega_to: Option<f64>,
    frequency_hz_from: Option<f64>,
    frequency_hz_to: Option<f64>,
    step: Option<f64>,
    min_step: Option<f64>,
    max_step: Option<f64>,
    max_points: Option<i64>,
    stability: Option<bool>,
    period_two: Option<bool>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawModes {
    mode: Option<i64>,
    amplitude_from: Option<f64>,
    amplitude_to: Option<f64>,
    energy_from: Option<f64>,
    energy_to: Option<f64>,
    max_points: Option<i64>,
}

/// Largest harmonic count accepted.
pub const MAX_HARMONICS: usize = 2000;
/// Largest sample / step count accepted.
pub const MAX_TIME_SAMPLES: usize = 1 << 20;
/// Smallest `[solver] accuracy` accepted: below it the iterations' own stopping rules limit
/// the answers (time marching stops at a period-to-period change of 1e-8, an error of
/// about 1.6e-7 on the paper's rod, module `semismooth_contact::march`).
pub const MIN_ACCURACY: f64 = 1e-7;
/// Largest `[solver] accuracy` accepted.
pub const MAX_ACCURACY: f64 = 0.1;
/// Largest accepted magnitude of a forcing amplitude or a gap: the response scales with
/// them, and a residual's square must stay below the largest double (1.8e308).
pub const MAX_RESPONSE_SCALE: f64 = 1e100;

/// The 1-based line of `text` nested deepest and its depth: the dots of a line (of a table
/// header or a dotted key) plus the most brackets and braces open on it (at least 1),
/// strings and comments skipped.
/// `None` for empty text. Only used to place a parse error that toml gives no position.
fn deepest_line(text: &str) -> Option<(usize, usize)> {
    let mut open = 0usize;
    let mut deepest = None::<(usize, usize)>;
    for (index, line) in text.lines().enumerate() {
        let (mut dots, mut quote, mut peak) = (0usize, None::<char>, open);
        for c in line.chars() {
            match (quote, c) {
                (Some(q), c) if c == q => quote = None,
                (Some(_), _) => {}
                (None, '"' | '\'') => quote = Some(c),
                (None, '#') => break,
                (None, '[' | '{') => {
                    open += 1;
                    peak = peak.max(open);
                }
                (None, ']' | '}') => open = open.saturating_sub(1),
                (None, '.') => dots += 1,
                _ => {}
            }
        }
        let depth = dots + peak.max(1);
        if deepest.is_none_or(|(_, d)| depth > d) {
            deepest = Some((index + 1, depth));
        }
    }
    deepest
}

impl Scene {
    /// Reads and validates a scene file (a regular file of at most
    /// [`crate::io::SCENE_SIZE_LIMIT`] bytes).
    pub fn from_path(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
        Scene::from_path_with(path, &[])
    }

    /// Parses and validates scene text; `path` is only used in messages.
    pub fn from_toml(text: &str, path: impl AsRef<Path>) -> Result<Scene, SceneError> {
        let path = path.as_ref();
        let raw: RawScene = toml::from_str(text)
            .map_err(|e| {
                let mut message = e.to_string().trim_end().to_string();
                // toml's words for a number outside f64 or i64: say what is allowed.
                if message.contains("overflow") || message.contains("as i128") {
                    message.push_str(
                        "\nallowed: floats of magnitude at most 1.7976931348623157e308, integers \
                     within 64 bits (each key's own range is in the README's scene table)",
                    );
                }
                // toml gives no position when the nesting exceeds its limit: name the line.
                if e.span().is_none() {
                    if let Some((line, depth)) = deepest_line(text) {
                        message.push_str(&format!(
                            " at line {line} (nested {depth} deep): allowed tables and values \
                             nested a few levels, as the README's scene table"
                        ));
                    }
                }
                message
            })
            .map_err(|message| SceneError::parse(path, message))?;
        check::resolve(raw, path)
    }

    /// The scene's `[forcing]` frequency (ratio or absolute): the `[model]`'s for an
    /// imported structure, the `[rod]`'s otherwise.
    pub fn frequency(&self) -> FrequencySpec {
        self.model
            .as_ref()
            .map_or(self.rod.frequency, |m| m.frequency)
    }

    /// [`Scene::frequency`] resolved for a structure whose first natural frequency is
    /// `omega_1` (the structure holds no frequency; the runs take this one).
    pub fn omega(&self, omega_1: f64) -> f64 {
        self.frequency().omega(omega_1)
    }
}

#[cfg(test)]
mod tests;
