//! Studies: one scene and what varies, each case a solve, a sweep or a solutions run.
//!
//! A study file (TOML) names what varies by scene keys (the keys of `--set`):
//!
//! ```toml
//! run = "solve"                      # or "sweep", "solutions"
//! [grid]                             # every combination (keys in alphabetical order, the first slowest)
//! "contact.gap" = [0.5, 1.0]
//! [[case]]                           # a list of cases (each combined with every grid point)
//! "forcing.amplitude" = 0.02
//! [random]                           # seeded samples (each combined with every case above)
//! samples = 200
//! seed = 2026
//! [random.keys."damping.zeta"]
//! distribution = "normal"            # or "uniform" (low, high)
//! mean = 0.01
//! std = 0.002
//! # size = 100                       # a list of 100 values per sample, for a key that takes a
//! #                                  # list (absent: one number)
//! ```
//!
//! Cases are numbered from 0: the grid point outermost, then the listed case, then the
//! random sample. Sample `s` draws from the ChaCha12 stream `s` of the seed, so every grid
//! point and listed case sees the same random values (common random numbers: a difference
//! between two gaps is not blurred by different samples), and a case's values depend only
//! on the study file and its number, never on the shard or thread that runs it.

#[cfg(feature = "cli")]
pub mod command;
pub mod run;
pub mod table;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use rand::SeedableRng;
use rand_distr::Distribution;
use serde::Deserialize;

use crate::input_file::{read_input_file, FileKind, InputFileError};
use crate::scene::{normal_key, Override};
use crate::source::SceneSource;

/// What each case of a study runs (`run = "..."`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum RunKind {
    /// `ssn solve`: one periodic response at the scene's frequency.
    #[default]
    Solve,
    /// `ssn sweep`: the frequency response over the scene's `[sweep]`.
    Sweep,
    /// `ssn solutions`: every periodic solution at the scene's frequency.
    Solutions,
}

impl RunKind {
    /// The study file's spelling.
    pub fn name(self) -> &'static str {
        match self {
            RunKind::Solve => "solve",
            RunKind::Sweep => "sweep",
            RunKind::Solutions => "solutions",
        }
    }

    /// The kind named `name` (`solve`, `sweep`, `solutions`).
    pub fn from_name(name: &str) -> Option<RunKind> {
        [RunKind::Solve, RunKind::Sweep, RunKind::Solutions]
            .into_iter()
            .find(|k| k.name() == name)
    }
}

/// One case: its number and the scene keys it sets, in study order.
#[derive(Debug, Clone, PartialEq)]
pub struct Case {
    /// Number of the case (from 0, study order).
    pub index: usize,
    /// The scene keys it sets and their values.
    pub values: Vec<Override>,
}

impl Case {
    /// The values as a JSON object (key to value).
    pub fn values_json(&self) -> serde_json::Value {
        serde_json::Value::Object(
            self.values
                .iter()
                .map(|o| (o.key.clone(), toml_to_json(&o.value)))
                .collect(),
        )
    }
}

/// A TOML value as JSON (datetimes as their text).
pub fn toml_to_json(v: &toml::Value) -> serde_json::Value {
    match v {
        toml::Value::String(s) => s.clone().into(),
        toml::Value::Integer(i) => (*i).into(),
        toml::Value::Float(f) => crate::json::finite_or_null(*f),
        toml::Value::Boolean(b) => (*b).into(),
        toml::Value::Datetime(d) => d.to_string().into(),
        toml::Value::Array(a) => a.iter().map(toml_to_json).collect(),
        toml::Value::Table(t) => serde_json::Value::Object(
            t.iter()
                .map(|(k, v)| (k.clone(), toml_to_json(v)))
                .collect(),
        ),
    }
}

/// A validated study: what each case runs and the cases.
#[derive(Debug, Clone, PartialEq)]
pub struct Study {
    /// The study file (`<built-in>` for studies built in code).
    pub path: PathBuf,
    /// What each case runs.
    pub run: RunKind,
    /// The cases in study order.
    pub cases: Vec<Case>,
    /// The varied keys in table order (grid, listed cases, random), each once.
    pub keys: Vec<String>,
}

/// Why a study file could not be used: the file, the key, the value, what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum StudyError {
    /// The file could not be read, is not TOML of the study's keys, or has a bad value.
    #[error(transparent)]
    File(#[from] InputFileError),
    /// A case makes the scene invalid (the scene's own message).
    #[error("{path}: case {case} ({values}) makes the scene invalid: {message}")]
    Case {
        /// The study file.
        path: PathBuf,
        /// The case number.
        case: usize,
        /// Its values, as `key=value` words.
        values: String,
        /// The scene's message.
        message: String,
    },
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStudy {
    #[serde(default)]
    run: RunKind,
    grid: Option<toml::Table>,
    case: Option<Vec<toml::Table>>,
    random: Option<RawRandom>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRandom {
    samples: i64,
    seed: i64,
    keys: BTreeMap<String, RawDistribution>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, tag = "distribution", rename_all = "lowercase")]
enum RawDistribution {
    Normal {
        mean: Option<f64>,
        std: f64,
        size: Option<i64>,
    },
    Uniform {
        low: f64,
        high: f64,
        size: Option<i64>,
    },
}

/// Largest number of cases in one study (each is validated before any runs, and leaves a
/// record file).
pub const MAX_CASES: usize = 1_000_000;
/// Largest number of values in all the cases of a study (cases times the values each
/// sets, a list of `size` counting `size`): the cases are held in memory.
pub const MAX_VALUES: usize = 10_000_000;
/// Largest number of random values per key and sample.
pub const MAX_SAMPLE_SIZE: usize = 100_000;

/// A distribution checked: draws one number.
enum Draw {
    Normal(rand_distr::Normal<f64>),
    Uniform(rand_distr::Uniform<f64>),
}

impl Study {
    /// Reads and validates a study file; every case is checked against `scene` (its scene
    /// is validated, nothing is solved), so a bad case is refused before any case runs.
    pub fn from_path(path: &Path, scene: &SceneSource) -> Result<Study, StudyError> {
        let text = read_input_file(path, FileKind::Study)?;
        Study::from_toml(&text, path, scene)
    }

    /// Parses and validates study text (`path` only names it in messages).
    pub fn from_toml(text: &str, path: &Path, scene: &SceneSource) -> Result<Study, StudyError> {
        let raw: RawStudy = toml::from_str(text)
            .map_err(|e| InputFileError::parse(path, e.to_string().trim_end()))?;
        let grid = parse_grid(path, raw.grid.unwrap_or_default())?;
        let listed = parse_listed(path, raw.case)?;
        let random = raw.random.map(|r| parse_random(path, r)).transpose()?;
        let keys = distinct_keys(path, &grid, &listed, random.as_ref())?;
        let samples = random.as_ref().map_or(1, |r| r.samples);
        let total = case_count(path, &grid, listed.len(), samples)?;
        let per_case = grid.len()
            + listed.iter().map(Vec::len).max().unwrap_or(0)
            + random.as_ref().map_or(0, |r| {
                r.draws.iter().map(|(.., size)| size.unwrap_or(1)).sum()
            });
        if total.saturating_mul(per_case) > MAX_VALUES {
            return Err(invalid(
                path,
                "random",
                format!(
                    "{total} cases x {per_case} values = {} values",
                    total as u128 * per_case as u128
                ),
                &format!(
                    "at most {MAX_VALUES} values in all (fewer samples or cases, a smaller \
                     size, or the study split into several files)"
                ),
            ));
        }
        // The random values of each sample, drawn once.
        let sampled = random
            .as_ref()
            .map_or_else(|| vec![Vec::new()], Random::values);
        let cases = combine(path, &grid, &listed, &sampled, total)?;
        for case in &cases {
            check_case(path, scene, case, raw.run)?;
        }
        Ok(Study {
            path: path.to_path_buf(),
            run: raw.run,
            cases,
            keys,
        })
    }
}

/// Checks that `case` makes a valid scene for `run` (validated, nothing solved): a sweep
/// needs the scene's `[sweep]`.
fn check_case(
    path: &Path,
    scene: &SceneSource,
    case: &Case,
    run: RunKind,
) -> Result<(), StudyError> {
    let refused = |message: String| StudyError::Case {
        path: path.to_path_buf(),
        case: case.index,
        values: words(&case.values),
        message,
    };
    let resolved = scene
        .with(&case.values)
        .scene()
        .map_err(|e| refused(e.to_string()))?;
    if run == RunKind::Sweep && resolved.sweep.is_none() {
        return Err(refused(format!(
            "run = \"sweep\" needs the scene's [sweep] section: add omega_ratio_from and \
             omega_ratio_to (units of omega_1) to {}, or vary sweep.omega_ratio_from and \
             sweep.omega_ratio_to",
            scene.path.display()
        )));
    }
    Ok(())
}

/// The varied keys in table order (grid, listed cases, random), each once and with the
/// spaces around its parts removed; a key named in two places (the grid and a listed case,
/// twice in one table under two spellings, ...) is refused, since one would silently
/// replace the other's values.
fn distinct_keys(
    path: &Path,
    grid: &[(String, Vec<toml::Value>)],
    listed: &[Pairs],
    random: Option<&Random>,
) -> Result<Vec<String>, StudyError> {
    let mut places: Vec<(String, String)> = Vec::new();
    let mut claim = |key: &str, place: String, shared: bool| -> Result<(), StudyError> {
        let normal = Override::new(key, toml::Value::Boolean(true))
            .map_err(|e| {
                let allowed = e.reason.trim_start_matches("allowed ");
                invalid(path, &place, e.text, allowed)
            })?
            .key;
        if let Some((_, first)) = places.iter().find(|(k, _)| *k == normal) {
            if !(shared && *first == place) {
                return Err(invalid(
                    path,
                    &format!("{place} \"{key}\""),
                    format!("the scene key {normal}, also in {first}"),
                    "each scene key in one place: [grid], [[case]] tables or [random.keys]",
                ));
            }
            return Ok(());
        }
        places.push((normal, place));
        Ok(())
    };
    for (key, _) in grid {
        claim(key, "[grid]".into(), false)?;
    }
    for table in listed {
        let mut in_table: Vec<String> = Vec::new();
        for (key, _) in table {
            let normal = normal_key(key);
            if in_table.contains(&normal) {
                return Err(invalid(
                    path,
                    &format!("[[case]] \"{key}\""),
                    format!("the scene key {normal} twice in one table"),
                    "each scene key once per [[case]] table",
                ));
            }
            in_table.push(normal);
            claim(key, "[[case]]".into(), true)?;
        }
    }
    for (key, ..) in random.map_or(&[][..], |r| &r.draws[..]) {
        claim(key, "[random.keys]".into(), false)?;
    }
    Ok(places.into_iter().map(|(k, _)| k).collect())
}

/// The number of cases, `grid points x listed cases x samples`, refused above
/// [`MAX_CASES`] with the exact count (a grid's size can exceed any integer type).
fn case_count(
    path: &Path,
    grid: &[(String, Vec<toml::Value>)],
    listed: usize,
    samples: usize,
) -> Result<usize, StudyError> {
    let factors = || grid.iter().map(|(_, v)| v.len()).chain([listed, samples]);
    factors()
        .try_fold(1usize, usize::checked_mul)
        .filter(|&n| n <= MAX_CASES)
        .ok_or_else(|| {
            let points = exact_product(grid.iter().map(|(_, v)| v.len()));
            invalid(
                path,
                "grid",
                format!(
                    "{points} grid points x {listed} cases x {samples} samples = {} cases",
                    exact_product(factors())
                ),
                &format!("at most {MAX_CASES} cases in all"),
            )
        })
}

/// The exact decimal product of `factors`, in base-10^9 limbs (least significant first).
fn exact_product(factors: impl IntoIterator<Item = usize>) -> String {
    const BASE: u128 = 1_000_000_000;
    let mut limbs: Vec<u128> = vec![1];
    for f in factors {
        let mut carry = 0u128;
        for limb in &mut limbs {
            let v = *limb * f as u128 + carry;
            *limb = v % BASE;
            carry = v / BASE;
        }
        while carry > 0 {
            limbs.push(carry % BASE);
            carry /= BASE;
        }
    }
    let mut text = limbs.last().copied().unwrap_or(0).to_string();
    for limb in limbs.iter().rev().skip(1) {
        text += &format!("{limb:09}");
    }
    text
}

/// The error of the study file `path` whose `key` has `value`, with what is `allowed`.
fn invalid(path: &Path, key: &str, value: String, allowed: &str) -> StudyError {
    StudyError::from(InputFileError::invalid(path, key, value, allowed))
}

/// Scene keys and their values, in study order.
type Pairs = Vec<(String, toml::Value)>;

/// The study's `[grid]`: a non-empty list of values per key, in key order.
fn parse_grid(
    path: &Path,
    grid: toml::Table,
) -> Result<Vec<(String, Vec<toml::Value>)>, StudyError> {
    let mut parsed = Vec::new();
    for (key, values) in grid {
        let key_name = format!("grid.\"{key}\"");
        let toml::Value::Array(values) = values else {
            return Err(invalid(
                path,
                &key_name,
                values.to_string(),
                "a non-empty list of values, e.g. [0.5, 1.0]",
            ));
        };
        if values.is_empty() {
            return Err(invalid(
                path,
                &key_name,
                "[]".into(),
                "a non-empty list of values",
            ));
        }
        parsed.push((key, values));
    }
    Ok(parsed)
}

/// The study's `[[case]]` tables (one case without values when there are none).
fn parse_listed(path: &Path, cases: Option<Vec<toml::Table>>) -> Result<Vec<Pairs>, StudyError> {
    match cases {
        Some(cases) if cases.is_empty() => Err(invalid(
            path,
            "case",
            "an empty list".into(),
            "[[case]] tables of scene keys",
        )),
        Some(cases) => Ok(cases.into_iter().map(|t| t.into_iter().collect()).collect()),
        None => Ok(vec![Vec::new()]),
    }
}

/// The study's `[random]` checked: the samples, the seed and each key's distribution and
/// size (`None`: one number), in key order.
struct Random {
    samples: usize,
    seed: u64,
    draws: Vec<(String, Draw, Option<usize>)>,
}

impl Random {
    /// The random values of each sample: sample `s` draws from stream `s` of the seed.
    fn values(&self) -> Vec<Pairs> {
        (0..self.samples)
            .map(|s| {
                let mut rng = rand_chacha::ChaCha12Rng::seed_from_u64(self.seed);
                rng.set_stream(s as u64);
                self.draws
                    .iter()
                    .map(|(key, draw, size)| {
                        let mut one = || match draw {
                            Draw::Normal(d) => d.sample(&mut rng),
                            Draw::Uniform(d) => d.sample(&mut rng),
                        };
                        let value = match size {
                            Some(n) => toml::Value::Array(
                                (0..*n).map(|_| toml::Value::Float(one())).collect(),
                            ),
                            None => toml::Value::Float(one()),
                        };
                        (key.clone(), value)
                    })
                    .collect()
            })
            .collect()
    }
}

/// The study's `[random]` checked.
fn parse_random(path: &Path, r: RawRandom) -> Result<Random, StudyError> {
    let samples = usize::try_from(r.samples)
        .ok()
        .filter(|s| (1..=MAX_CASES).contains(s))
        .ok_or_else(|| {
            invalid(
                path,
                "random.samples",
                r.samples.to_string(),
                &format!("an integer in 1..={MAX_CASES}"),
            )
        })?;
    if r.keys.is_empty() {
        return Err(invalid(
            path,
            "random.keys",
            "an empty table".into(),
            "[random.keys.\"KEY\"] tables with a distribution",
        ));
    }
    let mut draws = Vec::new();
    for (key, d) in r.keys {
        let (draw, size) = parse_draw(path, &key, d)?;
        draws.push((key, draw, size));
    }
    Ok(Random {
        samples,
        seed: r.seed as u64,
        draws,
    })
}

/// The distribution of the random key `key` checked, and its size (`None`: one number).
fn parse_draw(
    path: &Path,
    key: &str,
    d: RawDistribution,
) -> Result<(Draw, Option<usize>), StudyError> {
    let name = |field: &str| format!("random.keys.\"{key}\".{field}");
    let (draw, size) = match d {
        RawDistribution::Normal { mean, std, size } => {
            let mean = mean.unwrap_or(0.0);
            if !mean.is_finite() {
                return Err(invalid(
                    path,
                    &name("mean"),
                    mean.to_string(),
                    "a finite number",
                ));
            }
            let normal = rand_distr::Normal::new(mean, std)
                .ok()
                .filter(|_| std.is_finite() && std >= 0.0)
                .ok_or_else(|| {
                    invalid(path, &name("std"), std.to_string(), "a finite number >= 0")
                })?;
            (Draw::Normal(normal), size)
        }
        RawDistribution::Uniform { low, high, size } => {
            let uniform = rand_distr::Uniform::new(low, high)
                .ok()
                .filter(|_| low.is_finite() && high.is_finite())
                .ok_or_else(|| {
                    invalid(
                        path,
                        &name("high"),
                        high.to_string(),
                        &format!("a finite number > low ({low})"),
                    )
                })?;
            (Draw::Uniform(uniform), size)
        }
    };
    let size = size
        .map(|s| {
            usize::try_from(s)
                .ok()
                .filter(|s| (1..=MAX_SAMPLE_SIZE).contains(s))
                .ok_or_else(|| {
                    invalid(
                        path,
                        &name("size"),
                        s.to_string(),
                        &format!("an integer in 1..={MAX_SAMPLE_SIZE} (absent: one number)"),
                    )
                })
        })
        .transpose()?;
    Ok((draw, size))
}

/// The cases in study order: each grid point (mixed radix, the first key slowest) with
/// each listed case and each sample (each key in one place: [`distinct_keys`]).
fn combine(
    path: &Path,
    grid: &[(String, Vec<toml::Value>)],
    listed: &[Pairs],
    sampled: &[Pairs],
    total: usize,
) -> Result<Vec<Case>, StudyError> {
    let grid_points: usize = grid.iter().map(|(_, v)| v.len()).product();
    let mut cases = Vec::with_capacity(total);
    for point in 0..grid_points {
        // Mixed radix, the first key slowest.
        let mut rest = point;
        let mut grid_values = vec![None; grid.len()];
        for (slot, (_, values)) in grid_values.iter_mut().zip(grid).rev() {
            *slot = Some(values[rest % values.len()].clone());
            rest /= values.len();
        }
        for listed_case in listed {
            for sample in sampled {
                let mut values: Vec<Override> = Vec::new();
                let pairs = grid
                    .iter()
                    .map(|(k, _)| k.clone())
                    .zip(grid_values.iter().map(|v| v.clone().expect("set above")))
                    .chain(listed_case.iter().cloned())
                    .chain(sample.iter().cloned());
                for (key, value) in pairs {
                    let o = Override::new(&key, value)
                        .map_err(|e| invalid(path, &key, e.text.clone(), &e.reason))?;
                    values.push(o);
                }
                cases.push(Case {
                    index: cases.len(),
                    values,
                });
            }
        }
    }
    Ok(cases)
}

/// Overrides as `key=value` words (long lists shortened).
pub fn words(values: &[Override]) -> String {
    values
        .iter()
        .map(|o| match &o.value {
            toml::Value::Array(a) if a.len() > 4 => format!("{}=[{} values]", o.key, a.len()),
            _ => o.to_string(),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

#[cfg(test)]
mod tests;
