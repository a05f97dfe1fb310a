//! Harmonic-balance states as files: `ssn solve SCENE --state OUT.json` writes the
//! solution's coefficients, `ssn solve SCENE --start STATE.json` starts Newton from them,
//! and `ssn solutions --json` carries one such state per solution (pick it with
//! `--start SOLUTIONS.json --entry K`, `K` counted from 1).
//!
//! # The document
//!
//! ```text
//! { "format": "semismooth-contact harmonic-balance state", "version": 1,
//!   "method": "ssn-hb" | "penalty-hb", "harmonics": H, "dofs": N, "contacts": m,
//!   "omega": w, "omega_ratio": w / omega_1, "layout": "...",
//!   "displacement": [(2H+1) N numbers], "contact_force": [(2H+1) m numbers] (ssn-hb) }
//! ```
//!
//! Both lists are harmonic-major: entry `j N + dof` (`j m + contact`) is the coefficient of
//! the `j`-th function of `1, cos(w t), sin(w t), ..., cos(H w t), sin(H w t)`.
//!
//! # Compatibility
//!
//! A state starts a scene's solve when its `method`, `dofs` and `contacts` are the scene's
//! (a mismatch is an error naming the field). When only `harmonics` differs, the state is
//! lifted (the missing harmonics are zero) or truncated (the higher ones are dropped), which
//! is the Galerkin projection onto the scene's harmonics; the solve then says so. `omega`
//! may differ: the state is only a starting guess (e.g. a neighbouring frequency).

use std::path::Path;

use serde_json::{json, Value};

use semismooth_contact::settings::Method;
pub use semismooth_contact::solve::StateShape;

/// The `format` field of a state document.
pub const STATE_FORMAT: &str = "semismooth-contact harmonic-balance state";

/// The `version` field of a state document.
pub const STATE_VERSION: u64 = 1;

/// Largest state file read (bytes): 10,000 dofs at H = 40 take about 20 MB.
pub const STATE_FILE_LIMIT: u64 = 256 << 20;

/// Largest magnitude of a coefficient read from a state (the scale rule of the scenes'
/// amplitudes and gaps): larger ones overflow the residual.
pub const MAX_COEFFICIENT: f64 = 1e100;

/// The `layout` field of a state document, in words.
const LAYOUT: &str = "harmonic-major: entry j*dofs + dof (j*contacts + contact) is the \
    coefficient of function j of 1, cos(w t), sin(w t), ..., cos(H w t), sin(H w t)";

/// A state that cannot start the solve: the field and what is wrong with it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {problem}")]
pub struct StateError {
    /// The offending field (or option, e.g. `--entry`).
    pub field: String,
    /// What is wrong and what is allowed.
    pub problem: String,
}

fn field_error(field: impl Into<String>, problem: impl Into<String>) -> StateError {
    StateError {
        field: field.into(),
        problem: problem.into(),
    }
}

/// Refuses a method without harmonic coefficients (`what`: the option asking).
pub fn check_method(method: Method, what: &str) -> Result<(), StateError> {
    if method.is_harmonic_balance() {
        Ok(())
    } else {
        Err(field_error(
            what,
            format!(
                "the scene's method {} has no harmonic coefficients: allowed with ssn-hb \
                 or penalty-hb",
                method.name()
            ),
        ))
    }
}

/// The harmonic coefficients of a harmonic-balance solution (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct HbState {
    /// `ssn-hb` or `penalty-hb`.
    pub method: Method,
    /// Harmonics `H`.
    pub harmonics: usize,
    /// Dofs `N`.
    pub dofs: usize,
    /// Contacts `m`.
    pub contacts: usize,
    /// Forcing frequency of the solution.
    pub omega: f64,
    /// First natural frequency (for `omega_ratio`).
    pub omega_1: f64,
    /// `(2H+1) N` displacement coefficients.
    pub displacement: Vec<f64>,
    /// `(2H+1) m` contact-force coefficients (`ssn-hb`; `None` for `penalty-hb`).
    pub contact_force: Option<Vec<f64>>,
}

impl HbState {
    /// The state of the unknowns `x` of the scene's method (`[U; Lambda]` for `ssn-hb`,
    /// `U` for `penalty-hb`).
    pub fn from_unknowns(shape: StateShape, omega: f64, omega_1: f64, x: &[f64]) -> Self {
        let split = (2 * shape.harmonics + 1) * shape.dofs;
        let (u, lambda) = x.split_at(split.min(x.len()));
        Self {
            method: shape.method,
            harmonics: shape.harmonics,
            dofs: shape.dofs,
            contacts: shape.contacts,
            omega,
            omega_1,
            displacement: u.to_vec(),
            contact_force: shape
                .method
                .carries_contact_forces()
                .then(|| lambda.to_vec()),
        }
    }

    /// The JSON document (module documentation).
    pub fn to_json(&self) -> Value {
        let mut v = json!({
            "format": STATE_FORMAT,
            "version": STATE_VERSION,
            "method": self.method.name(),
            "harmonics": self.harmonics,
            "dofs": self.dofs,
            "contacts": self.contacts,
            "omega": self.omega,
            "omega_ratio": self.omega / self.omega_1,
            "layout": LAYOUT,
            "displacement": self.displacement,
        });
        if let Some(l) = &self.contact_force {
            v["contact_force"] = json!(l);
        }
        v
    }

    /// Reads a state document, checking every field (module documentation).
    pub fn from_json(v: &Value) -> Result<Self, StateError> {
        if v.get("format").and_then(Value::as_str) != Some(STATE_FORMAT) {
            return Err(field_error(
                "format",
                format!("expected \"{STATE_FORMAT}\" (written by ssn solve --state or ssn solutions --json)"),
            ));
        }
        if count_field(v, "version")? as u64 != STATE_VERSION {
            return Err(field_error("version", format!("allowed {STATE_VERSION}")));
        }
        let named = v.get("method").and_then(Value::as_str);
        let method = named
            .and_then(|name| serde_json::from_value::<Method>(Value::from(name)).ok())
            .filter(|m| m.is_harmonic_balance())
            .ok_or_else(|| {
                field_error(
                    "method",
                    format!("{named:?}: allowed \"ssn-hb\" or \"penalty-hb\""),
                )
            })?;
        let (harmonics, dofs, contacts) = (
            count_field(v, "harmonics")?,
            count_field(v, "dofs")?,
            count_field(v, "contacts")?,
        );
        if harmonics > crate::scene::MAX_HARMONICS {
            return Err(field_error(
                "harmonics",
                format!(
                    "{harmonics}: allowed 0..={} (the largest solver.harmonics)",
                    crate::scene::MAX_HARMONICS
                ),
            ));
        }
        let omega = positive_field(v, "omega")?;
        let ratio = positive_field(v, "omega_ratio")?;
        let omega_1 = omega / ratio;
        if !(omega_1.is_finite() && omega_1 > 0.0) {
            return Err(field_error(
                "omega_ratio",
                format!(
                    "{ratio:e}: omega / omega_ratio = {omega_1:e} is no natural frequency (allowed a \
                     ratio that leaves it finite and > 0)"
                ),
            ));
        }
        let functions = 2 * harmonics + 1;
        let length = |name: &str, width: usize| {
            functions.checked_mul(width).ok_or_else(|| {
                field_error(
                    name,
                    format!("(2 harmonics + 1) x {width} overflows: allowed a size that fits"),
                )
            })
        };
        let displacement = coefficients_field(v, "displacement", length("dofs", dofs)?)?;
        let contact_force = if method.carries_contact_forces() {
            Some(coefficients_field(
                v,
                "contact_force",
                length("contacts", contacts)?,
            )?)
        } else {
            None
        };
        Ok(Self {
            method,
            harmonics,
            dofs,
            contacts,
            omega,
            omega_1,
            displacement,
            contact_force,
        })
    }

    /// The scene's unknowns started from this state: `Err` naming the field when the
    /// method, dofs or contacts differ; harmonics lifted or truncated (module
    /// documentation). The note says what was adapted (`None`: nothing).
    pub fn unknowns_for(
        &self,
        shape: StateShape,
    ) -> Result<(Vec<f64>, Option<String>), StateError> {
        if self.method != shape.method {
            return Err(field_error(
                "method",
                format!(
                    "the state is of {}, the scene solves with {} (allowed: the scene's method)",
                    self.method.name(),
                    shape.method.name()
                ),
            ));
        }
        for (name, have, want) in [
            ("dofs", self.dofs, shape.dofs),
            ("contacts", self.contacts, shape.contacts),
        ] {
            if have != want {
                return Err(field_error(
                    name,
                    format!("the state has {have}, the scene's structure {want}"),
                ));
            }
        }
        let mut stacked = self.displacement.clone();
        let contacts = match &self.contact_force {
            Some(l) => {
                stacked.extend_from_slice(l);
                // Every row of G (contacts, then friction rows) per harmonic.
                l.len() / (2 * self.harmonics + 1)
            }
            None => 0,
        };
        let x = semismooth_contact::hb::resize_harmonics(
            &stacked,
            self.harmonics,
            shape.harmonics,
            self.dofs,
            contacts,
        );
        let note = (self.harmonics != shape.harmonics).then(|| {
            format!(
                "the state's H = {} {} to the scene's H = {}",
                self.harmonics,
                if self.harmonics < shape.harmonics {
                    "lifted (higher harmonics zero)"
                } else {
                    "truncated"
                },
                shape.harmonics
            )
        });
        Ok((x, note))
    }
}

/// The field `name` of the state document `v`: a non-negative integer.
fn count_field(v: &Value, name: &str) -> Result<usize, StateError> {
    v.get(name)
        .and_then(Value::as_u64)
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| field_error(name, "missing or not a non-negative integer"))
}

/// The field `name` of the state document `v`: a finite number > 0.
fn positive_field(v: &Value, name: &str) -> Result<f64, StateError> {
    v.get(name)
        .and_then(Value::as_f64)
        .filter(|x| x.is_finite() && *x > 0.0)
        .ok_or_else(|| field_error(name, "missing or not a finite number > 0"))
}

/// The field `name` of the state document `v`: a list of `len` coefficients, each finite
/// and of magnitude at most [`MAX_COEFFICIENT`].
fn coefficients_field(v: &Value, name: &str, len: usize) -> Result<Vec<f64>, StateError> {
    let items = v
        .get(name)
        .and_then(Value::as_array)
        .ok_or_else(|| field_error(name, "missing or not a list of numbers"))?;
    if items.len() != len {
        return Err(field_error(
            name,
            format!(
                "{} numbers, but (2 harmonics + 1) x {} = {len} expected",
                items.len(),
                if name == "displacement" {
                    "dofs"
                } else {
                    "contacts"
                }
            ),
        ));
    }
    items
        .iter()
        .enumerate()
        .map(|(i, x)| {
            x.as_f64()
                .filter(|x| x.abs() <= MAX_COEFFICIENT)
                .ok_or_else(|| {
                    field_error(
                        format!("{name}[{i}]"),
                        format!(
                            "{x}: allowed finite numbers of magnitude at most \
                             {MAX_COEFFICIENT:e}"
                        ),
                    )
                })
        })
        .collect()
}

/// Picks the state in a document: the document itself, or entry `entry` (from 1) of the
/// `solutions` list of `ssn solutions --json`.
pub fn select_state(doc: &Value, entry: Option<usize>) -> Result<HbState, StateError> {
    match (doc.get("solutions").and_then(Value::as_array), entry) {
        (Some(list), Some(k)) => {
            if k == 0 || k > list.len() {
                return Err(field_error(
                    "--entry",
                    format!(
                        "{k}: allowed 1 to {} (the solutions in the file)",
                        list.len()
                    ),
                ));
            }
            let state = list[k - 1]
                .get("state")
                .ok_or_else(|| field_error(format!("solutions[{}].state", k - 1), "missing"))?;
            HbState::from_json(state).map_err(|e| StateError {
                field: format!("solutions[{}].state.{}", k - 1, e.field),
                problem: e.problem,
            })
        }
        (Some(list), None) => Err(field_error(
            "--entry",
            format!(
                "the file lists {} solutions: choose one with --entry K (1 to {})",
                list.len(),
                list.len()
            ),
        )),
        (None, Some(_)) => Err(field_error(
            "--entry",
            "applies to the JSON of ssn solutions (a list of solutions); this file is one state",
        )),
        (None, None) => HbState::from_json(doc),
    }
}

/// Reads the state at `path` (a regular file of at most [`STATE_FILE_LIMIT`] bytes) and
/// picks `entry` ([`select_state`]); the message names the file.
pub fn read_state(path: &Path, entry: Option<usize>) -> Result<HbState, String> {
    let name = crate::io::printable(&path.display().to_string());
    let text = crate::io::read_regular_file(path, STATE_FILE_LIMIT)
        .map_err(|e| format!("{name}: cannot read the state: {e}"))?;
    let doc: Value =
        serde_json::from_str(&text).map_err(|e| format!("{name}: not a JSON state: {e}"))?;
    select_state(&doc, entry).map_err(|e| format!("{name}: {e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shape(harmonics: usize) -> StateShape {
        StateShape {
            method: Method::SsnHb,
            harmonics,
            dofs: 2,
            contacts: 1,
        }
    }

    #[test]
    fn a_state_round_trips_and_lifts_or_truncates_its_harmonics() {
        // H = 1: U has 3 x 2 entries, Lambda 3 x 1.
        let x: Vec<f64> = (1..=9).map(f64::from).collect();
        let s = HbState::from_unknowns(shape(1), 2.0, 1.0, &x);
        let back = HbState::from_json(&s.to_json()).unwrap();
        assert_eq!(back, s);
        assert_eq!(back.unknowns_for(shape(1)).unwrap(), (x.clone(), None));
        // H = 2: zero coefficients appended to each block.
        let (lifted, note) = back.unknowns_for(shape(2)).unwrap();
        assert_eq!(
            lifted,
            [1., 2., 3., 4., 5., 6., 0., 0., 0., 0., 7., 8., 9., 0., 0.]
        );
        assert!(note.unwrap().contains("lifted"));
        // H = 0: the constants only.
        let (cut, _) = back.unknowns_for(shape(0)).unwrap();
        assert_eq!(cut, [1., 2., 7.]);
    }

    #[test]
    fn a_ratio_that_leaves_no_natural_frequency_is_named_in_one_sentence() {
        let mut doc = HbState::from_unknowns(shape(1), 2.0, 1.0, &[0.0; 9]).to_json();
        (doc["omega"], doc["omega_ratio"]) = (json!(1e300), json!(1e-300));
        let error = HbState::from_json(&doc).unwrap_err();
        assert_eq!(error.field, "omega_ratio");
        let message = error.to_string();
        assert!(
            message.contains("is no natural frequency (allowed a ratio"),
            "{message}"
        );
        assert!(!message.contains("  "), "{message}");
    }

    #[test]
    fn mismatches_name_the_field() {
        let s = HbState::from_unknowns(shape(1), 2.0, 1.0, &[0.0; 9]);
        let mut other = shape(1);
        other.dofs = 3;
        assert_eq!(s.unknowns_for(other).unwrap_err().field, "dofs");
        other = shape(1);
        other.method = Method::PenaltyHb;
        assert_eq!(s.unknowns_for(other).unwrap_err().field, "method");
        let mut doc = s.to_json();
        doc["displacement"] = json!([1.0, 2.0]);
        assert_eq!(HbState::from_json(&doc).unwrap_err().field, "displacement");
        let mut doc = s.to_json();
        doc["contact_force"][1] = json!("x");
        assert_eq!(
            HbState::from_json(&doc).unwrap_err().field,
            "contact_force[1]"
        );
        let mut doc = s.to_json();
        doc["harmonics"] = json!(-1);
        assert_eq!(HbState::from_json(&doc).unwrap_err().field, "harmonics");
        assert_eq!(HbState::from_json(&json!({})).unwrap_err().field, "format");
        let list = json!({"solutions": [{"state": s.to_json()}]});
        assert_eq!(select_state(&list, None).unwrap_err().field, "--entry");
        assert_eq!(select_state(&list, Some(2)).unwrap_err().field, "--entry");
        assert_eq!(select_state(&list, Some(1)).unwrap(), s);
        assert_eq!(
            select_state(&s.to_json(), Some(1)).unwrap_err().field,
            "--entry"
        );
    }
}
