//! Scene overrides: `--set key=value` on the command line, `Scene.with_values({...})` in
//! Python and the varied values of a study. An override replaces one key of the parsed TOML
//! document before the scene is validated, so every key, default and error is the scene's
//! own: an unknown key, a wrong type or a value out of range is refused exactly as it would
//! be in the file, with the override named in the message.
//!
//! Keys are dotted paths as in the README's scene table (`forcing.omega_ratio`,
//! `solver.harmonics`); an array of tables is indexed by a number
//! (`contact.point.0.gap`, 0-based). Values are TOML values (`1.1`, `40`, `"ssn-hb"`,
//! `[0.01, -0.02]`); a bare word that is not one (`ssn-hb`) is read as a string. An
//! override of `solver.accuracy` replaces the file's discretisation keys (`harmonics`,
//! `time_samples`, `steps_per_period`): the target chooses them; sweep bounds in one unit
//! (`sweep.frequency_hz_from`) replace the file's bounds in the others.

use std::fmt;
use std::path::Path;

use super::{RawScene, Scene, SceneError};
use crate::input_file::{read_input_file, FileKind};

/// One override: a dotted scene key and the TOML value it takes.
#[derive(Debug, Clone, PartialEq)]
pub struct Override {
    /// The dotted key, as `section.key` (`contact.point.0.gap` into an array of tables).
    pub key: String,
    /// The value.
    pub value: toml::Value,
}

impl fmt::Display for Override {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}={}", self.key, self.value)
    }
}

/// Why an override could not be read (before the scene checks its value).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid override `{text}`: {reason}")]
pub struct OverrideError {
    /// The override as given.
    pub text: String,
    /// What is wrong and what is allowed.
    pub reason: String,
}

/// Most parts of an override's dotted key (the deepest scene key, `friction.point.0.dofs`,
/// has four): a deeper key names nothing and would nest that many tables.
pub const MAX_KEY_PARTS: usize = 8;

impl Override {
    /// An override of `key` by `value`; the key must be a non-empty dotted path of at most
    /// [`MAX_KEY_PARTS`] parts, each trimmed of surrounding spaces.
    pub fn new(key: &str, value: toml::Value) -> Result<Override, OverrideError> {
        let parts = key.split('.').count();
        let shown = |key: &str| {
            if key.chars().count() > 80 {
                format!(
                    "{}... ({parts} parts)",
                    key.chars().take(60).collect::<String>()
                )
            } else {
                key.to_string()
            }
        };
        if parts > MAX_KEY_PARTS {
            return Err(OverrideError {
                text: shown(key),
                reason: format!(
                    "allowed a dotted scene key of at most {MAX_KEY_PARTS} parts (this one \
                     has {parts}) such as forcing.omega_ratio or contact.point.0.gap"
                ),
            });
        }
        let key = normal_key(key);
        if key.split('.').any(str::is_empty) {
            return Err(OverrideError {
                text: format!("{}={value}", shown(&key)),
                reason: "allowed a dotted scene key such as forcing.omega_ratio or \
                         contact.point.0.gap"
                    .into(),
            });
        }
        Ok(Override { key, value })
    }

    /// Reads `key=value` (the form of `--set`): the value as a TOML value, or as a string
    /// when it is a bare word that TOML does not read.
    pub fn parse(text: &str) -> Result<Override, OverrideError> {
        let Some((key, value)) = text.split_once('=') else {
            return Err(OverrideError {
                text: text.to_string(),
                reason: "allowed key=value, e.g. forcing.omega_ratio=1.1".into(),
            });
        };
        Override::new(key, parse_value(value.trim()))
    }
}

/// A dotted key with the spaces around each part removed (` contact . gap` is
/// `contact.gap`): two spellings of one scene key compare equal.
pub fn normal_key(key: &str) -> String {
    key.split('.').map(str::trim).collect::<Vec<_>>().join(".")
}

/// A TOML value from its text; text that is not one is a string.
pub fn parse_value(text: &str) -> toml::Value {
    toml::from_str::<toml::Table>(&format!("value = {text}"))
        .ok()
        .filter(|table| table.len() == 1)
        .and_then(|mut table| table.remove("value"))
        .unwrap_or_else(|| toml::Value::String(text.to_string()))
}

impl Scene {
    /// [`Scene::from_toml`] with `overrides` applied to the document before it is
    /// validated (module documentation). Without overrides this is `from_toml` itself.
    pub fn from_toml_with(
        text: &str,
        path: impl AsRef<Path>,
        overrides: &[Override],
    ) -> Result<Scene, SceneError> {
        Scene::from_toml_noting(text, path, overrides).map(|(scene, _)| scene)
    }

    /// [`Scene::from_toml_with`], and the file's discretisation keys an accuracy override
    /// replaced, as `solver.harmonics = 20` (empty when none was).
    pub fn from_toml_noting(
        text: &str,
        path: impl AsRef<Path>,
        overrides: &[Override],
    ) -> Result<(Scene, Vec<String>), SceneError> {
        let path = path.as_ref();
        if overrides.is_empty() {
            return Scene::from_toml(text, path).map(|scene| (scene, Vec::new()));
        }
        let mut document: toml::Table =
            toml::from_str(text).map_err(|e| SceneError::parse(path, e.to_string().trim_end()))?;
        for o in overrides {
            apply(&mut document, o)
                .map_err(|reason| SceneError::parse(path, format!("--set {o}: {reason}")))?;
        }
        let mut replaced = drop_overridden_discretisation(&mut document, overrides);
        replaced.extend(drop_other_sweep_units(&mut document, overrides));
        let named = overrides
            .iter()
            .map(|o| format!("--set {o}"))
            .collect::<Vec<_>>()
            .join(" ");
        let raw: RawScene = document.try_into().map_err(|e| {
            SceneError::parse(path, format!("with {named}: {}", e.to_string().trim_end()))
        })?;
        super::check::resolve(raw, path).map(|scene| (scene, replaced))
    }

    /// Reads a scene file and applies `overrides` ([`Scene::from_toml_with`]).
    pub fn from_path_with(
        path: impl AsRef<Path>,
        overrides: &[Override],
    ) -> Result<Scene, SceneError> {
        Scene::from_path_noting(path, overrides).map(|(scene, _)| scene)
    }

    /// Reads a scene file and applies `overrides` ([`Scene::from_toml_noting`]).
    pub fn from_path_noting(
        path: impl AsRef<Path>,
        overrides: &[Override],
    ) -> Result<(Scene, Vec<String>), SceneError> {
        let path = path.as_ref();
        let text = read_scene_text(path)?;
        Scene::from_toml_noting(&text, path, overrides)
    }
}

/// The text of a scene file (a regular file of at most [`crate::io::SCENE_SIZE_LIMIT`]
/// bytes).
pub fn read_scene_text(path: &Path) -> Result<String, SceneError> {
    read_input_file(path, FileKind::Scene)
}

/// The `[solver]` keys that fix a discretisation, which an accuracy target chooses itself.
const DISCRETISATION_KEYS: [&str; 3] = ["harmonics", "time_samples", "steps_per_period"];

/// An accuracy target given by override replaces the file's discretisation: the file's
/// `solver.harmonics`, `time_samples` and `steps_per_period` are dropped unless an override
/// sets them too (which the scene then refuses beside the target, as in a file). Returns
/// the keys dropped with their values (`solver.harmonics = 20`).
fn drop_overridden_discretisation(
    document: &mut toml::Table,
    overrides: &[Override],
) -> Vec<String> {
    let key = |o: &Override| {
        o.key
            .split('.')
            .map(str::trim)
            .collect::<Vec<_>>()
            .join(".")
    };
    let keys: Vec<String> = overrides.iter().map(key).collect();
    let mut dropped = Vec::new();
    if !keys.iter().any(|k| k == "solver.accuracy") {
        return dropped;
    }
    if let Some(toml::Value::Table(solver)) = document.get_mut("solver") {
        for name in DISCRETISATION_KEYS {
            if keys.contains(&format!("solver.{name}")) {
                continue;
            }
            if let Some(value) = solver.remove(name) {
                dropped.push(format!("solver.{name} = {value}"));
            }
        }
    }
    dropped
}

/// Sweep bounds given by override in one unit replace the file's bounds in the others
/// (`--set sweep.frequency_hz_from=...` on a scene in ratios): the file's bound keys of the
/// other units are dropped unless an override sets them too (which the scene then refuses,
/// as in a file). Returns the keys dropped with their values.
fn drop_other_sweep_units(document: &mut toml::Table, overrides: &[Override]) -> Vec<String> {
    use super::sweep_units::SWEEP_BOUND_KEYS;
    let keys: Vec<String> = overrides.iter().map(|o| normal_key(&o.key)).collect();
    let overridden = |name: &str| keys.contains(&format!("sweep.{name}"));
    let mut dropped = Vec::new();
    if !SWEEP_BOUND_KEYS
        .iter()
        .flatten()
        .any(|name| overridden(name))
    {
        return dropped;
    }
    if let Some(toml::Value::Table(sweep)) = document.get_mut("sweep") {
        for pair in SWEEP_BOUND_KEYS {
            if pair.iter().any(|name| overridden(name)) {
                continue;
            }
            for name in pair {
                if let Some(value) = sweep.remove(name) {
                    dropped.push(format!("sweep.{name} = {value}"));
                }
            }
        }
    }
    dropped
}

/// Sets `o.key` in `document`, creating the tables on its path; an index into an array of
/// tables must exist. The scene's own checks then judge the key and the value.
fn apply(document: &mut toml::Table, o: &Override) -> Result<(), String> {
    let parts: Vec<&str> = o.key.split('.').map(str::trim).collect();
    let (last, path) = parts.split_last().expect("a non-empty key");
    let mut table = document;
    let mut i = 0;
    while i < path.len() {
        let part = path[i];
        let entry = table
            .entry(part.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        table = match entry {
            toml::Value::Table(t) => t,
            toml::Value::Array(items) => {
                let Some(index) = path.get(i + 1).and_then(|s| s.parse::<usize>().ok()) else {
                    return Err(format!(
                        "`{part}` is a list: allowed {part}.INDEX.KEY with INDEX in 0..{}",
                        items.len()
                    ));
                };
                let count = items.len();
                i += 1;
                match items.get_mut(index) {
                    Some(toml::Value::Table(t)) => t,
                    _ => {
                        return Err(format!(
                            "no entry {index} in `{part}`: allowed an index in 0..{count}"
                        ))
                    }
                }
            }
            other => {
                return Err(format!(
                    "`{part}` is a {}, not a section: allowed keys inside sections",
                    other.type_str()
                ))
            }
        };
        i += 1;
    }
    table.insert((*last).to_string(), o.value.clone());
    Ok(())
}
