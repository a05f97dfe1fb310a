//! The package's exceptions, by kind (the classes of `ssn/_errors.py`), raised from Rust
//! with the numbers that explain them as attributes.

use pyo3::prelude::*;
use pyo3::types::PyType;

use semismooth_contact::{Error as LibraryError, ErrorKind};
use ssn::load::LoadError;

/// An attribute of an exception.
pub(crate) enum Field {
    Int(usize),
    Float(f64),
    Text(String),
}

/// The exception `class` of `ssn._errors` with `message` and the attributes `fields`.
pub(crate) fn exception(class: &str, message: String, fields: Vec<(&str, Field)>) -> PyErr {
    Python::attach(|py| {
        let made = || -> PyResult<PyErr> {
            let class = py
                .import("ssn._errors")?
                .getattr(class)?
                .cast_into::<PyType>()?;
            let error = PyErr::from_type(class, message);
            let value = error.value(py);
            for (name, field) in fields {
                match field {
                    Field::Int(v) => value.setattr(name, v)?,
                    Field::Float(v) => value.setattr(name, v)?,
                    Field::Text(v) => value.setattr(name, v)?,
                }
            }
            Ok(error)
        };
        made().unwrap_or_else(|failed| failed)
    })
}

/// Bad input as `SceneError` with the command line's message.
pub(crate) fn bad_input(e: impl std::fmt::Display) -> PyErr {
    exception("SceneError", e.to_string(), Vec::new())
}

/// A value of the wrong type as `SceneTypeError` (a `SceneError` and a `TypeError`).
pub(crate) fn bad_type(e: impl std::fmt::Display) -> PyErr {
    exception("SceneTypeError", e.to_string(), Vec::new())
}

/// Why a run of a scene failed: the scene could not be loaded ([`LoadError`]), the library
/// refused or could not carry out the computation, or a result that needs a converged solve
/// did not get one.
pub(crate) enum RunFailure {
    Load(LoadError),
    Library(LibraryError),
    Input(String),
    NotConverged {
        termination: String,
        iterations: usize,
        residual_norm: f64,
    },
}

impl From<LibraryError> for RunFailure {
    fn from(e: LibraryError) -> Self {
        RunFailure::Library(e)
    }
}

impl From<&str> for RunFailure {
    fn from(message: &str) -> Self {
        RunFailure::Input(message.to_string())
    }
}

/// The exception of `failure` of the scene `path` (messages start with the file).
pub(crate) fn run_failure(path: &std::path::Path, failure: RunFailure) -> PyErr {
    let path = path.display();
    match failure {
        RunFailure::Load(LoadError::TooLarge(m)) => exception("TooLargeError", m, Vec::new()),
        RunFailure::Load(LoadError::NotConverged) => exception(
            "SolveError",
            "the solver did not converge".into(),
            Vec::new(),
        ),
        RunFailure::Load(LoadError::BadInput(m) | LoadError::Output(m)) => bad_input(m),
        RunFailure::Input(m) => bad_input(format!("{path}: {m}")),
        RunFailure::Library(e) => library_error(&format!("{path}: {e}"), &e),
        RunFailure::NotConverged {
            termination,
            iterations,
            residual_norm,
        } => exception(
            "NotConvergedError",
            format!(
                "{path}: the solve did not converge ({termination} after {iterations} \
                 iterations, |F| = {residual_norm:e})"
            ),
            vec![
                ("termination", Field::Text(termination)),
                ("iterations", Field::Int(iterations)),
                ("residual_norm", Field::Float(residual_norm)),
            ],
        ),
    }
}

/// A library error as the exception of its kind: bad input, or a computation that could
/// not be carried out.
fn library_error(message: &str, e: &LibraryError) -> PyErr {
    match e.kind() {
        ErrorKind::InvalidInput => bad_input(message),
        _ => exception("SolveError", message.to_string(), Vec::new()),
    }
}
