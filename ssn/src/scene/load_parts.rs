//! `[forcing]` loads beyond the cosine `vector` of a `[model]` scene: `vector_sin` (a sine
//! part on the forcing frequency), `static` (a constant load, harmonic 0) and
//! `[[forcing.harmonic]]` entries (`order = k`, `cos`, `sin`: a load on harmonic `k`), all
//! Matrix Market files of `N x 1`, scaled by `amplitude` except `static`.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use semismooth_contact::matrix_market::{read_matrix, ImportError};
use semismooth_contact::model::{SparseMatrix, StructuralModel};

use super::check::Check;
use super::{RawForcing, SceneError};

/// The matrices of a `[model]` scene held in memory: each path the scene names to its
/// matrix (the checks of the files' import apply as to files).
pub type MatrixSource<'a> = &'a dyn Fn(&Path) -> Result<SparseMatrix, ImportError>;

/// One `[[forcing.harmonic]]` entry as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawForcingHarmonic {
    order: i64,
    cos: Option<String>,
    sin: Option<String>,
}

/// A load part of a `[model]` scene: the files of the cosine and sine parts of one
/// harmonic (0: constant), the scene keys that named them, and whether `amplitude`
/// scales it.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadPart {
    /// The harmonic of the forcing frequency (0: constant).
    pub harmonic: usize,
    /// The cosine part's file and its key.
    pub cosine: Option<(PathBuf, &'static str)>,
    /// The sine part's file and its key.
    pub sine: Option<(PathBuf, &'static str)>,
    /// Multiplied by `[forcing] amplitude` (all but `static`).
    pub scaled: bool,
}

impl Check<'_> {
    /// `[forcing] vector_sin`, `static` and `[[forcing.harmonic]]` of a `[model]` scene
    /// with `harmonics` harmonics (`order` in `1..=harmonics`, a file for `cos` or `sin`);
    /// in a `[rod]` scene (`model = false`) every one of them is refused.
    pub(super) fn load_parts(
        &self,
        f: &RawForcing,
        model: bool,
        harmonics: usize,
    ) -> Result<Vec<LoadPart>, SceneError> {
        if !model {
            let given = [
                ("forcing.vector", f.vector.is_some()),
                ("forcing.node", f.node.is_some()),
                ("forcing.component", f.component.is_some()),
                ("forcing.vector_sin", f.vector_sin.is_some()),
                ("forcing.static", f.constant.is_some()),
                ("forcing.harmonic", f.harmonic.is_some()),
            ];
            if let Some((key, _)) = given.iter().find(|(_, g)| *g) {
                let name = key.trim_start_matches("forcing.");
                return Err(self.invalid(
                    key,
                    "given in a [rod] scene",
                    &format!(
                        "`load` (\"distributed\" or \"tip\"); `{name}` belongs to [model] scenes"
                    ),
                ));
            }
            return Ok(Vec::new());
        }
        let mut parts = Vec::new();
        if let Some(name) = &f.vector_sin {
            let sine = Some((self.file("forcing.vector_sin", name)?, "forcing.vector_sin"));
            parts.push(LoadPart {
                harmonic: 1,
                cosine: None,
                sine,
                scaled: true,
            });
        }
        if let Some(name) = &f.constant {
            parts.push(LoadPart {
                harmonic: 0,
                cosine: Some((self.file("forcing.static", name)?, "forcing.static")),
                sine: None,
                scaled: false,
            });
        }
        for h in f.harmonic.iter().flatten() {
            parts.push(self.harmonic_part(h, harmonics)?);
        }
        Ok(parts)
    }

    /// One `[[forcing.harmonic]]` entry.
    fn harmonic_part(
        &self,
        h: &RawForcingHarmonic,
        harmonics: usize,
    ) -> Result<LoadPart, SceneError> {
        if h.order < 1 || h.order > harmonics as i64 {
            return Err(self.invalid(
                "forcing.harmonic.order",
                h.order,
                &format!(
                    "an integer in 1..={harmonics} (solver.harmonics; a constant load is \
                     `static`)"
                ),
            ));
        }
        if h.cos.is_none() && h.sin.is_none() {
            return Err(self.invalid(
                "forcing.harmonic",
                format!("order = {} without a file", h.order),
                "`cos` and/or `sin`: Matrix Market files of N x 1",
            ));
        }
        let file = |key: &'static str, name: &Option<String>| {
            name.as_deref()
                .map(|n| self.file(key, n).map(|p| (p, key)))
                .transpose()
        };
        Ok(LoadPart {
            harmonic: h.order as usize,
            cosine: file("forcing.harmonic.cos", &h.cos)?,
            sine: file("forcing.harmonic.sin", &h.sin)?,
            scaled: true,
        })
    }

    /// The file `name` relative to the scene's directory (`key` names it in the error of
    /// an empty name).
    fn file(&self, key: &str, name: &str) -> Result<PathBuf, SceneError> {
        if name.trim().is_empty() {
            return Err(self.invalid(
                key,
                "\"\"",
                "a file name (relative to the scene's directory)",
            ));
        }
        Ok(self.path().parent().unwrap_or(Path::new("")).join(name))
    }
}

/// Adds the load parts to `model`'s load (`amplitude` the scene's `[forcing] amplitude`),
/// each file read by `read` (`None`: from the file system) and checked to be `N x 1`;
/// the error names the file, the key, the size found and the size allowed.
pub fn add_load_parts(
    parts: &[LoadPart],
    amplitude: f64,
    model: &mut StructuralModel,
    read: Option<MatrixSource>,
) -> Result<(), String> {
    let n = model.dofs();
    let vector = |part: &Option<(PathBuf, &'static str)>, scale: f64| match part {
        None => Ok(vec![0.0; n]),
        Some((path, key)) => {
            let matrix = match read {
                Some(read) => read(path),
                None => read_matrix(path),
            }
            .map_err(|e| e.to_string())?;
            if matrix.nrows() != n || matrix.ncols() != 1 {
                return Err(format!(
                    "{}: {key} is {} x {}: allowed {n} x 1 (one entry per dof)",
                    path.display(),
                    matrix.nrows(),
                    matrix.ncols()
                ));
            }
            let mut v = vec![0.0; n];
            let m = matrix.as_ref();
            for (i, a) in m.row_idx_of_col(0).zip(m.val_of_col(0)) {
                v[i] += scale * a;
            }
            Ok(v)
        }
    };
    for part in parts {
        let scale = if part.scaled { amplitude } else { 1.0 };
        let (cosine, sine) = (vector(&part.cosine, scale)?, vector(&part.sine, scale)?);
        model
            .load
            .add_harmonic(part.harmonic, &cosine, &sine)
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}
