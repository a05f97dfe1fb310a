//! The 3-D Jenkins element: a spring `k_t` in series with the Coulomb slider of a
//! frictional contact, in each tangent direction, as two massless slider dofs.
//!
//! [`with_tangential_stiffness`] appends the slider dofs `s_1, s_2` to the model, adds the
//! springs' energy `k_t / 2 sum_a (g_a . u - s_a)^2` to `K` (the block
//! `k_t [g_a; -e_a] [g_a; -e_a]^T` per direction) and moves the contact's tangent rows onto
//! the sliders: the friction force acts on the sliders and reaches the structure through
//! the springs. The sliders carry no mass, damping or load; the other rows are unchanged.
//! [`expand_tangential_stiffness`] does it for every contact that carries a
//! [`FrictionalContact::tangential_stiffness`](crate::model::FrictionalContact).
//! [`expand_tangential_stiffness`] does it for every contact that carries a
//! [`FrictionalContact::tangential_stiffness`](crate::model::FrictionalContact).

use faer::sparse::Triplet;

use crate::model::{ContactRow, HarmonicLoad, InvalidModel, SparseMatrix, StructuralModel};

/// `matrix` (`n x n`) embedded in `n + extra` dofs, plus the `added` entries.
fn extended(
    matrix: &SparseMatrix,
    extra: usize,
    added: &[Triplet<usize, usize, f64>],
) -> SparseMatrix {
    let n = matrix.nrows() + extra;
    let mut entries: Vec<Triplet<usize, usize, f64>> =
        Vec::with_capacity(matrix.compute_nnz() + added.len());
    let m = matrix.as_ref();
    for j in 0..matrix.ncols() {
        for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            entries.push(Triplet::new(i, j, *v));
        }
    }
    entries.extend_from_slice(added);
    SparseMatrix::try_new_from_triplets(n, n, &entries).expect("entries inside the extended size")
}

/// The model with a 3-D Jenkins element of tangential stiffness `kt` on frictional contact
/// `point` (module documentation): two dofs appended (`dofs()` and `dofs() + 1`, massless),
/// the contact's tangent rows on them. Refused: an unknown contact, `kt` not finite and
/// `> 0`, a cyclic model.
pub fn with_tangential_stiffness(
    model: &StructuralModel,
    point: usize,
    kt: f64,
) -> Result<StructuralModel, InvalidModel> {
    let count = model.frictional_contacts.len();
    let Some(contact) = model.frictional_contacts.get(point) else {
        return Err(InvalidModel::FrictionalContactValue {
            point,
            part: "index (no such frictional contact)",
            value: count as f64,
            allowed: "an index below the number of frictional contacts",
        });
    };
    if !(kt.is_finite() && kt > 0.0) || model.cyclic.is_some() {
        return Err(InvalidModel::FrictionalContactValue {
            point,
            part: "tangential stiffness",
            value: kt,
            allowed: "a finite k_t > 0 on a model without cyclic symmetry",
        });
    }
    let n = model.dofs();
    let mut springs = Vec::new();
    for (a, row) in contact.tangents.iter().enumerate() {
        // [g_a; -e_a] [g_a; -e_a]^T k_t.
        let entries: Vec<(usize, f64)> = row.entries().chain([(n + a, -1.0)]).collect();
        for &(i, gi) in &entries {
            for &(j, gj) in &entries {
                springs.push(Triplet::new(i, j, kt * gi * gj));
            }
        }
    }
    let mut load = HarmonicLoad::zero(n + 2);
    for harmonic in model.load.harmonics() {
        let pad = |v: &[f64]| [v, &[0.0, 0.0]].concat();
        load.add_harmonic(
            harmonic.harmonic,
            &pad(&harmonic.cosine),
            &pad(&harmonic.sine),
        )?;
    }
    let mut out = StructuralModel {
        mass: extended(&model.mass, 2, &[]),
        damping: model.damping.as_ref().map(|d| extended(d, 2, &[])),
        stiffness: extended(&model.stiffness, 2, &springs),
        load,
        ..model.clone()
    };
    let contact = &mut out.frictional_contacts[point];
    contact.tangents = [ContactRow::unit(n, 1.0), ContactRow::unit(n + 1, 1.0)];
    contact.tangential_stiffness = None;
    Ok(out)
}

/// The model with the slider dofs of every frictional contact that carries a tangential
/// stiffness ([`with_tangential_stiffness`], in the contacts' order); unchanged without one.
pub fn expand_tangential_stiffness(
    model: StructuralModel,
) -> Result<StructuralModel, InvalidModel> {
    let mut model = model;
    for point in 0..model.frictional_contacts.len() {
        if let Some(kt) = model.frictional_contacts[point].tangential_stiffness {
            model = with_tangential_stiffness(&model, point, kt)?;
        }
    }
    Ok(model)
}

/// Refuses a model whose frictional contact still carries a tangential stiffness (the
/// solvers see only the expanded slider dofs).
pub(crate) fn refuse_unexpanded(model: &StructuralModel) -> Result<(), InvalidModel> {
    let carried = (model.frictional_contacts.iter().enumerate())
        .find_map(|(p, c)| c.tangential_stiffness.map(|kt| (p, kt)));
    match carried {
        Some((point, value)) => Err(InvalidModel::FrictionalContactValue {
            point,
            part: "tangential stiffness not expanded",
            value,
            allowed: "slider dofs written by jenkins::expand_tangential_stiffness",
        }),
        None => Ok(()),
    }
}
