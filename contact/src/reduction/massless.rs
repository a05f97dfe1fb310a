//! MacNeal's massless-boundary reduction: free-interface modes plus the residual
//! flexibility of the boundary dofs, with the boundary displacements as coordinates.
//!
//! With the lowest free-interface modes `Phi` of `(K, M)` (`M`-normalised, frequencies
//! `Lambda = diag(omega_k^2)`) and the residual flexibility of the boundary columns
//! `R = (K^{-1} - Phi Lambda^{-1} Phi^T) E_b`, the displacement is `u = Phi q + R f_b`;
//! eliminating the boundary forces through `u_b = Phi_b q + R_bb f_b` gives the coordinates
//! `[u_b; q]` and `T = [R S, Phi - R S Phi_b]`, `S = R_bb^{-1}`. The stiffness is
//! `T^T K T`; the mass keeps only the modes' inertia, `blockdiag(0, I)` (MacNeal, 1971):
//! the residual flexibility carries no mass, so the boundary coordinates (the contact dofs)
//! are massless by construction. Rubin's variant adds the residual mass `T^T M T`; it is
//! not used here because it gives the boundary mass back, which is what a massless
//! boundary avoids (no contact impacts on a massive node, no high boundary frequencies).
//! The loads, damping and contacts are projected as for Craig–Bampton.
//!
//! References: MacNeal (1971), a hybrid method of component mode synthesis; Rubin (1975),
//! improved component-mode representation for structural dynamic analysis.

use faer::sparse::Triplet;
use semismooth::LinearSolve;

use crate::model::{SparseMatrix, Structure};

use super::{
    check_boundary, lowest_frequencies, lowest_modes, reduced_structure, CraigBampton, ModeCount,
    ReductionError, StiffnessFactor,
};

/// Reduces `full` onto `boundary` (ascending, distinct) and its lowest free-interface
/// modes `modes` (module documentation); the result's `interface_frequencies` are the
/// free-interface frequencies kept.
pub fn massless_boundary(
    full: &Structure,
    boundary: &[usize],
    modes: ModeCount,
) -> Result<CraigBampton, ReductionError> {
    let model = &full.model;
    let n = model.dofs();
    check_boundary(boundary, n)?;
    let failed = |e: semismooth::linalg::LinearSolveError| ReductionError::Factorization {
        reason: e.to_string(),
    };
    let mut factor = StiffnessFactor::new(&model.stiffness)?;
    let free = lowest_modes(&mut factor, &model.mass, modes)?;
    let nb = boundary.len();
    // R: K^{-1} e_b minus the kept modes' static part.
    let mut r = Vec::with_capacity(nb);
    for &b in boundary {
        let mut g = vec![0.0; n];
        g[b] = 1.0;
        factor.solve_in_place(&mut g).map_err(failed)?;
        for (omega, phi) in free.omegas.iter().zip(&free.shapes) {
            let c = phi[b] / (omega * omega);
            g.iter_mut().zip(phi).for_each(|(g, p)| *g -= c * p);
        }
        r.push(g);
    }
    let r_bb =
        nalgebra::DMatrix::from_fn(nb, nb, |i, j| 0.5 * (r[j][boundary[i]] + r[i][boundary[j]]));
    let s = r_bb
        .cholesky()
        .ok_or_else(|| {
            ReductionError::Invalid(
                "the boundary's residual flexibility is not positive definite: allowed \
                 boundary dofs that the kept modes do not already span"
                    .into(),
            )
        })?
        .inverse();
    let combine = |weights: &[f64]| -> Vec<f64> {
        let mut t = vec![0.0; n];
        for (rj, &w) in r.iter().zip(weights) {
            t.iter_mut().zip(rj).for_each(|(t, x)| *t += w * x);
        }
        t
    };
    let mut transform: Vec<Vec<f64>> = (0..nb)
        .map(|i| combine(&s.column(i).iter().copied().collect::<Vec<_>>()))
        .collect();
    for phi in &free.shapes {
        let phi_b: Vec<f64> = boundary.iter().map(|&b| phi[b]).collect();
        let weights: Vec<f64> = (0..nb)
            .map(|j| (0..nb).map(|i| s[(j, i)] * phi_b[i]).sum())
            .collect();
        let correction = combine(&weights);
        transform.push(phi.iter().zip(&correction).map(|(p, c)| p - c).collect());
    }
    let mut structure = reduced_structure(full, boundary, &transform)?;
    let size = transform.len();
    let modal: Vec<_> = (nb..size).map(|k| Triplet::new(k, k, 1.0)).collect();
    structure.model.mass = SparseMatrix::try_new_from_triplets(size, size, &modal)
        .map_err(|e| ReductionError::Invalid(format!("cannot store the modal mass: {e:?}")))?;
    structure
        .model
        .validate()
        .map_err(|e| ReductionError::Invalid(e.to_string()))?;
    structure.omega_1 = lowest_frequencies(&structure.model, 1)?[0];
    Ok(CraigBampton {
        structure,
        boundary: boundary.to_vec(),
        interface_frequencies: free.omegas,
        transform,
    })
}
