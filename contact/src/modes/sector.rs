//! Nonlinear modes of a reduced cyclic sector ([`crate::cyclic`]): harmonic `k` of the
//! motion lives on nodal diameter `k EO mod N`, where the interface couplings enter with
//! the phase `e^{i sign k phi}`, `phi = 2 pi EO / N`. When `phi` is a multiple of `pi`
//! (engine order 0, or `N / 2` for even `N`) every phase is real, `cos(k phi) = +-1`, and
//! harmonic `k` of the sector is the real model `A + cos(k phi) sum_t B_t` of each source:
//! harmonic 1's linear mode is a standing wave of the disk on nodal diameter 0 (or
//! `N / 2`), a real shape on the sector's dofs, and the EPMC start of [`super::Epmc`].
//! Other engine orders put harmonic 1 on a travelling wave (a complex shape) and are
//! refused.

use std::collections::BTreeMap;

use super::ModesError;
use crate::dynamic::UnionPattern;
use crate::model::{
    ContactRow, CouplingSource, CyclicCoupling, FrictionPoint, SparseMatrix, StructuralModel,
};

/// How far `sin(phi)` may be from zero for the phase to count as real (rounding of
/// `2 pi EO / N`).
const REAL_PHASE_TOLERANCE: f64 = 1e-9;

/// `cos(k phi)` of the sector's couplings when the phase is real (`+-1`), else the
/// refusal that names harmonic 1's nodal diameter.
fn real_phase(coupling: &CyclicCoupling, k: usize) -> Result<f64, ModesError> {
    let phi = coupling.phase_step;
    if phi.sin().abs() > REAL_PHASE_TOLERANCE {
        let n = coupling.sectors.max(1);
        let turns = (phi * n as f64 / (2.0 * std::f64::consts::PI)).round() as i64;
        let d = turns.rem_euclid(n as i64) as usize;
        return Err(ModesError::TravellingWaveSector {
            nodal_diameter: d.min(n - d),
            sectors: n,
        });
    }
    Ok(if (k as f64 * phi).cos() >= 0.0 {
        1.0
    } else {
        -1.0
    })
}

/// `a + cos(k phi) sum_t B_t` over the coupling terms of `source` (`a` itself without
/// them).
fn harmonic_matrix(
    a: &SparseMatrix,
    coupling: &CyclicCoupling,
    source: CouplingSource,
    k: usize,
) -> Result<SparseMatrix, ModesError> {
    let cos = real_phase(coupling, k)?;
    let terms: Vec<&SparseMatrix> = (coupling.terms.iter())
        .filter(|t| t.source == source)
        .map(|t| &t.matrix)
        .collect();
    if terms.is_empty() {
        return Ok(a.clone());
    }
    let sources: Vec<&SparseMatrix> = std::iter::once(a).chain(terms.iter().copied()).collect();
    let coefficients: Vec<f64> = std::iter::once(1.0)
        .chain(terms.iter().map(|_| cos))
        .collect();
    Ok(UnionPattern::linear_combination(
        a.nrows(),
        &sources,
        &coefficients,
    ))
}

/// Row `row` plus `cos(k phi)` times its neighbour part `part`, merged by dof.
fn merged_row(row: &ContactRow, part: &ContactRow, cos: f64) -> ContactRow {
    let mut entries = BTreeMap::new();
    for (dof, c) in row.entries() {
        *entries.entry(dof).or_insert(0.0) += c;
    }
    for (dof, c) in part.entries() {
        *entries.entry(dof).or_insert(0.0) += cos * c;
    }
    let (dofs, coefficients) = entries.into_iter().unzip();
    ContactRow::new(dofs, coefficients).expect("the dofs of two valid rows")
}

/// The real model of harmonic `k` of the reduced sector `model` (module documentation):
/// `K`, `M`, `D` with their couplings at the real phase `cos(k phi)`, the friction points'
/// tangential rows with their neighbour parts at that phase, no couplings left; the model
/// itself when it is no sector. [`ModesError::TravellingWaveSector`] when the phase is
/// not real.
pub(super) fn harmonic_model(
    model: &StructuralModel,
    k: usize,
) -> Result<StructuralModel, ModesError> {
    let Some(coupling) = &model.cyclic else {
        return Ok(model.clone());
    };
    let cos = real_phase(coupling, k)?;
    let mut real = model.clone();
    real.cyclic = None;
    real.stiffness = harmonic_matrix(&model.stiffness, coupling, CouplingSource::Stiffness, k)?;
    real.mass = harmonic_matrix(&model.mass, coupling, CouplingSource::Mass, k)?;
    real.damping = (model.damping.as_ref())
        .map(|d| harmonic_matrix(d, coupling, CouplingSource::Damping, k))
        .transpose()?;
    let contacts = model.contacts.len();
    for neighbour in &coupling.neighbour_rows {
        if let Some(point) =
            (neighbour.row.checked_sub(contacts)).and_then(|f| real.friction.get_mut(f))
        {
            *point = FrictionPoint {
                tangent: merged_row(&point.tangent, &neighbour.part, cos),
                ..point.clone()
            };
        }
    }
    Ok(real)
}

/// The stiffness and mass of each harmonic `0..=harmonics` of the sector `model` (their
/// [`harmonic_model`]s), for the energy; one pair for every harmonic when `model` is no
/// sector.
pub(super) fn harmonic_stiffness_and_mass(
    model: &StructuralModel,
    harmonics: usize,
) -> Result<Vec<(SparseMatrix, SparseMatrix)>, ModesError> {
    let count = if model.cyclic.is_some() {
        harmonics + 1
    } else {
        1
    };
    (0..count)
        .map(|k| harmonic_model(model, k).map(|m| (m.stiffness, m.mass)))
        .collect()
}
