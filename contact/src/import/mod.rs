//! Imported structures, independent of the file format: the parts a reader returns
//! ([`ModelParts`]: `M`, `K`, an optional `D`, the load shape and an optional [`DofMap`]),
//! what a structure attaches to them ([`Attachments`]: contacts, friction points, the
//! observed dof, a damping rule, the load amplitude), and [`assemble`], which checks both and
//! builds the [`Structure`] every method runs on. Matrix Market
//! ([`crate::matrix_market`]) is one reader of the parts.
//!
//! The matrices are those of `M u'' + D u' + K u = f(t) + G^T lambda(t)` on the free dofs
//! (the finite-element code has already removed the constrained ones). Contract of
//! [`assemble`] (each violation a [`ModelError`] naming the part, the entry or the use of a
//! dof, with the value and what is allowed; no file or scene key: the caller adds those):
//!
//! - every matrix is square of the stiffness' size `N >= 1`, the load shape is `N x 1`, a
//!   dof map has `N` rows;
//! - `K` and `M` are symmetric to round-off, `|a_ij - a_ji| <= SYMMETRY_TOLERANCE max |a|`
//!   (files written with ten significant digits pass), and are then replaced by
//!   `(A + A^T) / 2`; `D` may be any matrix (e.g. gyroscopic terms);
//! - `M` has no negative diagonal entry; zero rows are massless dofs (allowed, as the rod's
//!   modified mass: their frequencies are infinite and are not counted);
//! - `amplitude x load` is finite with magnitudes of at most [`MAX_ENTRY_MAGNITUDE`];
//! - contact, friction and observed dofs exist (`0..N`);
//! - `K` is nonsingular on the free dofs (its sparse LU has no zero pivot) and the pencil
//!   `(K, M)` has a lowest finite natural frequency `omega_1` in
//!   `[MIN_OMEGA_1, 1 / MIN_OMEGA_1]` (Rayleigh–Ritz / subspace iteration of
//!   [`natural_frequencies`]).
//!
//! Damping `StiffnessProportional { zeta }` gives `D = (2 zeta / omega_1) K`, `Rayleigh`
//! gives `D = alpha M + beta K`, exactly as for the rod.

use std::sync::Arc;

use faer::sparse::Triplet;
use semismooth::linalg::FaerSparseLu;
use semismooth::Factorize;

use crate::dynamic::UnionPattern;
use crate::model::{
    ContactPoint, ContactRow, FrictionPoint, FrictionalContact, SparseMatrix, StructuralModel,
    Structure,
};
use crate::reduction::{lowest_modes, ModeCount, ReductionError, StiffnessFactor};
use crate::rod::{natural_frequencies, DampingSpec};

/// Largest magnitude of an entry of a model (the scale rule of the rod's data and load
/// amplitude).
pub const MAX_ENTRY_MAGNITUDE: f64 = 1e100;

mod ansys_mapping;
mod deck;
mod dof_map;
mod mesh;

pub use deck::IncludeError;
pub use dof_map::{DofMap, DofMapError, NodeComponent, MAX_COMPONENT, MAX_DOF_MAP_BYTES};
pub use mesh::{
    radial_direction, MeshElement, MeshElements, MeshError, MeshNodes, MAX_INCLUDE_DEPTH,
};

/// Smallest first natural frequency of an imported model (its inverse the largest): the
/// rod's scale rule.
pub const MIN_OMEGA_1: f64 = 1e-100;

/// Relative tolerance of the symmetry check of `K` and `M`.
pub const SYMMETRY_TOLERANCE: f64 = 1e-9;

/// The matrices and the load shape of a structure as a reader returns them (any format).
#[derive(Debug, Clone)]
pub struct ModelParts {
    /// `M`, `N x N`.
    pub mass: SparseMatrix,
    /// `K`, `N x N`.
    pub stiffness: SparseMatrix,
    /// `D`, `N x N`, when the format gives one.
    pub damping: Option<SparseMatrix>,
    /// The load shape `f`, `N x 1` (applied as `amplitude * f * cos(omega t)`).
    pub load: SparseMatrix,
    /// The node and component of each row, when the format gives them (shared: a map of
    /// every row of a large model is not copied).
    pub dof_map: Option<Arc<DofMap>>,
}

/// A contact of an imported model: its row of `G` on 0-based dofs, its gap and its friction.
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

/// What a structure attaches to its matrices.
#[derive(Debug, Clone, PartialEq)]
pub struct Attachments {
    /// Contacts.
    pub contacts: Vec<DofContact>,
    /// Friction points under a prescribed normal load.
    pub friction: Vec<DofFriction>,
    /// 3-D frictional contacts (rows 0-based).
    pub frictional_contacts: Vec<FrictionalContact>,
    /// Observed dof (0-based); `None`: the first contact dof, else the first friction
    /// point's, else the first frictional contact's first tangent dof, else the largest
    /// load entry.
    pub observed_dof: Option<usize>,
    /// Damping built from `K` and `M` (not with a damping matrix).
    pub damping: Option<DampingSpec>,
    /// Load amplitude (multiplies the load shape).
    pub amplitude: f64,
}

/// A part of [`ModelParts`], as messages name it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Part {
    /// `M`.
    Mass,
    /// `K`.
    Stiffness,
    /// `D`.
    Damping,
    /// The load shape.
    Load,
    /// The dof map.
    DofMap,
}

impl Part {
    /// The part in words: `"mass matrix"`, ...
    pub fn name(self) -> &'static str {
        match self {
            Part::Mass => "mass matrix",
            Part::Stiffness => "stiffness matrix",
            Part::Damping => "damping matrix",
            Part::Load => "load vector",
            Part::DofMap => "dof map",
        }
    }
}

impl std::fmt::Display for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Where [`Attachments`] name a dof (indices 0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DofUse {
    /// The row of contact `contact`.
    ContactRow {
        /// Index in [`Attachments::contacts`].
        contact: usize,
    },
    /// The tangential row of contact `contact`'s friction.
    ContactTangent {
        /// Index in [`Attachments::contacts`].
        contact: usize,
    },
    /// The row of friction point `point`.
    FrictionRow {
        /// Index in [`Attachments::friction`].
        point: usize,
    },
    /// A row of frictional contact `point`.
    FrictionalContactRow {
        /// Index in [`Attachments::frictional_contacts`].
        point: usize,
    },
    /// [`Attachments::observed_dof`].
    Observed,
}

impl std::fmt::Display for DofUse {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DofUse::ContactRow { contact } => write!(f, "the row of contact {}", contact + 1),
            DofUse::ContactTangent { contact } => {
                write!(f, "the tangential row of contact {}", contact + 1)
            }
            DofUse::FrictionRow { point } => write!(f, "the row of friction point {}", point + 1),
            DofUse::FrictionalContactRow { point } => {
                write!(f, "a row of frictional contact {}", point + 1)
            }
            DofUse::Observed => f.write_str("the observed dof"),
        }
    }
}

/// Why [`assemble`] refused the parts or the attachments.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A part has the wrong size.
    #[error("{part} is {rows} x {cols}: allowed {expected}")]
    Size {
        /// The part.
        part: Part,
        /// Rows found.
        rows: usize,
        /// Columns found.
        cols: usize,
        /// What is allowed, in words.
        expected: String,
    },
    /// `K` or `M` is not symmetric to round-off.
    #[error(
        "{part} is not symmetric: entry ({row}, {col}) = {value:e} but ({col}, {row}) = \
         {transposed:e}: allowed |a_ij - a_ji| <= {tolerance:e} (relative {SYMMETRY_TOLERANCE:e} \
         of the largest entry)"
    )]
    NotSymmetric {
        /// [`Part::Stiffness`] or [`Part::Mass`].
        part: Part,
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
    #[error("mass matrix entry ({dof}, {dof}) = {value:e}: allowed >= 0 (0: a massless dof)")]
    NegativeMass {
        /// 1-based dof.
        dof: usize,
        /// The value found.
        value: f64,
    },
    /// A part's entries could not be stored.
    #[error("{part}: cannot store the entries: {message}")]
    Storage {
        /// The part.
        part: Part,
        /// The storage's message.
        message: String,
    },
    /// The dof map does not have one row per matrix row.
    #[error("the dof map has {rows} rows: allowed {dofs} (one per matrix row)")]
    DofMapRows {
        /// Rows of the map.
        rows: usize,
        /// `N`.
        dofs: usize,
    },
    /// An entry of `amplitude x load` is too large.
    #[error(
        "the load amplitude x load vector entry {row} = {value:e}: allowed magnitudes of at \
         most {MAX_ENTRY_MAGNITUDE:e} (as the rod's amplitude)"
    )]
    LoadTooLarge {
        /// 1-based row.
        row: usize,
        /// The scaled entry.
        value: f64,
    },
    /// A dof of the attachments does not exist.
    #[error("{used_by} names dof {value}: allowed 1..={dofs} (the model has {dofs} dofs)")]
    DofOutOfRange {
        /// Where it is named.
        used_by: DofUse,
        /// The 1-based dof.
        value: usize,
        /// `N`.
        dofs: usize,
    },
    /// `K` is singular on the free dofs.
    #[error(
        "the stiffness matrix is singular on the free dofs ({reason}): remove the rigid-body \
         motions (constrain dofs) before exporting"
    )]
    SingularStiffness {
        /// The factorization's words.
        reason: String,
    },
    /// `(K, M)` has no lowest finite natural frequency.
    #[error("no lowest natural frequency of (K, M): {reason}")]
    NoFrequency {
        /// The eigensolver's words.
        reason: String,
    },
    /// The lowest natural frequency is outside `[MIN_OMEGA_1, 1 / MIN_OMEGA_1]`.
    #[error(
        "the first natural frequency of (K, M) is {omega_1:e}: allowed in [{MIN_OMEGA_1:e}, \
         {:e}] (as the rod's; rescale the units of the model)", 1.0 / MIN_OMEGA_1
    )]
    FrequencyOutOfRange {
        /// `omega_1`.
        omega_1: f64,
    },
    /// The assembled model is not valid (e.g. a contact row of zero norm).
    #[error("{0}")]
    Invalid(String),
}

/// Checks `parts` and `attach` and builds the structure (module documentation).
pub fn assemble(parts: ModelParts, attach: &Attachments) -> Result<Structure, ModelError> {
    let ModelParts {
        mass,
        stiffness,
        damping,
        load,
        dof_map,
    } = parts;
    let n = stiffness.nrows();
    if n == 0 || stiffness.ncols() != n {
        return Err(ModelError::Size {
            part: Part::Stiffness,
            rows: n,
            cols: stiffness.ncols(),
            expected: "N x N with N >= 1".into(),
        });
    }
    let stiffness = symmetrized(&stiffness, Part::Stiffness)?;
    check_square(&mass, n, Part::Mass)?;
    let mass = symmetrized(&mass, Part::Mass)?;
    for dof in 0..n {
        let m = crate::model::diagonal_entry(&mass, dof);
        if m < 0.0 {
            return Err(ModelError::NegativeMass {
                dof: dof + 1,
                value: m,
            });
        }
    }
    if let Some(d) = &damping {
        check_square(d, n, Part::Damping)?;
    }
    let load = scaled_load(&load, n, attach.amplitude)?;
    if let Some(map) = &dof_map {
        if map.len() != n {
            return Err(ModelError::DofMapRows {
                rows: map.len(),
                dofs: n,
            });
        }
    }
    let (contacts, friction, observed_dof) = attached(attach, n, &load)?;
    let mut model = StructuralModel {
        frictional_contacts: attach.frictional_contacts.clone(),
        mass,
        damping,
        stiffness,
        load: crate::model::HarmonicLoad::cosine(load),
        contacts,
        friction,
        cyclic: None,
    };
    let omega_1 = first_frequency(&model)?;
    if let Some(d) = attach.damping {
        model.damping = Some(damping_matrix(&model, d, omega_1));
    }
    model
        .validate()
        .map_err(|e| ModelError::Invalid(e.to_string()))?;
    Ok(Structure {
        model,
        omega_1,
        observed_dof,
    })
}

/// `amplitude x shape` as a dense vector, after checking that `shape` is `n x 1` and every
/// scaled entry finite of magnitude at most [`MAX_ENTRY_MAGNITUDE`].
fn scaled_load(shape: &SparseMatrix, n: usize, amplitude: f64) -> Result<Vec<f64>, ModelError> {
    if shape.nrows() != n || shape.ncols() != 1 {
        return Err(ModelError::Size {
            part: Part::Load,
            rows: shape.nrows(),
            cols: shape.ncols(),
            expected: format!("{n} x 1 (one entry per dof)"),
        });
    }
    let mut load = vec![0.0; n];
    for (i, v) in shape.row_idx_of_col(0).zip(shape.val_of_col(0)) {
        load[i] += amplitude * v;
        if !load[i].is_finite() || load[i].abs() > MAX_ENTRY_MAGNITUDE {
            return Err(ModelError::LoadTooLarge {
                row: i + 1,
                value: load[i],
            });
        }
    }
    Ok(load)
}

/// The contacts, friction points and observed dof of `attach`, every dof checked `< n`.
fn attached(
    attach: &Attachments,
    n: usize,
    load: &[f64],
) -> Result<(Vec<ContactPoint>, Vec<FrictionPoint>, usize), ModelError> {
    let in_range = |used_by: DofUse, dof: usize| {
        if dof < n {
            Ok(dof)
        } else {
            Err(ModelError::DofOutOfRange {
                used_by,
                value: dof + 1,
                dofs: n,
            })
        }
    };
    let row_in_range = |used_by: DofUse, row: &ContactRow| {
        row.dofs()
            .iter()
            .try_for_each(|&d| in_range(used_by, d).map(|_| ()))
    };
    let mut contacts = Vec::with_capacity(attach.contacts.len());
    let mut friction = Vec::new();
    for (i, c) in attach.contacts.iter().enumerate() {
        row_in_range(DofUse::ContactRow { contact: i }, &c.row)?;
        contacts.push(ContactPoint::on_row(c.row.clone(), c.gap));
        if let Some((mu, tangent)) = &c.friction {
            row_in_range(DofUse::ContactTangent { contact: i }, tangent)?;
            friction.push(FrictionPoint::on_contact(tangent.clone(), *mu, i));
        }
    }
    for (point, p) in attach.frictional_contacts.iter().enumerate() {
        for row in p.rows() {
            row_in_range(DofUse::FrictionalContactRow { point }, row)?;
        }
    }
    for (point, f) in attach.friction.iter().enumerate() {
        row_in_range(DofUse::FrictionRow { point }, &f.tangent)?;
        friction.push(FrictionPoint::prescribed(
            f.tangent.clone(),
            f.coefficient,
            f.normal_load,
        ));
    }
    let observed_dof = match attach.observed_dof {
        Some(dof) => in_range(DofUse::Observed, dof)?,
        None => match (contacts.first(), friction.first()) {
            (Some(c), _) => c.dof(),
            (None, Some(f)) => f.tangent.first_dof(),
            (None, None) => match attach.frictional_contacts.first() {
                Some(p) => p.tangents[0].first_dof(),
                None => largest_entry(load),
            },
        },
    };
    Ok((contacts, friction, observed_dof))
}

/// Models with more dofs than this find `omega_1` by shift-invert block Lanczos
/// ([`crate::reduction::lowest_frequencies`]) instead of subspace iteration
/// ([`natural_frequencies`]), which converges slowly on large 3-D models.
pub const LANCZOS_MIN_DOFS: usize = 2000;

/// The lowest finite natural frequency of `(K, M)`, in `[MIN_OMEGA_1, 1 / MIN_OMEGA_1]`,
/// after checking that `K` is nonsingular. A large model's `K` is factored once (sparse
/// Cholesky, LU if not positive definite), for the check and the Lanczos steps both.
fn first_frequency(model: &StructuralModel) -> Result<f64, ModelError> {
    let no_frequency = |reason: String| ModelError::NoFrequency { reason };
    let singular = |reason: String| ModelError::SingularStiffness { reason };
    let omega_1 = if model.dofs() > LANCZOS_MIN_DOFS {
        let mut factor = StiffnessFactor::new(&model.stiffness).map_err(|e| match e {
            ReductionError::Factorization { reason } => singular(reason),
            e => singular(e.to_string()),
        })?;
        lowest_modes(&mut factor, &model.mass, ModeCount::Count(1))
            .map_err(|e| no_frequency(e.to_string()))?
            .omegas[0]
    } else {
        FaerSparseLu::new()
            .factor(&model.stiffness)
            .map_err(|e| singular(e.to_string()))?;
        natural_frequencies(model, 1).map_err(|e| no_frequency(e.to_string()))?[0]
    };
    if !(MIN_OMEGA_1..=1.0 / MIN_OMEGA_1).contains(&omega_1) {
        return Err(ModelError::FrequencyOutOfRange { omega_1 });
    }
    Ok(omega_1)
}

/// The damping matrix of the rule `d` for `model`'s `K` and `M`.
fn damping_matrix(model: &StructuralModel, d: DampingSpec, omega_1: f64) -> SparseMatrix {
    let n = model.dofs();
    match d {
        DampingSpec::StiffnessProportional { zeta } => {
            UnionPattern::linear_combination(n, &[&model.stiffness], &[2.0 * zeta / omega_1])
        }
        DampingSpec::Rayleigh { alpha, beta } => {
            UnionPattern::linear_combination(n, &[&model.stiffness, &model.mass], &[beta, alpha])
        }
    }
}

/// `(A + A^T) / 2` after checking `|a_ij - a_ji| <= SYMMETRY_TOLERANCE max |a|`.
fn symmetrized(a: &SparseMatrix, part: Part) -> Result<SparseMatrix, ModelError> {
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
                return Err(ModelError::NotSymmetric {
                    part,
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
    SparseMatrix::try_new_from_triplets(n, n, &triplets).map_err(|e| ModelError::Storage {
        part,
        message: format!("{e:?}"),
    })
}

/// `Ok` when `a` is `n x n`.
fn check_square(a: &SparseMatrix, n: usize, part: Part) -> Result<(), ModelError> {
    if a.nrows() == n && a.ncols() == n {
        return Ok(());
    }
    Err(ModelError::Size {
        part,
        rows: a.nrows(),
        cols: a.ncols(),
        expected: format!("{n} x {n} (the stiffness matrix' size)"),
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2-dof spring chain `K = [[2, -1], [-1, 1]]`, `M = I`, a unit load on dof 2.
    fn chain() -> ModelParts {
        let sparse = |n: usize, m: usize, t: &[(usize, usize, f64)]| {
            let t: Vec<_> = t.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
            SparseMatrix::try_new_from_triplets(n, m, &t).unwrap()
        };
        ModelParts {
            mass: sparse(2, 2, &[(0, 0, 1.0), (1, 1, 1.0)]),
            stiffness: sparse(
                2,
                2,
                &[(0, 0, 2.0), (1, 0, -1.0), (0, 1, -1.0), (1, 1, 1.0)],
            ),
            damping: None,
            load: sparse(2, 1, &[(1, 0, 1.0)]),
            dof_map: None,
        }
    }

    fn attachments(contact_dof: usize) -> Attachments {
        Attachments {
            contacts: vec![DofContact {
                row: ContactRow::unit(contact_dof, 1.0),
                gap: 0.1,
                friction: None,
            }],
            friction: Vec::new(),
            frictional_contacts: Vec::new(),
            observed_dof: None,
            damping: None,
            amplitude: 2.0,
        }
    }

    #[test]
    fn errors_name_the_part_and_the_use_of_a_dof_not_a_scene_key() {
        let e = assemble(chain(), &attachments(4)).unwrap_err();
        assert_eq!(
            e,
            ModelError::DofOutOfRange {
                used_by: DofUse::ContactRow { contact: 0 },
                value: 5,
                dofs: 2
            }
        );
        let message = e.to_string();
        assert!(
            message.contains("contact 1") && message.contains("1..=2"),
            "{message}"
        );
        assert!(!message.contains("contact.point"), "{message}");
        let mut short_map = chain();
        let rows = vec![NodeComponent {
            node: 3,
            component: 1,
        }];
        short_map.dof_map = Some(Arc::new(DofMap::new(rows).unwrap()));
        assert_eq!(
            assemble(short_map, &attachments(1)).unwrap_err(),
            ModelError::DofMapRows { rows: 1, dofs: 2 }
        );
    }

    #[test]
    fn the_load_is_scaled_by_the_amplitude_and_the_contact_dof_observed_by_default() {
        let s = assemble(chain(), &attachments(1)).unwrap();
        // 2 x 1.0 is exact; the frequency of this chain is checked against its closed form
        // in ssn's imported_model tests.
        assert_eq!(s.model.load.as_cosine(), Some(vec![0.0, 2.0]));
        assert_eq!(s.observed_dof, 1);
    }
}
