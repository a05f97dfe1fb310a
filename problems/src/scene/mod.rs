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

mod linear_solver;
pub use linear_solver::LinearSolverChoice;

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

struct Check<'a> {
    path: &'a Path,
}

impl Check<'_> {
    fn invalid(&self, key: &str, value: impl ToString, allowed: &str) -> SceneError {
        SceneError::Invalid {
            path: self.path.to_path_buf(),
            key: key.to_string(),
            value: value.to_string(),
            allowed: allowed.to_string(),
        }
    }

    fn positive(&self, key: &str, v: f64) -> Result<f64, SceneError> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(self.invalid(key, v, "a finite number > 0"))
        }
    }

    fn non_negative(&self, key: &str, v: f64) -> Result<f64, SceneError> {
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            Err(self.invalid(key, v, "a finite number >= 0"))
        }
    }

    /// A length or force of the response: `|v| <= MAX_RESPONSE_SCALE`, so that residuals
    /// and their squares (merit functions) stay finite.
    fn response_scale(&self, key: &str, v: f64) -> Result<f64, SceneError> {
        if v.is_finite() && v.abs() <= MAX_RESPONSE_SCALE {
            Ok(v)
        } else {
            Err(self.invalid(
                key,
                format!("{v:e}"),
                "a finite number with |value| <= 1e100",
            ))
        }
    }

    fn count(&self, key: &str, v: i64, min: usize, max: usize) -> Result<usize, SceneError> {
        if v >= min as i64 && v <= max as i64 {
            Ok(v as usize)
        } else {
            Err(self.invalid(key, v, &format!("an integer in {min}..={max}")))
        }
    }

    /// `count` of `v` when given, else `default`.
    fn count_or(
        &self,
        key: &str,
        v: Option<i64>,
        min: usize,
        max: usize,
        default: usize,
    ) -> Result<usize, SceneError> {
        v.map_or(Ok(default), |v| self.count(key, v, min, max))
    }
}

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
        resolve(raw, path)
    }
}

/// Validates a parsed scene section by section, in file order; the first invalid value is
/// the error.
fn resolve(raw: RawScene, path: &Path) -> Result<Scene, SceneError> {
    let ck = Check { path };
    let (rod, model, output_dof) = match (&raw.rod, raw.model) {
        (Some(raw_rod), None) => {
            let mut rod = ck.rod(raw_rod)?;
            if raw.forcing.vector.is_some() {
                return Err(ck.invalid(
                    "forcing.vector",
                    "given in a [rod] scene",
                    "`load` (\"distributed\" or \"tip\"); `vector` belongs to [model] scenes",
                ));
            }
            rod.damping = raw.damping.map(|d| ck.damping(&d)).transpose()?;
            (rod.load, rod.amplitude, rod.frequency) = ck.forcing(&raw.forcing)?;
            if let Some(c) = raw.contact {
                rod.contacts = ck.contacts(c, rod.elements)?;
            }
            let output_dof = raw
                .output
                .map(|o| ck.count("output.dof", o.dof, 1, rod.elements))
                .transpose()?
                .map(|dof| dof - 1);
            (rod, None, output_dof)
        }
        (None, Some(m)) => {
            let model = ck.model(m, raw.damping, &raw.forcing, raw.contact, raw.output)?;
            let output_dof = model.observed_dof;
            (RodSpec::canonical(), Some(model), output_dof)
        }
        (Some(_), Some(_)) => {
            return Err(ck.invalid(
                "model",
                "given together with [rod]",
                "either [rod] (the built-in rod) or [model] (Matrix Market files)",
            ))
        }
        (None, None) => {
            return Err(ck.invalid(
                "rod",
                "missing",
                "a [rod] section (the built-in rod) or a [model] section (Matrix Market files)",
            ))
        }
    };
    // An LCP without contact is empty: allowed, solved as the linear response.
    let solver = ck.solver(&raw.solver)?;
    let contacts = model
        .as_ref()
        .map_or(rod.contacts.len(), |m| m.contacts.len());
    ck.lcp_size(&solver, contacts, raw.solver.time_samples.is_some())?;
    let sweep = raw.sweep.map(|sw| ck.sweep(&sw)).transpose()?;
    Ok(Scene {
        path: path.to_path_buf(),
        title: raw.title,
        rod,
        model,
        output_dof,
        solver,
        sweep,
    })
}

impl Check<'_> {
    /// `[rod]`: the mesh and the material; the other sections fill in damping, forcing and
    /// contacts (none until they do).
    fn rod(&self, r: &RawRod) -> Result<RodSpec, SceneError> {
        let spec = RodSpec {
            elements: self.count("rod.elements", r.elements, 1, crate::rod::MAX_ELEMENTS)?,
            length: self.positive("rod.length", r.length.unwrap_or(1.0))?,
            axial_stiffness: self
                .positive("rod.axial_stiffness", r.axial_stiffness.unwrap_or(1.0))?,
            mass_per_length: self
                .positive("rod.mass_per_length", r.mass_per_length.unwrap_or(1.0))?,
            mass: match r.mass {
                RawMass::Consistent => MassModel::Consistent,
                RawMass::Lumped => MassModel::Lumped,
                RawMass::Modified => MassModel::Modified,
            },
            damping: None,
            load: LoadKind::Distributed,
            amplitude: 0.0,
            frequency: FrequencySpec::Ratio(1.0),
            contacts: Vec::new(),
        };
        self.rod_scales(&spec)?;
        Ok(spec)
    }

    /// The rod must vibrate at a representable frequency: the modified mass needs a node
    /// with mass besides the massless tip, and the element length `h = L / elements`, the
    /// element stiffness `EA / h`, mass `rhoA h` and the first frequency
    /// `(pi / 2) sqrt(EA / rhoA) / L` must stay within `[1e-100, 1e100]` (far inside
    /// floating point, so that squares and products of them neither overflow nor vanish).
    fn rod_scales(&self, s: &RodSpec) -> Result<(), SceneError> {
        if s.mass == MassModel::Modified && s.elements < 2 {
            return Err(self.invalid(
                "rod.elements",
                format!("{} with mass = \"modified\"", s.elements),
                "at least 2 with the modified mass (the tip node is massless, so a one-element \
                 rod has no vibration mode)",
            ));
        }
        let h = s.length / s.elements as f64;
        let omega_1 =
            0.5 * std::f64::consts::PI * (s.axial_stiffness / s.mass_per_length).sqrt() / s.length;
        let in_range = |v: f64| (1e-100..=1e100).contains(&v);
        for (what, v) in [
            ("the element length L / elements", h),
            (
                "the element stiffness EA elements / L",
                s.axial_stiffness / h,
            ),
            ("the element mass rhoA L / elements", s.mass_per_length * h),
            (
                "the first natural frequency (pi / 2) sqrt(EA / rhoA) / L",
                omega_1,
            ),
        ] {
            if !in_range(v) {
                return Err(self.invalid(
                    "rod.length",
                    format!(
                        "{:?} (with axial_stiffness = {:?}, mass_per_length = {:?}, elements = {}: \
                         {what} is {v:e})",
                        s.length, s.axial_stiffness, s.mass_per_length, s.elements
                    ),
                    "length, axial_stiffness and mass_per_length whose element length, element \
                     stiffness, element mass and first natural frequency lie in [1e-100, 1e100]",
                ));
            }
        }
        Ok(())
    }

    /// `[damping]`: stiffness-proportional (`zeta`) or Rayleigh (`alpha`, `beta`), chosen by
    /// `model` or by the keys present.
    fn damping(&self, d: &RawDamping) -> Result<DampingSpec, SceneError> {
        let model = match (d.model, d.zeta, d.alpha, d.beta) {
            (Some(m), _, _, _) => m,
            (None, Some(_), None, None) => RawDampingModel::StiffnessProportional,
            (None, None, a, b) if a.is_some() || b.is_some() => RawDampingModel::Rayleigh,
            (None, None, None, None) => {
                return Err(self.invalid(
                    "damping",
                    "an empty section",
                    "`zeta` (stiffness-proportional) or `alpha`/`beta` (Rayleigh); omit [damping] for none",
                ))
            }
            _ => {
                return Err(self.invalid(
                    "damping.zeta",
                    "given together with alpha/beta",
                    "either `zeta` (model = \"stiffness-proportional\") or `alpha`/`beta` (model = \"rayleigh\")",
                ))
            }
        };
        match model {
            RawDampingModel::StiffnessProportional => {
                if d.alpha.is_some() || d.beta.is_some() {
                    return Err(self.invalid(
                        "damping.alpha",
                        "given with model = \"stiffness-proportional\"",
                        "only `zeta` for this model",
                    ));
                }
                let zeta = d.zeta.ok_or_else(|| {
                    self.invalid(
                        "damping.zeta",
                        "missing",
                        "a finite number >= 0 (required by model = \"stiffness-proportional\")",
                    )
                })?;
                Ok(DampingSpec::StiffnessProportional {
                    zeta: self.non_negative("damping.zeta", zeta)?,
                })
            }
            RawDampingModel::Rayleigh => {
                if d.zeta.is_some() {
                    return Err(self.invalid(
                        "damping.zeta",
                        "given with model = \"rayleigh\"",
                        "only `alpha` and `beta` for this model",
                    ));
                }
                if d.alpha.is_none() && d.beta.is_none() {
                    return Err(self.invalid(
                        "damping.model",
                        "\"rayleigh\" without alpha or beta",
                        "model = \"rayleigh\" with `alpha` and/or `beta` (D = alpha M + beta K); \
                         omit [damping] for no damping",
                    ));
                }
                Ok(DampingSpec::Rayleigh {
                    alpha: self.non_negative("damping.alpha", d.alpha.unwrap_or(0.0))?,
                    beta: self.non_negative("damping.beta", d.beta.unwrap_or(0.0))?,
                })
            }
        }
    }

    /// `[forcing]`: the load, its amplitude and its frequency (`omega_1` by default).
    fn forcing(&self, f: &RawForcing) -> Result<(LoadKind, f64, FrequencySpec), SceneError> {
        let amplitude = self.response_scale("forcing.amplitude", f.amplitude)?;
        let frequency = match (f.omega_ratio, f.omega) {
            (Some(r), None) => FrequencySpec::Ratio(self.positive("forcing.omega_ratio", r)?),
            (None, Some(w)) => FrequencySpec::Absolute(self.positive("forcing.omega", w)?),
            (None, None) => FrequencySpec::Ratio(1.0),
            (Some(_), Some(_)) => {
                return Err(self.invalid(
                    "forcing.omega",
                    "given together with omega_ratio",
                    "either `omega_ratio` (units of omega_1) or `omega` (rad per unit time)",
                ))
            }
        };
        let load = match f.load.unwrap_or_default() {
            RawLoad::Distributed => LoadKind::Distributed,
            RawLoad::Tip => LoadKind::Tip,
        };
        Ok((load, amplitude, frequency))
    }

    /// `[contact]`: one contact (`gap`, at `node` or the tip) or a list of
    /// `[[contact.point]]` at distinct nodes of the `elements`-element rod.
    fn contacts(&self, c: RawContact, elements: usize) -> Result<Vec<RodContact>, SceneError> {
        match (c.gap, c.point) {
            (Some(gap), None) => Ok(vec![RodContact {
                node: self.count_or("contact.node", c.node, 1, elements, elements)?,
                gap: self.response_scale("contact.gap", gap)?,
            }]),
            (None, Some(points)) if c.node.is_none() => {
                if points.is_empty() {
                    return Err(self.invalid(
                        "contact.point",
                        "an empty list",
                        "at least one [[contact.point]] with node and gap",
                    ));
                }
                let mut contacts: Vec<RodContact> = Vec::with_capacity(points.len());
                for p in points {
                    if p.dof.is_some() || p.direction.is_some() {
                        return Err(self.invalid(
                            "contact.point.dof",
                            "given in a [rod] scene",
                            "`node` and `gap` (`dof` and `direction` belong to [model] scenes)",
                        ));
                    }
                    let node = p.node.ok_or_else(|| {
                        self.invalid("contact.point.node", "missing", "an integer node number")
                    })?;
                    let node = self.count("contact.point.node", node, 1, elements)?;
                    if contacts.iter().any(|c| c.node == node) {
                        return Err(self.invalid(
                            "contact.point.node",
                            node,
                            "distinct nodes (one contact per node)",
                        ));
                    }
                    contacts.push(RodContact {
                        node,
                        gap: self.response_scale("contact.point.gap", p.gap)?,
                    });
                }
                Ok(contacts)
            }
            (None, None) => Err(self.invalid(
                "contact",
                "a section without gap",
                "`gap` (and optional `node`) or [[contact.point]] entries; omit [contact] for a linear problem",
            )),
            _ => Err(self.invalid(
                "contact.gap",
                "given together with [[contact.point]] or node",
                "either `gap` (+ optional `node`) or [[contact.point]] entries",
            )),
        }
    }

    /// `[model]` and the sections an imported structure reads: `[damping]` (unless a
    /// damping file is given), `[forcing]` with a load `vector` file, `[[contact.point]]`
    /// with 1-based `dof`, `gap` and `direction` (+1 or -1), `[output] dof`. File names are
    /// relative to the scene's directory; dof upper bounds are checked when the files are
    /// read.
    fn model(
        &self,
        m: RawModel,
        damping: Option<RawDamping>,
        f: &RawForcing,
        contact: Option<RawContact>,
        output: Option<RawOutput>,
    ) -> Result<ModelSpec, SceneError> {
        let dir = self.path.parent().unwrap_or(Path::new(""));
        let file = |key: &str, name: &str| {
            if name.trim().is_empty() {
                Err(self.invalid(
                    key,
                    "\"\"",
                    "a file name (relative to the scene's directory)",
                ))
            } else {
                Ok(dir.join(name))
            }
        };
        let mass = file("model.mass", &m.mass)?;
        let stiffness = file("model.stiffness", &m.stiffness)?;
        let damping_matrix = m.damping.map(|d| file("model.damping", &d)).transpose()?;
        let damping = damping.map(|d| self.damping(&d)).transpose()?;
        if damping_matrix.is_some() && damping.is_some() {
            return Err(self.invalid(
                "damping",
                "a [damping] section together with model.damping",
                "either a damping matrix file or a [damping] section",
            ));
        }
        if f.load.is_some() {
            return Err(self.invalid(
                "forcing.load",
                "given in a [model] scene",
                "`vector` (a Matrix Market file of the load shape, N x 1)",
            ));
        }
        let vector = f.vector.as_deref().ok_or_else(|| {
            self.invalid(
                "forcing.vector",
                "missing",
                "a Matrix Market file of the load shape, N x 1 (relative to the scene)",
            )
        })?;
        let forcing_vector = file("forcing.vector", vector)?;
        let (_, amplitude, frequency) = self.forcing(f)?;
        let contacts = contact
            .map(|c| self.dof_contacts(c))
            .transpose()?
            .unwrap_or_default();
        let observed_dof = output
            .map(|o| self.count("output.dof", o.dof, 1, usize::MAX >> 1))
            .transpose()?
            .map(|dof| dof - 1);
        Ok(ModelSpec {
            scene: self.path.to_path_buf(),
            mass,
            stiffness,
            damping_matrix,
            damping,
            forcing_vector,
            amplitude,
            frequency,
            contacts,
            observed_dof,
        })
    }

    /// `[[contact.point]]` entries of a `[model]` scene: `dof` (1-based), `gap`, `direction`
    /// (+1, the default, or -1); one contact per dof and direction.
    fn dof_contacts(&self, c: RawContact) -> Result<Vec<DofContact>, SceneError> {
        let allowed = "[[contact.point]] entries with dof, gap and optional direction";
        let points = match (c.gap, c.node, c.point) {
            (None, None, Some(points)) if !points.is_empty() => points,
            (None, None, _) => return Err(self.invalid("contact.point", "an empty list", allowed)),
            (Some(_), _, _) => {
                return Err(self.invalid("contact.gap", "given in a [model] scene", allowed))
            }
            (None, Some(_), _) => {
                return Err(self.invalid("contact.node", "given in a [model] scene", allowed))
            }
        };
        let mut contacts: Vec<DofContact> = Vec::with_capacity(points.len());
        for p in points {
            if p.node.is_some() {
                return Err(self.invalid(
                    "contact.point.node",
                    "given in a [model] scene",
                    "`dof` (1-based, as in Matrix Market)",
                ));
            }
            let dof = p.dof.ok_or_else(|| {
                self.invalid("contact.point.dof", "missing", "a 1-based dof number")
            })?;
            let dof = self.count("contact.point.dof", dof, 1, usize::MAX >> 1)? - 1;
            let direction = match p.direction.unwrap_or(1) {
                1 => ContactDirection::Positive,
                -1 => ContactDirection::Negative,
                d => return Err(self.invalid(
                    "contact.point.direction",
                    d,
                    "1 (obstacle on the positive side: u <= gap) or -1 (negative side: -u <= gap)",
                )),
            };
            if contacts
                .iter()
                .any(|c| c.dof == dof && c.direction == direction)
            {
                return Err(self.invalid(
                    "contact.point.dof",
                    dof + 1,
                    "one contact per dof and direction (two contacts on one dof need opposite directions)",
                ));
            }
            contacts.push(DofContact {
                dof,
                gap: self.response_scale("contact.point.gap", p.gap)?,
                direction,
            });
        }
        Ok(contacts)
    }

    /// The periodic LCP's matrix is dense, of order `contacts x time_samples`: that order
    /// must not exceed [`crate::lcp::MAX_LCP_SIZE`], so `solver.time_samples` is refused
    /// above `MAX_LCP_SIZE / contacts` for `lcp-lemke` and `lcp-ssn`.
    fn lcp_size(
        &self,
        solver: &SolverSettings,
        contacts: usize,
        given: bool,
    ) -> Result<(), SceneError> {
        let nt = solver.time_samples;
        if !matches!(solver.method, Method::LcpLemke | Method::LcpSsn)
            || contacts.saturating_mul(nt) <= crate::lcp::MAX_LCP_SIZE
        {
            return Ok(());
        }
        let most = crate::lcp::MAX_LCP_SIZE / contacts;
        let value = if given {
            nt.to_string()
        } else {
            format!("{nt} (the default)")
        };
        let allowed = if most >= 8 {
            format!(
                "an integer in 8..={most} for {} with {contacts} contacts (contacts x \
                 time_samples <= {}: the LCP matrix is dense)",
                solver.method.name(),
                crate::lcp::MAX_LCP_SIZE
            )
        } else {
            format!(
                "none for {} with {contacts} contacts (contacts x time_samples <= {} with \
                 time_samples >= 8: the LCP matrix is dense); use ssn-hb or penalty-hb",
                solver.method.name(),
                crate::lcp::MAX_LCP_SIZE
            )
        };
        Err(self.invalid("solver.time_samples", value, &allowed))
    }

    /// `[solver]`: the method and its discretisation and iteration settings, defaults filled
    /// in (an HB method needs more AFT samples than `2 H`).
    fn solver(&self, s: &RawSolver) -> Result<SolverSettings, SceneError> {
        let method = s.method;
        let harmonics = self.count_or(
            "solver.harmonics",
            s.harmonics,
            1,
            MAX_HARMONICS,
            DEFAULT_HARMONICS,
        )?;
        let time_samples = match (s.time_samples, method.is_harmonic_balance()) {
            (Some(n), true) => {
                let n = self.count("solver.time_samples", n, 1, MAX_TIME_SAMPLES)?;
                if n <= 2 * harmonics {
                    return Err(self.invalid(
                        "solver.time_samples",
                        n,
                        &format!(
                            "an integer > 2 * harmonics = {} (the AFT needs more samples than basis functions)",
                            2 * harmonics
                        ),
                    ));
                }
                n
            }
            (Some(n), false) => self.count("solver.time_samples", n, 8, MAX_TIME_SAMPLES)?,
            (None, true) => default_hb_time_samples(harmonics),
            (None, false) => DEFAULT_LCP_TIME_SAMPLES,
        };
        let c = s.c.map(|c| self.positive("solver.c", c)).transpose()?;
        let penalty_stiffness = s
            .penalty_stiffness
            .map(|k| self.positive("solver.penalty_stiffness", k))
            .transpose()?;
        let max_iterations =
            self.count_or("solver.max_iterations", s.max_iterations, 1, 100_000, 200)?;
        let tolerance = self.positive("solver.tolerance", s.tolerance.unwrap_or(1e-10))?;
        let steps_per_period = self.count_or(
            "solver.steps_per_period",
            s.steps_per_period,
            8,
            MAX_TIME_SAMPLES,
            2000,
        )?;
        let max_periods = self.count_or("solver.max_periods", s.max_periods, 1, 1_000_000, 2000)?;
        let march_tolerance =
            self.positive("solver.march_tolerance", s.march_tolerance.unwrap_or(1e-8))?;
        let restitution = s.restitution.unwrap_or(0.0);
        if !(0.0..=1.0).contains(&restitution) {
            return Err(self.invalid("solver.restitution", restitution, "a number in [0, 1]"));
        }
        Ok(SolverSettings {
            method,
            harmonics,
            time_samples,
            c,
            penalty_stiffness,
            linear_solver: s.linear_solver,
            max_iterations,
            globalization: s.globalization,
            tolerance,
            steps_per_period,
            max_periods,
            march_tolerance,
            restitution,
        })
    }

    /// `[sweep]`: a non-empty frequency interval and arclength steps with
    /// `min_step <= step <= max_step`.
    fn sweep(&self, sw: &RawSweep) -> Result<SweepSettings, SceneError> {
        let from = self.positive("sweep.omega_ratio_from", sw.omega_ratio_from)?;
        let to = self.positive("sweep.omega_ratio_to", sw.omega_ratio_to)?;
        if to == from {
            return Err(self.invalid(
                "sweep.omega_ratio_to",
                to,
                "a value different from omega_ratio_from",
            ));
        }
        let defaults = SweepSettings::new(from, to);
        let step = self.positive("sweep.step", sw.step.unwrap_or(defaults.step))?;
        let min_step = self.positive("sweep.min_step", sw.min_step.unwrap_or(defaults.min_step))?;
        let max_step = self.positive("sweep.max_step", sw.max_step.unwrap_or(defaults.max_step))?;
        if step < min_step || step > max_step {
            return Err(self.invalid(
                "sweep.step",
                step,
                &format!("min_step ({min_step}) <= step <= max_step ({max_step})"),
            ));
        }
        Ok(SweepSettings {
            step,
            min_step,
            max_step,
            max_points: self.count_or(
                "sweep.max_points",
                sw.max_points,
                2,
                1_000_000,
                defaults.max_points,
            )?,
            ..defaults
        })
    }
}

#[cfg(test)]
mod tests;
