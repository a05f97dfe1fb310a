//! A structure from its matrices, in code: the shortest route from `M`, `K`, the load
//! shape `f` and the contacts to a [`Structure`] every method solves.
//!
//! ```
//! use semismooth_contact::builder::sparse_matrix;
//! use semismooth_contact::model::{ContactPoint, StructuralModel, Structure};
//!
//! // Two unit masses on springs of stiffness 1 to the ground and between them, the second
//! // against a stop 0.1 away.
//! let k = sparse_matrix(2, &[(0, 0, 2.0), (0, 1, -1.0), (1, 0, -1.0), (1, 1, 2.0)]).unwrap();
//! let m = sparse_matrix(2, &[(0, 0, 1.0), (1, 1, 1.0)]).unwrap();
//! let model = StructuralModel::new(m, k, vec![0.0, 1.0])
//!     .with_rayleigh_damping(0.0, 0.02)
//!     .with_contact(ContactPoint::new(1, 0.1));
//! let structure = Structure::new(model, 1).unwrap();
//! assert!((structure.omega_1 - 1.0).abs() < 1e-12); // the in-phase mode, sqrt(k / m)
//! ```

use faer::sparse::Triplet;

use crate::dynamic::UnionPattern;
use crate::model::{
    ContactPoint, FrictionPoint, FrictionalContact, HarmonicLoad, InvalidModel, SparseMatrix,
    StructuralModel, Structure,
};
use crate::rod::{natural_frequencies, ModelError};

/// Why a [`Structure`] could not be built from its model.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StructureError {
    /// The model is not valid ([`StructuralModel::validate`]).
    #[error(transparent)]
    Invalid(#[from] InvalidModel),
    /// Its first natural frequency could not be computed (a singular `K`, no mass).
    #[error(transparent)]
    Frequencies(#[from] ModelError),
}

/// A square `n x n` sparse matrix from `(row, column, value)` entries, duplicates summed
/// (assembly); `Err` for an entry outside the matrix.
pub fn sparse_matrix(
    n: usize,
    entries: &[(usize, usize, f64)],
) -> Result<SparseMatrix, InvalidModel> {
    if let Some(&(row, col, _)) = entries.iter().find(|(i, j, _)| *i >= n || *j >= n) {
        return Err(InvalidModel::EntryOutOfRange { row, col, dofs: n });
    }
    let triplets: Vec<Triplet<usize, usize, f64>> = entries
        .iter()
        .map(|&(i, j, v)| Triplet::new(i, j, v))
        .collect();
    SparseMatrix::try_new_from_triplets(n, n, &triplets).map_err(|_| InvalidModel::Assembly {
        dofs: n,
        entries: entries.len(),
    })
}

impl StructuralModel {
    /// `M u'' + K u = load cos(omega t)`: no damping and no contact until they are added.
    pub fn new(mass: SparseMatrix, stiffness: SparseMatrix, load: Vec<f64>) -> Self {
        Self {
            frictional_contacts: Vec::new(),
            mass,
            damping: None,
            stiffness,
            load: HarmonicLoad::cosine(load),
            contacts: Vec::new(),
            friction: Vec::new(),
            cyclic: None,
        }
    }

    /// The model with the external force `load` in place of its own.
    pub fn with_load(self, load: HarmonicLoad) -> Self {
        Self { load, ..self }
    }

    /// The model with the damping matrix `D`.
    pub fn with_damping(self, damping: SparseMatrix) -> Self {
        Self {
            damping: Some(damping),
            ..self
        }
    }

    /// The model with Rayleigh damping `D = alpha M + beta K`.
    pub fn with_rayleigh_damping(self, alpha: f64, beta: f64) -> Self {
        let d = UnionPattern::linear_combination(
            self.dofs(),
            &[&self.mass, &self.stiffness],
            &[alpha, beta],
        );
        self.with_damping(d)
    }

    /// The model with one more contact.
    pub fn with_contact(mut self, contact: ContactPoint) -> Self {
        self.contacts.push(contact);
        self
    }

    /// The model with one more Coulomb friction point.
    pub fn with_friction(mut self, point: FrictionPoint) -> Self {
        self.friction.push(point);
        self
    }

    /// The model with one more 3-D frictional contact.
    pub fn with_frictional_contact(mut self, point: FrictionalContact) -> Self {
        self.frictional_contacts.push(point);
        self
    }
}

impl Structure {
    /// The structure of `model` observed at `observed_dof`: the model validated
    /// ([`StructuralModel::validate`]) and its first finite natural frequency `omega_1`
    /// computed (the unit of frequency ratios and of the sweeps' step lengths).
    pub fn new(model: StructuralModel, observed_dof: usize) -> Result<Self, StructureError> {
        model.validate()?;
        model.check_observed(&[observed_dof])?;
        let omega_1 = natural_frequencies(&model, 1)?[0];
        Ok(Self {
            model,
            omega_1,
            observed_dof,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 2-dof chain's frequencies are 1 and sqrt(3); its Rayleigh damping matrix is
    /// `alpha M + beta K` entry by entry; a stop out of range names the dof.
    #[test]
    fn a_chain_built_in_code_has_its_analytic_frequency_and_damping() {
        let k = sparse_matrix(2, &[(0, 0, 2.0), (0, 1, -1.0), (1, 0, -1.0), (1, 1, 2.0)]).unwrap();
        let m = sparse_matrix(2, &[(0, 0, 1.0), (1, 1, 1.0)]).unwrap();
        let model = StructuralModel::new(m, k, vec![0.0, 1.0]).with_rayleigh_damping(0.5, 0.25);
        let d = model.damping.as_ref().unwrap();
        for (i, j, want) in [(0, 0, 1.0), (0, 1, -0.25), (1, 1, 1.0)] {
            let got = semismooth::linalg::diagonal_entry(d.as_ref(), i)
                .filter(|_| i == j)
                .unwrap_or_else(|| {
                    let col = d.as_ref();
                    col.row_idx_of_col(j)
                        .zip(col.val_of_col(j))
                        .find(|(r, _)| *r == i)
                        .map_or(0.0, |(_, v)| *v)
                });
            assert!((got - want).abs() < 1e-15, "D[{i}][{j}] = {got}");
        }
        let structure = Structure::new(model.clone(), 1).unwrap();
        assert!((structure.omega_1 - 1.0).abs() < 1e-12);
        let bad = model.with_contact(ContactPoint::new(2, 0.1));
        assert!(matches!(
            Structure::new(bad, 1),
            Err(StructureError::Invalid(
                InvalidModel::ContactDofOutOfRange { dof: 2, .. }
            ))
        ));
        assert!(matches!(
            sparse_matrix(2, &[(2, 0, 1.0)]),
            Err(InvalidModel::EntryOutOfRange {
                row: 2,
                col: 0,
                dofs: 2
            })
        ));
    }
}
