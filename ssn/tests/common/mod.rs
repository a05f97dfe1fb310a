//! Helpers shared by the application's integration tests: the library tests' helpers
//! (`contact/tests/common`), the shipped scenes and the documented JSON fields.

#![allow(dead_code)]

pub mod json_fields;

#[path = "../../../contact/tests/common/mod.rs"]
mod library;
pub use library::*;

use std::path::{Path, PathBuf};

use semismooth_contact::matrix_market::build_imported;
use semismooth_contact::model::Structure;
use ssn::scene::Scene;

/// The shipped scenes, `scenes/` at the root of the repository.
pub fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes")
}

/// The shipped `[model]` scene `name` with `edit` applied to its text, and the structure
/// it imports.
pub fn shipped_model(name: &str, edit: impl Fn(String) -> String) -> (Scene, Structure) {
    let path = scenes_dir().join(name);
    let text = std::fs::read_to_string(&path).unwrap();
    let scene = Scene::from_toml(&edit(text), &path).unwrap();
    let structure = build_imported(scene.model.as_ref().unwrap()).unwrap();
    (scene, structure)
}
