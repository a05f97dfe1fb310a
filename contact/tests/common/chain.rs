//! The two-dof chain with a stop on its free mass (a contact on a dof that carries mass),
//! shared by a test and an example.

use faer::sparse::Triplet;
use semismooth_contact::model::{
    ContactPoint, HarmonicLoad, SparseMatrix, StructuralModel, Structure,
};

fn matrix(entries: &[(usize, usize, f64)]) -> SparseMatrix {
    let t: Vec<_> = entries
        .iter()
        .map(|&(i, j, v)| Triplet::new(i, j, v))
        .collect();
    SparseMatrix::try_new_from_triplets(2, 2, &t).unwrap()
}

/// Unit masses and springs (ground - 0 - 1), stiffness-proportional damping of ratio
/// `zeta` at the first mode, the forces `load` on the masses and a stop at `gap` from the
/// free mass 1 (observed).
pub fn chain(gap: f64, zeta: f64, load: [f64; 2]) -> Structure {
    chain_with_masses([1.0, 1.0], 1, gap, zeta, load)
}

/// Springs of unit stiffness ground - 0 - 1, masses `masses`, stiffness-proportional
/// damping of ratio `zeta` at the first mode, the forces `load` and a stop at `gap` from
/// `contact_dof` (observed).
pub fn chain_with_masses(
    masses: [f64; 2],
    contact_dof: usize,
    gap: f64,
    zeta: f64,
    load: [f64; 2],
) -> Structure {
    let [m0, m1] = masses;
    // det(K - λ M) = m0 m1 λ² - (m0 + 2 m1) λ + 1 = 0: the smaller root is ω_1².
    let b = m0 + 2.0 * m1;
    let omega_1 = ((b - (b * b - 4.0 * m0 * m1).sqrt()) / (2.0 * m0 * m1)).sqrt();
    let c = 2.0 * zeta / omega_1;
    let model = StructuralModel {
        frictional_contacts: Vec::new(),
        mass: matrix(&[(0, 0, m0), (1, 1, m1)]),
        damping: Some(matrix(&[
            (0, 0, 2.0 * c),
            (0, 1, -c),
            (1, 0, -c),
            (1, 1, c),
        ])),
        stiffness: matrix(&[(0, 0, 2.0), (0, 1, -1.0), (1, 0, -1.0), (1, 1, 1.0)]),
        load: HarmonicLoad::cosine(load.to_vec()),
        contacts: vec![ContactPoint::new(contact_dof, gap)],
        friction: Vec::new(),
        cyclic: None,
    };
    Structure {
        model,
        omega_1,
        observed_dof: contact_dof,
    }
}
