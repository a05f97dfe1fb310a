//! Component mode synthesis: a structure reduced onto its boundary dofs (contacts,
//! friction, observed and loaded dofs) and a few modes of its interior.
//!
//! Craig–Bampton: with the dofs split into boundary `b` and interior `i`,
//! `u = T [u_b; q]`, `T = [[I, 0], [Psi, Phi]]`, the static constraint modes
//! `Psi = -K_ii^{-1} K_ib` and the fixed-interface modes `Phi` of `(K_ii, M_ii)`
//! (`M`-normalised, the lowest by count or below a frequency; [`lowest_modes`]). The reduced
//! matrices are `T^T K T`, `T^T M T`, `T^T D T` (dense, of size `n_b + n_m`), the load
//! `T^T f`; the boundary coordinates are the boundary dofs themselves, so contact and
//! friction rows and the observed dof keep their meaning (renumbered). The boundary keeps
//! its mass. With every interior mode the reduction is exact (`T` square and invertible);
//! the reduced frequencies bound the full ones from above (Rayleigh–Ritz).
//!
//! [`massless_boundary`] reduces onto the same boundary with free-interface modes and
//! residual flexibility (MacNeal), the boundary massless; [`modal_damping`] gives a reduced
//! model modal damping.
//!
//! Reference: Craig & Bampton (1968), coupling of substructures for dynamic analyses.

use faer::sparse::Triplet;

use crate::model::{
    ContactPoint, ContactRow, FrictionPoint, HarmonicLoad, SparseMatrix, StructuralModel, Structure,
};

mod cholesky;
mod damping;
mod massless;
mod modes;

pub use damping::modal_damping;
pub use massless::massless_boundary;

pub(crate) use cholesky::StiffnessFactor;

pub use modes::{lowest_modes, ModeCount, Modes, BLOCK, MODE_TOLERANCE};

/// Why a structure could not be reduced.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReductionError {
    /// `K` (or `K_ii`) could not be factored.
    #[error("the stiffness matrix could not be factored: {reason}")]
    Factorization {
        /// The factorization's words.
        reason: String,
    },
    /// The projected eigenproblem failed.
    #[error("the projected eigenproblem failed: {reason}")]
    Eigen {
        /// The eigensolver's words.
        reason: String,
    },
    /// Fewer finite frequencies than requested.
    #[error("{requested} modes requested: allowed at most {available} (the finite frequencies of the pencil)")]
    TooFewModes {
        /// Requested.
        requested: usize,
        /// Available.
        available: usize,
    },
    /// Every dof is a boundary dof: nothing to reduce.
    #[error("every one of the {dofs} dofs is a boundary dof: allowed a model with interior dofs")]
    NoInterior {
        /// `N`.
        dofs: usize,
    },
    /// A boundary dof does not exist.
    #[error("boundary dof {dof} (1-based): allowed 1..={dofs}")]
    DofOutOfRange {
        /// The 1-based dof.
        dof: usize,
        /// `N`.
        dofs: usize,
    },
    /// The reduced model is not valid.
    #[error("the reduced model is not valid: {0}")]
    Invalid(String),
}

/// A structure reduced by Craig–Bampton (module documentation) or by the massless-boundary
/// reduction ([`massless_boundary`]: then the interface frequencies are the free-interface
/// ones).
#[derive(Debug, Clone)]
#[non_exhaustive]
pub struct CraigBampton {
    /// The reduced structure: coordinates `[u_b; q]`, its contacts, friction points,
    /// observed dof and load on them, its `omega_1` the reduced model's.
    pub structure: Structure,
    /// The boundary dofs of the full model (ascending): reduced coordinate `k` is dof
    /// `boundary[k]`.
    pub boundary: Vec<usize>,
    /// The fixed-interface frequencies kept (ascending).
    pub interface_frequencies: Vec<f64>,
    /// The columns of `T` (each of the full model's length): `u = sum_k T_k x_k`.
    pub transform: Vec<Vec<f64>>,
}

impl CraigBampton {
    /// The full model's displacement of the reduced coordinates `x` (`u = T x`).
    pub fn recover(&self, x: &[f64]) -> Vec<f64> {
        let n = self.transform.first().map_or(0, Vec::len);
        let mut u = vec![0.0; n];
        for (t, &c) in self.transform.iter().zip(x) {
            u.iter_mut().zip(t).for_each(|(u, t)| *u += c * t);
        }
        u
    }
}

/// The boundary dofs of `model`: every dof of a contact or friction row, the observed dof,
/// every dof a load harmonic touches, and `extra`; ascending, each once.
pub fn boundary_dofs(structure: &Structure, extra: &[usize]) -> Vec<usize> {
    let model = &structure.model;
    let mut b: Vec<usize> = extra.to_vec();
    b.push(structure.observed_dof);
    for c in &model.contacts {
        b.extend_from_slice(c.row.dofs());
    }
    for f in &model.friction {
        b.extend_from_slice(f.tangent.dofs());
    }
    for row in model.frictional_contacts.iter().flat_map(|c| c.rows()) {
        b.extend_from_slice(row.dofs());
    }
    for h in model.load.harmonics() {
        for (i, (c, s)) in h.cosine.iter().zip(&h.sine).enumerate() {
            if *c != 0.0 || *s != 0.0 {
                b.push(i);
            }
        }
    }
    b.sort_unstable();
    b.dedup();
    b
}

/// Reduces `full` onto `boundary` (ascending, distinct) and the fixed-interface modes
/// `modes` of its interior (module documentation).
pub fn craig_bampton(
    full: &Structure,
    boundary: &[usize],
    modes: ModeCount,
) -> Result<CraigBampton, ReductionError> {
    let model = &full.model;
    let n = model.dofs();
    check_boundary(boundary, n)?;
    // Position of each dof: Ok(boundary index) or Err(interior index).
    let mut place = vec![Err(0); n];
    for (k, &d) in boundary.iter().enumerate() {
        place[d] = Ok(k);
    }
    let interior: Vec<usize> = (0..n).filter(|&d| place[d].is_err()).collect();
    if interior.is_empty() {
        return Err(ReductionError::NoInterior { dofs: n });
    }
    for (k, &d) in interior.iter().enumerate() {
        place[d] = Err(k);
    }
    let (k_ii, k_ib) = split(&model.stiffness, &place, interior.len(), boundary.len())?;
    let (m_ii, _) = split(&model.mass, &place, interior.len(), boundary.len())?;
    let mut lu = StiffnessFactor::new(&k_ii)?;
    let fixed = lowest_modes(&mut lu, &m_ii, modes)?;
    let mut transform = Vec::with_capacity(boundary.len() + fixed.shapes.len());
    for (k, mut psi) in k_ib.into_iter().enumerate() {
        semismooth::LinearSolve::solve_in_place(&mut lu, &mut psi).map_err(|e| {
            ReductionError::Factorization {
                reason: e.to_string(),
            }
        })?;
        let mut t = scatter(&psi, &interior, n, -1.0);
        t[boundary[k]] = 1.0;
        transform.push(t);
    }
    for phi in &fixed.shapes {
        transform.push(scatter(phi, &interior, n, 1.0));
    }
    let structure = reduced_structure(full, boundary, &transform)?;
    Ok(CraigBampton {
        structure,
        boundary: boundary.to_vec(),
        interface_frequencies: fixed.omegas,
        transform,
    })
}

/// Every boundary dof exists (`< n`) and leaves an interior.
fn check_boundary(boundary: &[usize], n: usize) -> Result<(), ReductionError> {
    if let Some(&d) = boundary.iter().find(|&&d| d >= n) {
        return Err(ReductionError::DofOutOfRange {
            dof: d + 1,
            dofs: n,
        });
    }
    if boundary.len() >= n {
        return Err(ReductionError::NoInterior { dofs: n });
    }
    Ok(())
}

/// `scale v` placed on the `interior` dofs of a vector of length `n`.
fn scatter(v: &[f64], interior: &[usize], n: usize, scale: f64) -> Vec<f64> {
    let mut t = vec![0.0; n];
    for (&d, &x) in interior.iter().zip(v) {
        t[d] = scale * x;
    }
    t
}

/// `A_ii` (sparse) and the columns of `A_ib` (dense, over the interior) of `a`.
fn split(
    a: &SparseMatrix,
    place: &[Result<usize, usize>],
    interior: usize,
    boundary: usize,
) -> Result<(SparseMatrix, Vec<Vec<f64>>), ReductionError> {
    let r = a.as_ref();
    let mut ii = Vec::new();
    let mut ib = vec![vec![0.0; interior]; boundary];
    for j in 0..a.ncols() {
        for (i, &v) in r.row_idx_of_col(j).zip(r.val_of_col(j)) {
            match (place[i], place[j]) {
                (Err(p), Err(q)) => ii.push(Triplet::new(p, q, v)),
                (Err(p), Ok(q)) => ib[q][p] += v,
                _ => {}
            }
        }
    }
    let ii = SparseMatrix::try_new_from_triplets(interior, interior, &ii)
        .map_err(|e| ReductionError::Invalid(format!("cannot store K_ii: {e:?}")))?;
    Ok((ii, ib))
}

/// `T^T A T` (symmetrised when `symmetric`) as a dense-pattern sparse matrix.
fn projected(
    a: &SparseMatrix,
    t: &[Vec<f64>],
    symmetric: bool,
) -> Result<SparseMatrix, ReductionError> {
    let at: Vec<Vec<f64>> = t.iter().map(|c| modes::times(a, c)).collect();
    let r = t.len();
    let dot = |x: &[f64], y: &[f64]| -> f64 { x.iter().zip(y).map(|(a, b)| a * b).sum() };
    let mut triplets = Vec::with_capacity(r * r);
    for j in 0..r {
        for i in 0..r {
            let v = match symmetric {
                true => 0.5 * (dot(&t[i], &at[j]) + dot(&t[j], &at[i])),
                false => dot(&t[i], &at[j]),
            };
            triplets.push(Triplet::new(i, j, v));
        }
    }
    SparseMatrix::try_new_from_triplets(r, r, &triplets)
        .map_err(|e| ReductionError::Invalid(format!("cannot store a reduced matrix: {e:?}")))
}

/// The reduced structure of `full` through `t` (boundary coordinates first).
fn reduced_structure(
    full: &Structure,
    boundary: &[usize],
    t: &[Vec<f64>],
) -> Result<Structure, ReductionError> {
    let model = &full.model;
    if model.cyclic.is_some() {
        let why = "a cyclic sector's interface couplings are not reduced: reduce the sector \
                   before it is made cyclic";
        return Err(ReductionError::Invalid(why.into()));
    }
    let r = t.len();
    let dot = |x: &[f64], y: &[f64]| -> f64 { x.iter().zip(y).map(|(a, b)| a * b).sum() };
    let mut load = HarmonicLoad::zero(r);
    for h in model.load.harmonics() {
        let cosine: Vec<f64> = t.iter().map(|c| dot(c, &h.cosine)).collect();
        let sine: Vec<f64> = t.iter().map(|c| dot(c, &h.sine)).collect();
        load.add_harmonic(h.harmonic, &cosine, &sine)
            .map_err(|e| ReductionError::Invalid(e.to_string()))?;
    }
    let at = |d: usize| boundary.binary_search(&d).expect("a boundary dof");
    let row = |row: &ContactRow| {
        let dofs = row.dofs().iter().map(|&d| at(d)).collect();
        ContactRow::new(dofs, row.coefficients().to_vec())
            .map_err(|e| ReductionError::Invalid(e.to_string()))
    };
    let contacts = model
        .contacts
        .iter()
        .map(|c| Ok(ContactPoint::on_row(row(&c.row)?, c.gap)))
        .collect::<Result<_, ReductionError>>()?;
    let friction = model
        .friction
        .iter()
        .map(|f| {
            Ok(FrictionPoint {
                tangent: row(&f.tangent)?,
                ..f.clone()
            })
        })
        .collect::<Result<_, ReductionError>>()?;
    let reduced = StructuralModel {
        mass: projected(&model.mass, t, true)?,
        damping: model
            .damping
            .as_ref()
            .map(|d| projected(d, t, false))
            .transpose()?,
        stiffness: projected(&model.stiffness, t, true)?,
        load,
        contacts,
        friction,
        cyclic: None,
        frictional_contacts: (model.frictional_contacts.iter())
            .map(|c| c.with_rows(row))
            .collect::<Result<_, ReductionError>>()?,
    };
    reduced
        .validate()
        .map_err(|e| ReductionError::Invalid(e.to_string()))?;
    let omega_1 = lowest_frequencies(&reduced, 1)?[0];
    Ok(Structure {
        model: reduced,
        omega_1,
        observed_dof: at(full.observed_dof),
    })
}

/// The lowest `count` natural frequencies of `model` (ascending) by [`lowest_modes`] on
/// one sparse factorization of `K` (Cholesky, or LU when `K` is not positive definite).
pub fn lowest_frequencies(
    model: &StructuralModel,
    count: usize,
) -> Result<Vec<f64>, ReductionError> {
    let mut lu = StiffnessFactor::new(&model.stiffness)?;
    Ok(lowest_modes(&mut lu, &model.mass, ModeCount::Count(count))?.omegas)
}
