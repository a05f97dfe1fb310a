//! Modal damping of a reduced model: `D = sum_k 2 zeta omega_k (M phi_k) (M phi_k)^T` over
//! every finite mode `(omega_k, phi_k)` of `(K, M)`, `phi_k` `M`-normalised, so that each
//! modal coordinate obeys `q_k'' + 2 zeta omega_k q_k' + omega_k^2 q_k = phi_k^T f` (the
//! modes' damping ratio is `zeta`, none coupled to another). `D` is dense: meant for a
//! reduced model of a few hundred coordinates, not for the full one.

use faer::sparse::Triplet;

use crate::model::{SparseMatrix, StructuralModel};

use super::modes::times;
use super::{lowest_modes, ModeCount, ReductionError, StiffnessFactor};

/// The modal damping matrix of ratio `zeta` of `model` (module documentation).
pub fn modal_damping(model: &StructuralModel, zeta: f64) -> Result<SparseMatrix, ReductionError> {
    if !(zeta.is_finite() && zeta >= 0.0) {
        return Err(ReductionError::Invalid(format!(
            "modal damping ratio {zeta}: allowed a finite ratio >= 0"
        )));
    }
    let n = model.dofs();
    let mut factor = StiffnessFactor::new(&model.stiffness)?;
    let modes = lowest_modes(&mut factor, &model.mass, ModeCount::Below(f64::INFINITY))?;
    let mut d = vec![0.0; n * n];
    for (omega, phi) in modes.omegas.iter().zip(&modes.shapes) {
        let m_phi = times(&model.mass, phi);
        let c = 2.0 * zeta * omega;
        for (j, &b) in m_phi.iter().enumerate() {
            for (i, &a) in m_phi.iter().enumerate() {
                d[j * n + i] += c * a * b;
            }
        }
    }
    let triplets: Vec<_> = (0..n * n)
        .map(|k| Triplet::new(k % n, k / n, d[k]))
        .collect();
    SparseMatrix::try_new_from_triplets(n, n, &triplets)
        .map_err(|e| ReductionError::Invalid(format!("cannot store the modal damping: {e:?}")))
}
