//! `[model] format`: the format of the matrix files, given or detected from the stiffness
//! file's name, and the dof map that goes with it.
//!
//! | format | detected from | dof map |
//! |---|---|---|
//! | `"matrix-market"` (default) | any other name | `dof_map` file (`node.component` lines), optional |
//! | `"calculix"` | `.sti` | `dof_map` = the `.dof` file, required |
//! | `"abaqus"` | `*_STIF<n>.mtx` | the node labels of the matrix files (no `dof_map`) |
//! | `"nastran-dmig"` | `.pch` | the grid labels of the DMIG matrices (no `dof_map`) |
//! | `"harwell-boeing"` | `.matrix`, `.hb`, `.rsa`, `.rua` | `dof_map` = Ansys' mapping file, optional |

use std::path::{Path, PathBuf};
use std::sync::Arc;

use semismooth_contact::import::{DofMap, Part};
use semismooth_contact::matrix_market::{labelled_files_dof_map, DofMapFile, MatrixFormat};

use super::check::Check;
use super::{RawMatrixFormat, SceneError};

/// The files of a `[model]` (paths resolved).
pub(super) struct ModelFiles<'a> {
    pub(super) stiffness: &'a Path,
    pub(super) mass: &'a Path,
    pub(super) damping: Option<&'a Path>,
    /// The `dof_map` file, when given.
    pub(super) dof_map: Option<PathBuf>,
}

/// The format a stiffness file's name implies (module documentation).
fn detected(stiffness: &Path) -> MatrixFormat {
    let name = stiffness
        .file_name()
        .map(|n| n.to_string_lossy().to_lowercase())
        .unwrap_or_default();
    let extension = name.rsplit_once('.').map_or("", |(_, e)| e);
    let abaqus = name
        .strip_suffix(".mtx")
        .and_then(|stem| stem.rsplit_once("_stif"))
        .is_some_and(|(_, step)| !step.is_empty() && step.chars().all(|c| c.is_ascii_digit()));
    match extension {
        "sti" => MatrixFormat::CalculiX,
        "pch" => MatrixFormat::NastranDmig,
        "matrix" | "hb" | "rsa" | "rua" => MatrixFormat::HarwellBoeing,
        _ if abaqus => MatrixFormat::Abaqus,
        _ => MatrixFormat::MatrixMarket,
    }
}

impl Check<'_> {
    /// The format of `[model]` (`given`, else [`detected`]) and its dof map.
    pub(super) fn model_format(
        &self,
        given: Option<RawMatrixFormat>,
        files: ModelFiles<'_>,
    ) -> Result<(MatrixFormat, Option<DofMapFile>), SceneError> {
        let format = match given {
            None => detected(files.stiffness),
            Some(RawMatrixFormat::MatrixMarket) => MatrixFormat::MatrixMarket,
            Some(RawMatrixFormat::Calculix) => MatrixFormat::CalculiX,
            Some(RawMatrixFormat::Abaqus) => MatrixFormat::Abaqus,
            Some(RawMatrixFormat::NastranDmig) => MatrixFormat::NastranDmig,
            Some(RawMatrixFormat::HarwellBoeing) => MatrixFormat::HarwellBoeing,
        };
        let read_map = |read: fn(&Path) -> Result<DofMap, _>| {
            files
                .dof_map
                .clone()
                .map(|path| {
                    let map = read(&path).map_err(|e| {
                        SceneError::parse(self.path(), format!("`model.dof_map`: {e}"))
                    })?;
                    Ok(DofMapFile {
                        path,
                        map: Arc::new(map),
                    })
                })
                .transpose()
        };
        let map = match format {
            MatrixFormat::HarwellBoeing => read_map(DofMap::read_ansys_mapping)?,
            f if f.labels_rows() => Some(self.labelled_map(f, &files)?),
            _ => read_map(DofMap::read)?,
        };
        if format == MatrixFormat::CalculiX && map.is_none() {
            return Err(self.invalid(
                "model.dof_map",
                "missing with format = \"calculix\"",
                "the CalculiX .dof file written beside the .sti and .mas files (it gives the \
                 matrices' size and each row's node and component)",
            ));
        }
        Ok((format, map))
    }

    /// The dof map of matrix files that label their rows (`format.labels_rows()`).
    fn labelled_map(
        &self,
        format: MatrixFormat,
        files: &ModelFiles<'_>,
    ) -> Result<DofMapFile, SceneError> {
        let name = format.name();
        if files.dof_map.is_some() {
            return Err(self.invalid(
                "model.dof_map",
                format!("given with format = \"{name}\""),
                &format!(
                    "no dof_map with format = \"{name}\" (the node labels in its matrix files \
                     give the rows); a dof_map goes with \"calculix\", \"matrix-market\" or \
                     \"harwell-boeing\""
                ),
            ));
        }
        let mut parts = vec![(Part::Stiffness, files.stiffness), (Part::Mass, files.mass)];
        parts.extend(files.damping.map(|d| (Part::Damping, d)));
        let map = labelled_files_dof_map(format, &parts).map_err(|e| {
            SceneError::parse(self.path(), format!("`model.format` = \"{name}\": {e}"))
        })?;
        Ok(DofMapFile {
            path: files.stiffness.to_path_buf(),
            map: Arc::new(map),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_stiffness_file_name_gives_the_format() {
        for (name, format) in [
            ("model.sti", MatrixFormat::CalculiX),
            ("dir/job_STIF1.mtx", MatrixFormat::Abaqus),
            ("job_stif12.mtx", MatrixFormat::Abaqus),
            ("job_STIF.mtx", MatrixFormat::MatrixMarket),
            ("K.mtx", MatrixFormat::MatrixMarket),
            ("model.pch", MatrixFormat::NastranDmig),
            ("k.MATRIX", MatrixFormat::HarwellBoeing),
            ("k.rsa", MatrixFormat::HarwellBoeing),
            ("stiffness", MatrixFormat::MatrixMarket),
        ] {
            assert_eq!(detected(Path::new(name)), format, "{name}");
        }
    }
}
