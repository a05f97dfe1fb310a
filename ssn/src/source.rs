//! A scene as written: its TOML text, where it came from, the overrides applied to it and,
//! for a structure given as matrices rather than files, those matrices. It is what a study
//! ships to its cases and what the Python package pickles: the validated [`Scene`] and the
//! structure are rebuilt from it wherever it runs, with the checks and messages of a scene
//! file.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use semismooth_contact::matrix_market::ImportError;
use semismooth_contact::model::SparseMatrix;

use crate::exit::CliError;
use crate::load::{prepare, Loaded, Workload};
use crate::scene::{read_scene_text, Override, Scene, SceneError};

/// A scene's text, path, overrides and in-memory matrices (module documentation).
#[derive(Debug, Clone)]
pub struct SceneSource {
    /// The TOML text.
    pub text: String,
    /// The file it was read from (messages name it; `[model]` file names are relative to
    /// its directory).
    pub path: PathBuf,
    /// Overrides applied in order (a later one of the same key wins).
    pub overrides: Vec<Override>,
    /// The `[model]`'s matrices by path, when they are held in memory instead of files.
    pub matrices: Option<Arc<BTreeMap<PathBuf, SparseMatrix>>>,
}

impl SceneSource {
    /// The scene file at `path`.
    pub fn from_path(path: impl AsRef<Path>) -> Result<SceneSource, SceneError> {
        let path = path.as_ref();
        Ok(SceneSource {
            text: read_scene_text(path)?,
            path: path.to_path_buf(),
            overrides: Vec::new(),
            matrices: None,
        })
    }

    /// Scene text with `path` used in messages.
    pub fn from_text(text: impl Into<String>, path: impl Into<PathBuf>) -> SceneSource {
        SceneSource {
            text: text.into(),
            path: path.into(),
            overrides: Vec::new(),
            matrices: None,
        }
    }

    /// This scene with `overrides` applied after its own.
    pub fn with(&self, overrides: &[Override]) -> SceneSource {
        let mut next = self.clone();
        next.overrides.extend_from_slice(overrides);
        next
    }

    /// The validated scene.
    pub fn scene(&self) -> Result<Scene, SceneError> {
        Scene::from_toml_with(&self.text, &self.path, &self.overrides)
    }

    /// The validated scene and its structure, as [`crate::load::load_for`] builds them for a
    /// run of `workload` (its memory and work limits).
    pub fn load(&self, workload: Workload) -> Result<Loaded, CliError> {
        let scene = self
            .scene()
            .map_err(|e| CliError::BadInput(e.to_string()))?;
        match &self.matrices {
            Some(matrices) => {
                let read = |path: &Path| -> Result<SparseMatrix, ImportError> {
                    matrices.get(path).cloned().ok_or_else(|| ImportError::Io {
                        path: path.to_path_buf(),
                        source: std::io::Error::new(
                            std::io::ErrorKind::NotFound,
                            "no such matrix among those given in memory",
                        ),
                    })
                };
                prepare(scene, workload, Some(&read))
            }
            None => prepare(scene, workload, None),
        }
    }
}
