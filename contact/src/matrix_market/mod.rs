//! Imported structures: a `[model]` scene's Matrix Market files resolved into the
//! [`Structure`] every method runs on, and the inverse, a rod written as such files.
//!
//! The files hold the matrices of `M u'' + D u' + K u = f(t) + G^T lambda(t)` on the free
//! dofs (the finite-element code has already removed the constrained ones): `M`, `K` and an
//! optional `D`, `N x N`, and the load shape `f`, `N x 1`, applied as
//! `amplitude * f * cos(omega t)`. Matrix Market coordinate (real or integer; general,
//! symmetric or skew-symmetric, the lower triangle then mirrored) and array formats are
//! read by [`read_matrix`] as the file goes, from regular files only, with the declared size
//! checked before it is allocated and every defect named with its line (nalgebra-sparse's
//! reader reads any file whole, allocates what the header declares and reports neither the
//! line nor the value); duplicate coordinate entries are summed (assembly).
//!
//! Contract of [`build_imported`] (each violation is an [`ImportError`] naming the file, and
//! the entry or the key with its value):
//!
//! - every matrix is square of the stiffness' size `N >= 1`, the load vector is `N x 1`,
//!   every entry finite;
//! - `K` and `M` are symmetric to round-off, `|a_ij - a_ji| <= SYMMETRY_TOLERANCE max |a|`
//!   (files written with ten significant digits pass), and are then replaced by
//!   `(A + A^T) / 2`; `D` may be any matrix (e.g. gyroscopic terms);
//! - `M` has no negative diagonal entry; zero rows are massless dofs (allowed, as the rod's
//!   modified mass: their frequencies are infinite and are not counted);
//! - `K` is nonsingular on the free dofs (its sparse LU has no zero pivot) and the pencil
//!   `(K, M)` has a lowest finite natural frequency `omega_1` (Rayleigh–Ritz / subspace
//!   iteration of [`natural_frequencies`]);
//! - contact and observed dofs exist (`1..=N` in the scene, 1-based as in Matrix Market);
//! - the forcing frequency ([`ModelSpec::omega`]) is finite and `> 0`.
//!
//! `[damping] zeta` gives `D = (2 zeta / omega_1) K`, `alpha`/`beta` give
//! `D = alpha M + beta K`, exactly as for the rod; a `damping` file and a `[damping]`
//! section together are an error (of the scene).

use std::path::{Path, PathBuf};

use faer::sparse::Triplet;
use semismooth::linalg::FaerSparseLu;
use semismooth::Factorize;

use crate::dynamic::UnionPattern;
use crate::model::{
    ContactPoint, ContactRow, FrictionPoint, SparseMatrix, StructuralModel, Structure,
};
use crate::rod::{natural_frequencies, DampingSpec, FrequencySpec};

/// Smallest first natural frequency of an imported model (its inverse the largest): the
/// rod's scale rule.
pub const MIN_OMEGA_1: f64 = 1e-100;

/// Relative tolerance of the symmetry check of `K` and `M`.
pub const SYMMETRY_TOLERANCE: f64 = 1e-9;

mod read;

pub use read::{
    matrix_market_text, parse_matrix, read_matrix, vector_market_text, MAX_ENTRY_MAGNITUDE,
    MAX_LINE_BYTES, MAX_MATRIX_DIMENSION, MAX_MATRIX_FILE_BYTES,
};

pub use crate::model::ContactDirection;

/// A contact of an imported model: its row of `G` on 0-based dofs (the scene's `dof` or
/// `dofs` minus one, with `direction` or `coefficients`), its gap and its friction.
#[derive(Debug, Clone, PartialEq)]
pub struct DofContact {
    /// The row of `G`.
    pub row: ContactRow,
    /// Gap (negative: preloaded).
    pub gap: f64,
    /// Coulomb friction on the contact: the coefficient `mu` and the tangential row.
    pub friction: Option<(f64, ContactRow)>,
}

/// A friction point of an imported model under a prescribed normal load.
#[derive(Debug, Clone, PartialEq)]
pub struct DofFriction {
    /// The tangential row on 0-based dofs.
    pub tangent: ContactRow,
    /// The coefficient `mu`.
    pub coefficient: f64,
    /// The normal load `N > 0`.
    pub normal_load: f64,
}

/// Everything a `[model]` scene declares (paths resolved against the scene's directory).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelSpec {
    /// The scene file (for messages).
    pub scene: PathBuf,
    /// Mass matrix file.
    pub mass: PathBuf,
    /// Stiffness matrix file.
    pub stiffness: PathBuf,
    /// Damping matrix file (optional).
    pub damping_matrix: Option<PathBuf>,
    /// Damping from the `[damping]` section (not with a damping file).
    pub damping: Option<DampingSpec>,
    /// Load shape file (`N x 1`).
    pub forcing_vector: PathBuf,
    /// Load amplitude (multiplies the load shape).
    pub amplitude: f64,
    /// Forcing frequency (`Ratio` in units of `omega_1`).
    pub frequency: FrequencySpec,
    /// Contacts.
    pub contacts: Vec<DofContact>,
    /// Friction points under a prescribed normal load (`[[friction.point]]`).
    pub friction: Vec<DofFriction>,
    /// Observed dof (0-based); `None`: the first contact dof, else the first friction
    /// point's, else the largest load entry.
    pub observed_dof: Option<usize>,
}

impl ModelSpec {
    /// The forcing frequency for the imported structure's first natural frequency
    /// `omega_1` ([`Structure::omega_1`] of [`build_imported`], which checks it).
    pub fn omega(&self, omega_1: f64) -> f64 {
        self.frequency.omega(omega_1)
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
    /// Any other defect of the assembled model or of the forcing frequency.
    #[error("{scene}: {reason}")]
    Model {
        /// The scene file.
        scene: PathBuf,
        /// What is wrong.
        reason: String,
    },
}

/// `(A + A^T) / 2` after checking `|a_ij - a_ji| <= SYMMETRY_TOLERANCE max |a|`.
fn symmetrized(
    a: &SparseMatrix,
    path: &Path,
    what: &'static str,
) -> Result<SparseMatrix, ImportError> {
    let n = a.nrows();
    let r = a.as_ref();
    let max = a.val().iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let tolerance = SYMMETRY_TOLERANCE * max;
    let entry = |i: usize, j: usize| -> f64 {
        r.row_idx_of_col(j)
            .zip(r.val_of_col(j))
            .find(|(row, _)| *row == i)
            .map_or(0.0, |(_, v)| *v)
    };
    let mut triplets = Vec::with_capacity(2 * a.val().len());
    for j in 0..n {
        for (i, &v) in r.row_idx_of_col(j).zip(r.val_of_col(j)) {
            let t = entry(j, i);
            if (v - t).abs() > tolerance {
                return Err(ImportError::NotSymmetric {
                    path: path.to_path_buf(),
                    what,
                    row: i + 1,
                    col: j + 1,
                    value: v,
                    transposed: t,
                    tolerance,
                });
            }
            triplets.push(Triplet::new(i, j, 0.5 * v));
            triplets.push(Triplet::new(j, i, 0.5 * v));
        }
    }
    SparseMatrix::try_new_from_triplets(n, n, &triplets).map_err(|e| ImportError::MatrixMarket {
        path: path.to_path_buf(),
        message: format!("{e:?}"),
    })
}

fn check_square(
    a: &SparseMatrix,
    n: usize,
    path: &Path,
    what: &'static str,
) -> Result<(), ImportError> {
    if a.nrows() == n && a.ncols() == n {
        return Ok(());
    }
    Err(ImportError::Size {
        path: path.to_path_buf(),
        what,
        rows: a.nrows(),
        cols: a.ncols(),
        expected: format!("{n} x {n} (the stiffness matrix' size)"),
    })
}

/// Reads and checks the files of `spec` and assembles the structure (module documentation).
pub fn build_imported(spec: &ModelSpec) -> Result<Structure, ImportError> {
    build_imported_with(spec, read_matrix)
}

/// [`build_imported`] with the matrices of `spec`'s file names given by `read` (matrices
/// held in memory: `read` maps each path of `spec` to its matrix); the checks are the same.
pub fn build_imported_with(
    spec: &ModelSpec,
    read: impl Fn(&Path) -> Result<SparseMatrix, ImportError>,
) -> Result<Structure, ImportError> {
    let read_matrix = read;
    let stiffness = read_matrix(&spec.stiffness)?;
    let n = stiffness.nrows();
    if n == 0 || stiffness.ncols() != n {
        return Err(ImportError::Size {
            path: spec.stiffness.clone(),
            what: "stiffness matrix",
            rows: n,
            cols: stiffness.ncols(),
            expected: "N x N with N >= 1".into(),
        });
    }
    let stiffness = symmetrized(&stiffness, &spec.stiffness, "stiffness matrix")?;
    let mass = read_matrix(&spec.mass)?;
    check_square(&mass, n, &spec.mass, "mass matrix")?;
    let mass = symmetrized(&mass, &spec.mass, "mass matrix")?;
    for dof in 0..n {
        let m = crate::model::diagonal_entry(&mass, dof);
        if m < 0.0 {
            return Err(ImportError::NegativeMass {
                path: spec.mass.clone(),
                dof: dof + 1,
                value: m,
            });
        }
    }
    let damping = match &spec.damping_matrix {
        Some(path) => {
            let d = read_matrix(path)?;
            check_square(&d, n, path, "damping matrix")?;
            Some(d)
        }
        None => None,
    };
    let load = read_matrix(&spec.forcing_vector)?;
    if load.nrows() != n || load.ncols() != 1 {
        return Err(ImportError::Size {
            path: spec.forcing_vector.clone(),
            what: "load vector",
            rows: load.nrows(),
            cols: load.ncols(),
            expected: format!("{n} x 1 (one entry per dof)"),
        });
    }
    let shape = load;
    let mut load = vec![0.0; n];
    for (i, v) in shape.row_idx_of_col(0).zip(shape.val_of_col(0)) {
        load[i] += spec.amplitude * v;
        if !load[i].is_finite() || load[i].abs() > MAX_ENTRY_MAGNITUDE {
            return Err(ImportError::Model {
                scene: spec.scene.clone(),
                reason: format!(
                    "the load amplitude x {} entry {} = {:e}: allowed magnitudes of at most \
                     {MAX_ENTRY_MAGNITUDE:e} (as the rod's amplitude)",
                    spec.forcing_vector.display(),
                    i + 1,
                    load[i]
                ),
            });
        }
    }
    let dof_in_range = |key: &'static str, dof: usize| {
        if dof < n {
            Ok(dof)
        } else {
            Err(ImportError::DofOutOfRange {
                scene: spec.scene.clone(),
                key,
                value: dof + 1,
                dofs: n,
            })
        }
    };
    let row_in_range = |one: &'static str, many: &'static str, row: &ContactRow| {
        let key = if row.single().is_some() { one } else { many };
        row.dofs()
            .iter()
            .try_for_each(|&d| dof_in_range(key, d).map(|_| ()))
    };
    let mut contacts = Vec::with_capacity(spec.contacts.len());
    let mut friction = Vec::new();
    for (i, c) in spec.contacts.iter().enumerate() {
        row_in_range("contact.point.dof", "contact.point.dofs", &c.row)?;
        contacts.push(ContactPoint::on_row(c.row.clone(), c.gap));
        if let Some((mu, tangent)) = &c.friction {
            let key = "contact.point.tangent_dofs";
            row_in_range(key, key, tangent)?;
            friction.push(FrictionPoint::on_contact(tangent.clone(), *mu, i));
        }
    }
    for f in &spec.friction {
        row_in_range("friction.point.dof", "friction.point.dofs", &f.tangent)?;
        friction.push(FrictionPoint::prescribed(
            f.tangent.clone(),
            f.coefficient,
            f.normal_load,
        ));
    }
    let observed_dof = match spec.observed_dof {
        Some(dof) => dof_in_range("output.dof", dof)?,
        None => match (contacts.first(), friction.first()) {
            (Some(c), _) => c.dof(),
            (None, Some(f)) => f.tangent.first_dof(),
            (None, None) => largest_entry(&load),
        },
    };
    let stiffness_error = |reason: String| ImportError::Stiffness {
        path: spec.stiffness.clone(),
        reason,
    };
    FaerSparseLu::new().factor(&stiffness).map_err(|e| {
        stiffness_error(format!(
            "the stiffness matrix is singular on the free dofs ({e}): remove the rigid-body \
             motions (constrain dofs) before exporting"
        ))
    })?;
    let mut model = StructuralModel {
        mass,
        damping,
        stiffness,
        load: crate::model::HarmonicLoad::cosine(load),
        contacts,
        friction,
    };
    let omega_1 = natural_frequencies(&model, 1)
        .map_err(|e| stiffness_error(format!("no lowest natural frequency of (K, M): {e}")))?[0];
    if !(MIN_OMEGA_1..=1.0 / MIN_OMEGA_1).contains(&omega_1) {
        return Err(stiffness_error(format!(
            "the first natural frequency of (K, M) is {omega_1:e}: allowed in [{MIN_OMEGA_1:e}, \
             {:e}] (as the rod's; rescale the units of the model)",
            1.0 / MIN_OMEGA_1
        )));
    }
    if let Some(d) = spec.damping {
        model.damping = Some(match d {
            DampingSpec::StiffnessProportional { zeta } => {
                UnionPattern::linear_combination(n, &[&model.stiffness], &[2.0 * zeta / omega_1])
            }
            DampingSpec::Rayleigh { alpha, beta } => UnionPattern::linear_combination(
                n,
                &[&model.stiffness, &model.mass],
                &[beta, alpha],
            ),
        });
    }
    model.validate().map_err(|e| ImportError::Model {
        scene: spec.scene.clone(),
        reason: e.to_string(),
    })?;
    let omega = spec.omega(omega_1);
    if !(omega.is_finite() && omega > 0.0) {
        return Err(ImportError::Model {
            scene: spec.scene.clone(),
            reason: format!("forcing omega = {omega}: allowed a finite angular frequency > 0"),
        });
    }
    Ok(Structure {
        model,
        omega_1,
        observed_dof,
    })
}

/// Index of the entry of largest magnitude (0 for an all-zero vector).
fn largest_entry(v: &[f64]) -> usize {
    let mut best = 0;
    for (i, x) in v.iter().enumerate() {
        if x.abs() > v[best].abs() {
            best = i;
        }
    }
    best
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
