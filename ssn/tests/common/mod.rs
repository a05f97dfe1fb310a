//! Helpers shared by the application's integration tests: the library tests' helpers
//! (`contact/tests/common`), the shipped scenes and the documented JSON fields.

#![allow(dead_code)]

pub mod json_fields;

#[path = "../../../contact/tests/common/mod.rs"]
mod library;
#[allow(unused_imports)] // not every test uses the library helpers
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

/// The message of the scene file `path` with `edit` applied to its text (its directory
/// kept), from reading the scene or else from importing its files; panics if both accept.
pub fn error_of_edited_scene(path: &Path, edit: impl Fn(String) -> String) -> String {
    let text = edit(std::fs::read_to_string(path).unwrap());
    let scene = match Scene::from_toml(&text, path) {
        Ok(s) => s,
        Err(e) => return e.to_string(),
    };
    match build_imported(scene.model.as_ref().unwrap()) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

/// The eigenvalues `omega^2` CalculiX printed in the `.dat` file `dat` (EIGENVALUE OUTPUT,
/// mode order).
pub fn calculix_eigenvalues(dat: &Path) -> Vec<f64> {
    let dat = std::fs::read_to_string(dat).unwrap();
    let table = dat
        .split("E I G E N V A L U E   O U T P U T")
        .nth(1)
        .unwrap();
    let table = table.split("P A R T I C I P A T I O N").next().unwrap();
    table
        .lines()
        .filter_map(|l| {
            let w: Vec<&str> = l.split_whitespace().collect();
            (w.len() == 5 && w[0].parse::<usize>().is_ok()).then(|| w[1].parse().unwrap())
        })
        .collect()
}
