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
//!
//! `[model] mesh = "x.inp"` reads the node coordinates of a CalculiX or Abaqus input deck,
//! from which a 3-D contact's `normal = "radial"` is computed (module `frictional`).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use semismooth_contact::import::{radial_direction, DofMap, MeshNodes, Part};
use semismooth_contact::matrix_market::{labelled_files_dof_map, DofMapFile, MatrixFormat};

use super::check::Check;
use super::{RawContactPoint, RawMatrixFormat, SceneError};

/// A contact's `normal`: a vector, or a name of a computed normal (`"radial"`).
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(untagged)]
pub(super) enum RawNormal {
    /// `[nx, ny, nz]`.
    Vector(Vec<f64>),
    /// `"radial"`.
    Named(String),
}

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

impl Check<'_> {
    /// The node coordinates of the input deck `path` (`[model] mesh`).
    pub(super) fn mesh_nodes(&self, path: &Path) -> Result<MeshNodes, SceneError> {
        MeshNodes::read_inp(path)
            .map_err(|e| SceneError::parse(self.path(), format!("`model.mesh`: {e}")))
    }

    /// The normal vector of `p` (before its unit check): as given, or `"radial"` about
    /// `axis` through `axis_origin` at the node's mesh coordinates.
    pub(super) fn normal_vector(
        &self,
        p: &RawContactPoint,
        normal: &RawNormal,
    ) -> Result<Vec<f64>, SceneError> {
        let three = |key: &str, v: &[f64]| -> Result<[f64; 3], SceneError> {
            let finite = v.iter().all(|x| x.is_finite());
            v.try_into()
                .ok()
                .filter(|_| finite)
                .ok_or_else(|| self.invalid(key, format!("{v:?}"), "3 finite values [x, y, z]"))
        };
        let name = match normal {
            RawNormal::Vector(v) => {
                if p.axis.is_some() || p.axis_origin.is_some() {
                    return Err(self.invalid(
                        "contact.point.axis",
                        "given with a normal vector",
                        "`axis` (and `axis_origin`) only with normal = \"radial\"",
                    ));
                }
                return Ok(v.clone());
            }
            RawNormal::Named(name) if name == "radial" => name,
            RawNormal::Named(other) => {
                return Err(self.invalid(
                    "contact.point.normal",
                    format!("\"{other}\""),
                    "a unit vector [nx, ny, nz] or \"radial\" (about `axis`)",
                ))
            }
        };
        let mesh = self.mesh().ok_or_else(|| {
            self.invalid(
                "contact.point.normal",
                format!("\"{name}\" without a [model] mesh"),
                "a [model] mesh = \"x.inp\" (the node coordinates) with normal = \"radial\"",
            )
        })?;
        let axis = p.axis.as_deref().ok_or_else(|| {
            self.invalid(
                "contact.point.axis",
                "missing",
                "the axis [ax, ay, az] of normal = \"radial\"",
            )
        })?;
        let axis = three("contact.point.axis", axis)?;
        let origin = match p.axis_origin.as_deref() {
            Some(o) => three("contact.point.axis_origin", o)?,
            None => [0.0; 3],
        };
        let node = p.node.unwrap_or(0);
        let point = u64::try_from(node)
            .ok()
            .and_then(|n| mesh.coordinates(n))
            .ok_or_else(|| {
                self.invalid(
                    "contact.point.node",
                    node,
                    "a node of the [model] mesh (its coordinates give the radial normal)",
                )
            })?;
        let n = radial_direction(point, origin, axis).ok_or_else(|| {
            self.invalid(
                "contact.point.axis",
                format!("{axis:?} through {origin:?}, with node {node} at {point:?}"),
                "a nonzero axis that does not pass through the node (the radial normal \
                 needs a distance)",
            )
        })?;
        Ok(n.to_vec())
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
