//! Shared by the examples that write files (`mod common;`); each uses part of it.

#![allow(dead_code)]

use std::error::Error;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

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

/// The exit code of an example whose work `run` returned: failure, with the error printed,
/// when it failed.
pub fn exit_code(run: Result<(), Box<dyn Error>>) -> ExitCode {
    match run {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Replaces the generated block `block` of `docs/studies.md` with `page`.
pub fn write_studies_block(block: &str, page: &str) -> Result<(), Box<dyn Error>> {
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/studies.md");
    let text = std::fs::read_to_string(&docs)?;
    let text = ssn::tables::replace_block(&text, block, page)
        .ok_or_else(|| format!("docs/studies.md has no {block} block"))?;
    std::fs::write(&docs, text)?;
    eprintln!("wrote {}", docs.display());
    Ok(())
}
