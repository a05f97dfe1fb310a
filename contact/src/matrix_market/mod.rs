//! Matrix Market files of an imported structure: the reader of the format-neutral
//! [`ModelParts`] for a `[model]` scene ([`ModelSpec`]: the files and what the scene
//! attaches to them), and the inverse, a structure written as such files.
//!
//! The files hold `M`, `K` and an optional `D`, `N x N`, and the load shape `f`, `N x 1`
//! (module [`crate::import`] for what they mean and how they are checked). Matrix Market
//! coordinate (real or integer; general, symmetric or skew-symmetric, the lower triangle
//! then mirrored) and array formats are read by [`read_matrix`] as the file goes, from
//! regular files only, with the declared size checked before it is allocated and every
//! defect named with its line (nalgebra-sparse's reader reads any file whole, allocates what
//! the header declares and reports neither the line nor the value); duplicate coordinate
//! entries are summed (assembly).
//!
//! [`build_imported`] reads the files of a [`ModelSpec`], checks them with
//! [`crate::import::assemble`] and names each violation as the scene gives it (an
//! [`ImportError`] with the file, or the scene and its key, and the value); it also checks
//! that the forcing frequency ([`ModelSpec::omega`]) is finite and `> 0`. A `dof_map`
//! ([`DofMap`]) has `N` rows. A `damping` file and a `[damping]` section together are an
//! error (of the scene).

use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::import::{assemble, Attachments, DofMap, DofUse, ModelError, ModelParts, Part};
use crate::model::{FrictionalContact, SparseMatrix, Structure};
use crate::rod::{DampingSpec, FrequencySpec};

mod abaqus;
mod calculix;
mod harwell_boeing;
mod labelled;
mod nastran;
mod read;

pub use abaqus::{parse_abaqus_matrix, read_abaqus_matrix};
pub use calculix::{calculix_matrix_text, parse_calculix_matrix, read_calculix_matrix};
pub use harwell_boeing::{parse_harwell_boeing, read_harwell_boeing};
pub use labelled::{labelled_dof_map, LabelledEntry, LabelledMatrix, Storage};
pub use nastran::{parse_dmig, read_dmig, select_dmig, DmigMatrix};

pub use read::{
    matrix_market_text, parse_matrix, read_matrix, vector_market_text, MAX_ENTRY_MAGNITUDE,
    MAX_LINE_BYTES, MAX_MATRIX_DIMENSION, MAX_MATRIX_FILE_BYTES,
};

pub use crate::import::{DofContact, DofFriction, MIN_OMEGA_1, SYMMETRY_TOLERANCE};
pub use crate::model::ContactDirection;

/// A dof map file and the map read from it.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMapFile {
    /// The file (for messages).
    pub path: PathBuf,
    /// Its rows (shared by the scene's copies).
    pub map: Arc<DofMap>,
}

/// The format of a model's matrix files.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum MatrixFormat {
    /// Matrix Market files ([`read_matrix`]).
    #[default]
    MatrixMarket,
    /// CalculiX `.sti` / `.mas` files ([`read_calculix_matrix`]), sized by the dof map
    /// (required); the load vector is still a Matrix Market file.
    CalculiX,
    /// Abaqus `*MATRIX OUTPUT, FORMAT=MATRIX INPUT` files ([`read_abaqus_matrix`]): the
    /// rows are the (node, dof) pairs the files name ([`labelled_dof_map`]).
    Abaqus,
    /// Nastran DMIG matrices in a punch file ([`read_dmig`], [`select_dmig`]): the rows are
    /// the (grid, component) pairs the matrices name ([`labelled_dof_map`]).
    NastranDmig,
    /// Harwell-Boeing files ([`read_harwell_boeing`]), the rows' nodes and dofs in Ansys'
    /// mapping file ([`DofMap::read_ansys_mapping`], optional).
    HarwellBoeing,
}

impl MatrixFormat {
    /// The format's name in a scene: `"matrix-market"`, `"calculix"`.
    pub fn name(self) -> &'static str {
        match self {
            MatrixFormat::MatrixMarket => "matrix-market",
            MatrixFormat::CalculiX => "calculix",
            MatrixFormat::Abaqus => "abaqus",
            MatrixFormat::NastranDmig => "nastran-dmig",
            MatrixFormat::HarwellBoeing => "harwell-boeing",
        }
    }

    /// The kind of file, as messages name it: `"Matrix Market"`, `"Abaqus matrix"`, ...
    pub const fn file_kind(self) -> &'static str {
        match self {
            MatrixFormat::MatrixMarket => "Matrix Market",
            MatrixFormat::CalculiX => "CalculiX matrix",
            MatrixFormat::Abaqus => "Abaqus matrix",
            MatrixFormat::NastranDmig => "Nastran DMIG",
            MatrixFormat::HarwellBoeing => "Harwell-Boeing",
        }
    }

    /// Whether the matrix files name their rows by node and component themselves (the
    /// dof map is then theirs, [`labelled_files_dof_map`], not a file of its own).
    pub fn labels_rows(self) -> bool {
        matches!(self, MatrixFormat::Abaqus | MatrixFormat::NastranDmig)
    }
}

/// Everything a `[model]` scene declares (paths resolved against the scene's directory).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelSpec {
    /// The scene file (for messages).
    pub scene: PathBuf,
    /// The format of the matrix files (`mass`, `stiffness`, `damping_matrix`).
    pub format: MatrixFormat,
    /// Mass matrix file.
    pub mass: PathBuf,
    /// Stiffness matrix file.
    pub stiffness: PathBuf,
    /// Damping matrix file (optional).
    pub damping_matrix: Option<PathBuf>,
    /// Damping from the `[damping]` section (not with a damping file).
    pub damping: Option<DampingSpec>,
    /// Load shape file (`N x 1`, Matrix Market), unless `load_dof` is given.
    pub forcing_vector: PathBuf,
    /// A unit point load on this 0-based dof as the load shape, in place of the
    /// `forcing_vector` file (then unused).
    pub load_dof: Option<usize>,
    /// Load amplitude (multiplies the load shape).
    pub amplitude: f64,
    /// Forcing frequency (`Ratio` in units of `omega_1`).
    pub frequency: FrequencySpec,
    /// Contacts.
    pub contacts: Vec<DofContact>,
    /// Friction points under a prescribed normal load (`[[friction.point]]`).
    pub friction: Vec<DofFriction>,
    /// 3-D frictional contacts (rows 0-based).
    pub frictional_contacts: Vec<FrictionalContact>,
    /// Observed dof (0-based); `None`: the first contact dof, else the first friction
    /// point's, else the largest load entry.
    pub observed_dof: Option<usize>,
    /// The node and component of each row (`[model] dof_map`), read when the scene was;
    /// the scene's node-addressed dofs are already resolved through it.
    pub dof_map: Option<DofMapFile>,
}

impl ModelSpec {
    /// The forcing frequency for the imported structure's first natural frequency
    /// `omega_1` ([`Structure::omega_1`] of [`build_imported`], which checks it).
    pub fn omega(&self, omega_1: f64) -> f64 {
        self.frequency.omega(omega_1)
    }

    /// What the scene attaches to the matrices.
    fn attachments(&self) -> Attachments {
        Attachments {
            contacts: self.contacts.clone(),
            friction: self.friction.clone(),
            frictional_contacts: self.frictional_contacts.clone(),
            observed_dof: self.observed_dof,
            damping: self.damping,
            amplitude: self.amplitude,
        }
    }

    /// The file of `part`.
    fn path_of(&self, part: Part) -> PathBuf {
        let none = PathBuf::new;
        match part {
            Part::Mass => self.mass.clone(),
            Part::Stiffness => self.stiffness.clone(),
            Part::Damping => self.damping_matrix.clone().unwrap_or_else(none),
            Part::Load => self.forcing_vector.clone(),
            Part::DofMap => self.dof_map.as_ref().map_or_else(none, |m| m.path.clone()),
        }
    }

    /// The scene key that names the dof of `used_by`.
    fn key_of(&self, used_by: DofUse) -> &'static str {
        let single = |row: &crate::model::ContactRow| row.single().is_some();
        match used_by {
            DofUse::ContactRow { contact } => match self.contacts.get(contact) {
                Some(c) if !single(&c.row) => "contact.point.dofs",
                _ => "contact.point.dof",
            },
            DofUse::ContactTangent { .. } => "contact.point.tangent_dofs",
            DofUse::FrictionRow { point } => match self.friction.get(point) {
                Some(f) if !single(&f.tangent) => "friction.point.dofs",
                _ => "friction.point.dof",
            },
            DofUse::FrictionalContactRow { .. } => "contact.point",
            DofUse::Observed => "output.dof",
        }
    }
}

/// Why an imported model could not be built.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ImportError {
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The system error.
        source: std::io::Error,
    },
    /// A file is larger than [`MAX_MATRIX_FILE_BYTES`] (noticed as it is read).
    #[error(
        "{path}: more than {limit} bytes: allowed at most {limit} bytes for a Matrix Market file"
    )]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// The limit.
        limit: u64,
    },
    /// A file the scene names is not a regular file (a FIFO could block forever, a device
    /// never end).
    #[error("{path}: not a regular file: allowed a regular Matrix Market file")]
    NotRegular {
        /// The file.
        path: PathBuf,
    },
    /// The CalculiX reader rejected the file (the message has the line, what was found and
    /// what is allowed).
    #[error("{path}: not a valid CalculiX matrix file: {message}")]
    CalculiX {
        /// The file.
        path: PathBuf,
        /// The reader's message.
        message: String,
    },
    /// The reader of a finite-element code's matrix file (Abaqus, Nastran DMIG,
    /// Harwell-Boeing) rejected it (the message has the line, what was found and what is
    /// allowed).
    #[error("{path}: not a valid {format} file: {message}")]
    FileFormat {
        /// The file.
        path: PathBuf,
        /// The format, in words (`"Abaqus matrix"`, `"Nastran DMIG"`, `"Harwell-Boeing"`).
        format: &'static str,
        /// The reader's message.
        message: String,
    },
    /// The Matrix Market reader rejected the file (the message has the line, what was
    /// found and what is allowed).
    #[error("{path}: not a valid Matrix Market file: {message}")]
    MatrixMarket {
        /// The file.
        path: PathBuf,
        /// The reader's message.
        message: String,
    },
    /// A matrix or vector has the wrong size.
    #[error("{path}: {what} is {rows} x {cols}: allowed {expected}")]
    Size {
        /// The file.
        path: PathBuf,
        /// `"mass matrix"`, ...
        what: &'static str,
        /// Rows found.
        rows: usize,
        /// Columns found.
        cols: usize,
        /// What is allowed, in words.
        expected: String,
    },
    /// An entry is NaN or infinite.
    #[error("{path}: entry ({row}, {col}) = {value}: allowed finite numbers")]
    NonFinite {
        /// The file.
        path: PathBuf,
        /// 1-based row.
        row: usize,
        /// 1-based column.
        col: usize,
        /// The value found.
        value: f64,
    },
    /// `K` or `M` is not symmetric to round-off.
    #[error(
        "{path}: {what} is not symmetric: entry ({row}, {col}) = {value:e} but ({col}, {row}) = \
         {transposed:e}: allowed |a_ij - a_ji| <= {tolerance:e} (relative {SYMMETRY_TOLERANCE:e} \
         of the largest entry)"
    )]
    NotSymmetric {
        /// The file.
        path: PathBuf,
        /// `"stiffness matrix"` or `"mass matrix"`.
        what: &'static str,
        /// 1-based row.
        row: usize,
        /// 1-based column.
        col: usize,
        /// `a_ij`.
        value: f64,
        /// `a_ji`.
        transposed: f64,
        /// Absolute tolerance.
        tolerance: f64,
    },
    /// A diagonal entry of `M` is negative.
    #[error(
        "{path}: mass matrix entry ({dof}, {dof}) = {value:e}: allowed >= 0 (0: a massless dof)"
    )]
    NegativeMass {
        /// The file.
        path: PathBuf,
        /// 1-based dof.
        dof: usize,
        /// The value found.
        value: f64,
    },
    /// `K` is singular on the free dofs, or `(K, M)` has no finite natural frequency.
    #[error("{path}: {reason}")]
    Stiffness {
        /// The stiffness file.
        path: PathBuf,
        /// What failed.
        reason: String,
    },
    /// A dof named in the scene does not exist.
    #[error("{scene}: invalid `{key}` = {value}: allowed 1..={dofs} (the model has {dofs} dofs)")]
    DofOutOfRange {
        /// The scene file.
        scene: PathBuf,
        /// `contact.point.dof` (`dofs`, `tangent_dofs`), `friction.point.dof` (`dofs`) or
        /// `output.dof`.
        key: &'static str,
        /// The 1-based value found.
        value: usize,
        /// `N`.
        dofs: usize,
    },
    /// A defect of a part as [`crate::import::assemble`] names it, with the part's file.
    #[error("{path}: {source}")]
    Part {
        /// The part's file.
        path: PathBuf,
        /// The defect.
        source: ModelError,
    },
    /// Any other defect of the assembled model or of the forcing frequency.
    #[error("{scene}: {reason}")]
    Model {
        /// The scene file.
        scene: PathBuf,
        /// What is wrong.
        reason: String,
    },
}

/// Reads and checks the files of `spec` (in its [`MatrixFormat`]) and assembles the
/// structure (module documentation). The load vector file is Matrix Market in every format.
pub fn build_imported(spec: &ModelSpec) -> Result<Structure, ImportError> {
    let load_or = |part: Part,
                   path: &Path,
                   read: &dyn Fn() -> Result<SparseMatrix, ImportError>| {
        match part {
            Part::Load => read_matrix(path),
            _ => read(),
        }
    };
    match spec.format {
        MatrixFormat::MatrixMarket => build_imported_with(spec, read_matrix),
        MatrixFormat::CalculiX => {
            let dofs = required_map(spec)?.len();
            build_parts(spec, |part, path| {
                load_or(part, path, &|| read_calculix_matrix(path, dofs))
            })
        }
        MatrixFormat::HarwellBoeing => build_parts(spec, |part, path| {
            load_or(part, path, &|| read_harwell_boeing(path))
        }),
        MatrixFormat::Abaqus => {
            let map = required_map(spec)?;
            let kind = spec.format.file_kind();
            build_parts(spec, |part, path| {
                load_or(part, path, &|| {
                    read_abaqus_matrix(path)?.on_rows(map, path, kind)
                })
            })
        }
        MatrixFormat::NastranDmig => {
            let map = required_map(spec)?;
            let kind = spec.format.file_kind();
            build_parts(spec, |part, path| {
                load_or(part, path, &|| {
                    select_dmig(&read_dmig(path)?, part, path)?.on_rows(map, path, kind)
                })
            })
        }
    }
}

/// The dof map of `spec`, which its format needs (it gives the matrices' rows).
fn required_map(spec: &ModelSpec) -> Result<&DofMap, ImportError> {
    spec.dof_map
        .as_ref()
        .map(|m| m.map.as_ref())
        .ok_or_else(|| ImportError::Model {
            scene: spec.scene.clone(),
            reason: format!(
                "format = \"{}\" without a dof map: allowed a CalculiX model with its .dof \
                 file (which gives the matrices' size), or Abaqus and Nastran files, whose \
                 node labels give it",
                spec.format.name()
            ),
        })
}

/// The dof map of matrix files that name their rows by node and component
/// ([`MatrixFormat::labels_rows`]): every (node, component) that the `files` (each the
/// file of its part; several parts may share a Nastran punch file) name, sorted by node,
/// then component ([`labelled_dof_map`]).
pub fn labelled_files_dof_map(
    format: MatrixFormat,
    files: &[(Part, &Path)],
) -> Result<DofMap, ImportError> {
    let mut matrices = Vec::with_capacity(files.len());
    let mut punch_files: Vec<(&Path, Vec<DmigMatrix>)> = Vec::new();
    for &(part, path) in files {
        let matrix = match format {
            MatrixFormat::Abaqus => read_abaqus_matrix(path)?,
            MatrixFormat::NastranDmig => {
                if !punch_files.iter().any(|(p, _)| *p == path) {
                    punch_files.push((path, read_dmig(path)?));
                }
                let (_, all) = punch_files
                    .iter()
                    .find(|(p, _)| *p == path)
                    .unwrap_or_else(|| unreachable!("the punch file was read just above"));
                select_dmig(all, part, path)?.clone()
            }
            other => {
                return Err(ImportError::Model {
                    scene: path.to_path_buf(),
                    reason: format!(
                        "format = \"{}\" has no node labels in its matrix files: allowed \
                         \"abaqus\" or \"nastran-dmig\"",
                        other.name()
                    ),
                })
            }
        };
        matrices.push(matrix);
    }
    let all: Vec<&LabelledMatrix> = matrices.iter().collect();
    labelled_dof_map(&all).ok_or_else(|| ImportError::Model {
        scene: files
            .first()
            .map_or_else(PathBuf::new, |f| f.1.to_path_buf()),
        reason: "the matrix files name no node: allowed at least one entry".into(),
    })
}

/// [`build_imported`] with the matrices of `spec`'s file names given by `read` (matrices
/// held in memory: `read` maps each path of `spec` to its matrix); the checks are the same.
pub fn build_imported_with(
    spec: &ModelSpec,
    read: impl Fn(&Path) -> Result<SparseMatrix, ImportError>,
) -> Result<Structure, ImportError> {
    build_parts(spec, |_, path| read(path))
}

/// [`build_imported_with`] with `read` told which part it reads.
fn build_parts(
    spec: &ModelSpec,
    read: impl Fn(Part, &Path) -> Result<SparseMatrix, ImportError>,
) -> Result<Structure, ImportError> {
    let stiffness = read(Part::Stiffness, &spec.stiffness)?;
    let mass = read(Part::Mass, &spec.mass)?;
    let damping = spec
        .damping_matrix
        .as_deref()
        .map(|p| read(Part::Damping, p))
        .transpose()?;
    let load = match spec.load_dof {
        Some(dof) => point_load(spec, dof, stiffness.nrows())?,
        None => read(Part::Load, &spec.forcing_vector)?,
    };
    let parts = ModelParts {
        mass,
        stiffness,
        damping,
        load,
        dof_map: spec.dof_map.as_ref().map(|m| m.map.clone()),
    };
    let structure =
        assemble(parts, &spec.attachments()).map_err(|e| ImportError::of_model(spec, e))?;
    let omega = spec.omega(structure.omega_1);
    if !(omega.is_finite() && omega > 0.0) {
        return Err(ImportError::Model {
            scene: spec.scene.clone(),
            reason: format!("forcing omega = {omega}: allowed a finite angular frequency > 0"),
        });
    }
    Ok(structure)
}

/// The load shape of a unit point load on the 0-based `dof` of a model of `dofs` rows.
fn point_load(spec: &ModelSpec, dof: usize, dofs: usize) -> Result<SparseMatrix, ImportError> {
    if dof >= dofs {
        return Err(ImportError::DofOutOfRange {
            scene: spec.scene.clone(),
            key: "forcing.node",
            value: dof + 1,
            dofs,
        });
    }
    let unit = [faer::sparse::Triplet::new(dof, 0, 1.0)];
    SparseMatrix::try_new_from_triplets(dofs, 1, &unit).map_err(|e| ImportError::Model {
        scene: spec.scene.clone(),
        reason: format!("cannot store the point load: {e:?}"),
    })
}

impl ImportError {
    /// `e` as the scene of `spec` gives it: a part's defect names its file, a dof's the
    /// scene and the key that names it.
    pub fn of_model(spec: &ModelSpec, e: ModelError) -> Self {
        let file = |part: Part| spec.path_of(part);
        match e {
            ModelError::Size {
                part,
                rows,
                cols,
                expected,
            } => ImportError::Size {
                path: file(part),
                what: part.name(),
                rows,
                cols,
                expected,
            },
            ModelError::NotSymmetric {
                part,
                row,
                col,
                value,
                transposed,
                tolerance,
            } => ImportError::NotSymmetric {
                path: file(part),
                what: part.name(),
                row,
                col,
                value,
                transposed,
                tolerance,
            },
            ModelError::NegativeMass { dof, value } => ImportError::NegativeMass {
                path: spec.mass.clone(),
                dof,
                value,
            },
            ModelError::Storage { part, message } => ImportError::MatrixMarket {
                path: file(part),
                message,
            },
            ModelError::LoadTooLarge { row, value } => ImportError::Model {
                scene: spec.scene.clone(),
                reason: format!(
                    "the load amplitude x {} entry {row} = {value:e}: allowed magnitudes of at \
                     most {MAX_ENTRY_MAGNITUDE:e} (as the rod's amplitude)",
                    spec.forcing_vector.display(),
                ),
            },
            ModelError::DofOutOfRange {
                used_by,
                value,
                dofs,
            } => ImportError::DofOutOfRange {
                scene: spec.scene.clone(),
                key: spec.key_of(used_by),
                value,
                dofs,
            },
            e @ (ModelError::SingularStiffness { .. }
            | ModelError::NoFrequency { .. }
            | ModelError::FrequencyOutOfRange { .. }) => ImportError::Stiffness {
                path: spec.stiffness.clone(),
                reason: e.to_string(),
            },
            e @ ModelError::DofMapRows { .. } => ImportError::Part {
                path: file(Part::DofMap),
                source: e,
            },
            ModelError::Invalid(reason) => ImportError::Model {
                scene: spec.scene.clone(),
                reason,
            },
        }
    }
}

/// The Matrix Market files of a structure built in code for a `[model]` scene: `K.mtx`,
/// `M.mtx` and the load shape `f.mtx`, as `(file name, text)`.
pub fn model_matrix_files(
    stiffness: &SparseMatrix,
    mass: &SparseMatrix,
    load: &[f64],
) -> [(&'static str, String); 3] {
    [
        ("K.mtx", matrix_market_text(stiffness)),
        ("M.mtx", matrix_market_text(mass)),
        ("f.mtx", vector_market_text(load)),
    ]
}
