//! Why an input file (a scene or a study file) could not be used: one set of errors, each
//! naming the file, and for a bad value also the key, the value found and what is allowed.

use std::fmt;
use std::path::{Path, PathBuf};

/// What an input file describes, as its messages name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FileKind {
    /// A scene (`ssn run`, `ssn sweep`, ...).
    Scene,
    /// A study file (`ssn study`).
    Study,
}

impl fmt::Display for FileKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FileKind::Scene => "scene",
            FileKind::Study => "study",
        })
    }
}

/// Why an input file could not be used. Every variant names the file; `Invalid` also names
/// the key, the value found and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum InputFileError {
    /// The file could not be read.
    #[error("{path}: cannot read {kind}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What the file describes.
        kind: FileKind,
        /// The system error.
        source: std::io::Error,
    },
    /// Malformed TOML, an unknown key, a wrong type or a missing required key.
    #[error("{path}: {message}")]
    Parse {
        /// The file.
        path: PathBuf,
        /// The parser's message (with line and column, key and expected type).
        message: String,
    },
    /// A value of the right type outside its allowed range, or conflicting keys.
    #[error("{path}: invalid `{key}` = {value}: allowed {allowed}")]
    Invalid {
        /// The file.
        path: PathBuf,
        /// The offending key, as `section.key`.
        key: String,
        /// The value found.
        value: String,
        /// What is allowed.
        allowed: String,
    },
}

impl InputFileError {
    /// [`InputFileError::Parse`] of the file `path`.
    pub fn parse(path: &Path, message: impl Into<String>) -> Self {
        Self::Parse {
            path: path.to_path_buf(),
            message: message.into(),
        }
    }

    /// [`InputFileError::Invalid`]: `key` of the file `path` is `value`, `allowed` is.
    pub fn invalid(path: &Path, key: &str, value: impl ToString, allowed: &str) -> Self {
        Self::Invalid {
            path: path.to_path_buf(),
            key: key.to_string(),
            value: value.to_string(),
            allowed: allowed.to_string(),
        }
    }
}

/// The text of the input file `path` (a regular file of at most
/// [`crate::io::SCENE_SIZE_LIMIT`] bytes); [`InputFileError::Io`] otherwise.
pub fn read_input_file(path: &Path, kind: FileKind) -> Result<String, InputFileError> {
    crate::io::read_regular_file(path, crate::io::SCENE_SIZE_LIMIT).map_err(|source| {
        InputFileError::Io {
            path: path.to_path_buf(),
            kind,
            source,
        }
    })
}
