//! How a command failed, as the documented exit codes: 1 not converged, 2 bad input (or a
//! run refused up front as too large), 3 an output not written.

use crate::io::{OutputError, TargetError};

/// How a command failed, mapped by `main` onto the documented exit codes.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// The solver ran but did not converge (exit code 1); its output was printed.
    #[error("the solver did not converge")]
    NotConverged,
    /// Bad input: scene, option (exit code 2).
    #[error("{0}")]
    BadInput(String),
    /// A run refused before it starts: its memory or work estimate is above the limit
    /// (exit code 2, as bad input: smaller settings or a raised limit let it run).
    #[error("{0}")]
    TooLarge(String),
    /// An output could not be written (exit code 3).
    #[error("{0}")]
    Output(String),
}

impl From<OutputError> for CliError {
    fn from(e: OutputError) -> Self {
        CliError::Output(e.to_string())
    }
}

/// A target that is not a regular file cannot be written (exit code 3); two uses of one
/// file are a bad combination of options (exit code 2).
impl From<TargetError> for CliError {
    fn from(e: TargetError) -> Self {
        match e {
            TargetError::NotRegular { .. } => CliError::Output(e.to_string()),
            TargetError::Clash { .. } => CliError::BadInput(e.to_string()),
        }
    }
}
