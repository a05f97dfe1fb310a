//! Helpers shared by the application's integration tests: the library tests' helpers
//! (`contact/tests/common`), the shipped scenes and the documented JSON fields.

#![allow(dead_code)]

pub mod json_fields;

#[path = "../../../contact/tests/common/mod.rs"]
mod library;
pub use library::*;

use std::path::{Path, PathBuf};

/// The shipped scenes, `scenes/` at the root of the repository.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}
