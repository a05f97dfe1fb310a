//! Shared by the examples that write files (`mod common;`).

use std::path::PathBuf;

use ssn::output::{prepare_directory, OutputError};

/// The output directory of an example: its first command-line argument, else `default`;
/// created (with its parents) when absent.
pub fn output_directory(default: &str) -> Result<PathBuf, OutputError> {
    let out = std::env::args()
        .nth(1)
        .map_or_else(|| PathBuf::from(default), PathBuf::from);
    prepare_directory(&out)?;
    Ok(out)
}
