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

use crate::import::{ContactDirection, DofContact, ModelSpec};
use crate::rod::{DampingSpec, FrequencySpec, LoadKind, MassModel, RodContact, RodSpec};

mod check;
mod linear_solver;
pub use linear_solver::LinearSolverChoice;

pub use crate::lcp::LcpScheme;

/// Why a scene could not be used. Every variant names the file; `Invalid` also names the
/// key, the value found and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{path}: cannot read scene: {source}")]
    Io {
        /// The scene file.
        path: PathBuf,
        /// The system error.
        source: std::io::Error,
    },
    /// Malformed TOML, an unknown key, a wrong type or a missing required key.
    #[error("{path}: {message}")]
    Parse {
        /// The scene file.
        path: PathBuf,
        /// The parser's message (with line and column, key and expected type).
        message: String,
    },
    /// A value of the right type outside its allowed range, or conflicting keys.
    #[error("{path}: invalid `{key}` = {value}: allowed {allowed}")]
    Invalid {
        /// The scene file.
        path: PathBuf,
        /// The offending key, as `section.key`.
        key: String,
        /// The value found.
        value: String,
        /// What is allowed.
        allowed: String,
    },
}

/// Solution method of a scene (`[solver] method`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Harmonic balance with exact contact as the Lipschitz equation, semismooth Newton
    /// (the paper).
    #[default]
    SsnHb,
    /// Harmonic balance with a penalty contact law `lambda = -k_p max(0, G u - g)`.
    PenaltyHb,
    /// Periodic time-domain LCP solved by Lemke's algorithm.
    LcpLemke,
    /// Periodic time-domain LCP `min(z, q + A z) = 0` solved by semismooth Newton.
    LcpSsn,
    /// Time marching to the steady state (the reference).
    March,
}

impl Method {
    /// The scene spelling of the method.
    pub fn name(self) -> &'static str {
        match self {
            Method::SsnHb => "ssn-hb",
            Method::PenaltyHb => "penalty-hb",
            Method::LcpLemke => "lcp-lemke",
            Method::LcpSsn => "lcp-ssn",
            Method::March => "march",
        }
    }

    /// Whether the method represents the response by harmonics.
    pub fn is_harmonic_balance(self) -> bool {
        matches!(self, Method::SsnHb | Method::PenaltyHb)
    }

    /// Whether the method solves the periodic LCP.
    pub fn is_lcp(self) -> bool {
        matches!(self, Method::LcpLemke | Method::LcpSsn)
    }
}

/// Globalization of the Newton iterations.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum GlobalizationChoice {
    /// Full Newton steps.
    None,
    /// Armijo backtracking on `0.5 |F|^2`.
    Armijo,
    /// Non-monotone (Grippo–Lampariello–Lucidi) line search.
    Nonmonotone,
    /// Full steps for 30 iterations (active-set behaviour), then the non-monotone line
    /// search from the initial guess.
    Hybrid,
    /// Full steps for 30 iterations, then the Newton homotopy from the initial guess, then
    /// the non-monotone line search; the report names the strategy that converged.
    #[default]
    Auto,
}

/// Default number of harmonics.
pub const DEFAULT_HARMONICS: usize = 20;
/// Default number of LCP time steps per period.
pub const DEFAULT_LCP_TIME_SAMPLES: usize = 256;
/// Default penalty stiffness, relative to the contact stiffness scale `K[tip, tip]`.
pub const DEFAULT_RELATIVE_PENALTY: f64 = 1e5;

/// Default AFT sample count for `H` harmonics: the next power of two >= max(64, 4 (2H + 1)).
pub fn default_hb_time_samples(harmonics: usize) -> usize {
    (4 * (2 * harmonics + 1)).max(64).next_power_of_two()
}

/// Validated solver settings (`[solver]`), defaults filled in.
#[derive(Debug, Clone, PartialEq)]
pub struct SolverSettings {
    /// Method.
    pub method: Method,
    /// Number of harmonics `H` (harmonic-balance methods).
    pub harmonics: usize,
    /// AFT samples (HB) or time steps per period (LCP).
    pub time_samples: usize,
    /// Complementarity constant `c`; `None`: the contact stiffness scale.
    pub c: Option<f64>,
    /// Penalty stiffness `k_p` (absolute); `None`: 1e5 times the contact stiffness scale.
    pub penalty_stiffness: Option<f64>,
    /// Linear solver for HB Newton systems.
    pub linear_solver: LinearSolverChoice,
    /// Newton iteration limit.
    pub max_iterations: usize,
    /// Newton globalization.
    pub globalization: GlobalizationChoice,
    /// Absolute tolerance on the residual 2-norm (Newton methods).
    pub tolerance: f64,
    /// Time-marching steps per period.
    pub steps_per_period: usize,
    /// Time-marching period limit.
    pub max_periods: usize,
    /// Time-marching period-to-period tolerance.
    pub march_tolerance: f64,
    /// Restitution coefficient of the Moreau–Jean scheme (massive contact nodes).
    pub restitution: f64,
    /// Time discretisation of the periodic LCP (`lcp-lemke`, `lcp-ssn`).
    pub lcp_scheme: LcpScheme,
}

/// Validated sweep settings (`[sweep]`).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSettings {
    /// Start of the sweep, in units of omega_1.
    pub omega_ratio_from: f64,
    /// End of the sweep, in units of omega_1.
    pub omega_ratio_to: f64,
    /// Initial arclength step.
    pub step: f64,
    /// Smallest step before giving up.
    pub min_step: f64,
    /// Largest step.
    pub max_step: f64,
    /// Point limit.
    pub max_points: usize,
}

impl SweepSettings {
    /// A sweep from `omega_ratio_from` to `omega_ratio_to` (units of omega_1) with the
    /// scene defaults: `step = 0.01`, `min_step = 1e-5`, `max_step = 0.05`,
    /// `max_points = 2000` (not validated; the sweep checks).
    pub fn new(omega_ratio_from: f64, omega_ratio_to: f64) -> Self {
        Self {
            omega_ratio_from,
            omega_ratio_to,
            step: 0.01,
            min_step: 1e-5,
            max_step: 0.05,
            max_points: 2000,
        }
    }
}

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
    /// `[output] dof`, 0-based: the dof that `tip_*` outputs and plots describe (default: the
    /// rod's tip; for a `[model]` scene the first contact dof).
    pub output_dof: Option<usize>,
    /// Solver settings.
    pub solver: SolverSettings,
    /// Frequency sweep, if declared.
    pub sweep: Option<SweepSettings>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawScene {
    title: Option<String>,
    rod: Option<RawRod>,
    model: Option<RawModel>,
    damping: Option<RawDamping>,
    forcing: RawForcing,
    contact: Option<RawContact>,
    output: Option<RawOutput>,
    #[serde(default)]
    solver: RawSolver,
    sweep: Option<RawSweep>,
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
    mass: String,
    stiffness: String,
    damping: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOutput {
    dof: i64,
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

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawForcing {
    load: Option<RawLoad>,
    vector: Option<String>,
    amplitude: f64,
    omega_ratio: Option<f64>,
    omega: Option<f64>,
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
    dof: Option<i64>,
    gap: f64,
    direction: Option<i64>,
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
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSweep {
    omega_ratio_from: f64,
    omega_ratio_to: f64,
    step: Option<f64>,
    min_step: Option<f64>,
    max_step: Option<f64>,
    max_points: Option<i64>,
}

/// Largest harmonic count accepted.
pub const MAX_HARMONICS: usize = 2000;
/// Largest sample / step count accepted.
pub const MAX_TIME_SAMPLES: usize = 1 << 20;
/// Largest accepted magnitude of a forcing amplitude or a gap: the response scales with
/// them, and a residual's square must stay below the largest double (1.8e308).
pub const MAX_RESPONSE_SCALE: f64 = 1e100;

impl Scene {
    /// Reads and validates a scene file (a regular file of at most
    /// [`crate::io::SCENE_SIZE_LIMIT`] bytes).
    pub fn from_path(path: impl AsRef<Path>) -> Result<Scene, SceneError> {
        let path = path.as_ref();
        // Only a regular file of at most 1 MiB: a FIFO would block, a device never end.
        let text =
            crate::io::read_regular_file(path, crate::io::SCENE_SIZE_LIMIT).map_err(|source| {
                SceneError::Io {
                    path: path.to_path_buf(),
                    source,
                }
            })?;
        Scene::from_toml(&text, path)
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
                message
            })
            .map_err(|message| SceneError::Parse {
                path: path.to_path_buf(),
                message,
            })?;
        check::resolve(raw, path)
    }
}

#[cfg(test)]
mod tests;
