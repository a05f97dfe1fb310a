//! The linear mode a nonlinear mode starts from: the structure at small amplitude, its
//! contacts open and its friction points stuck.

use nalgebra::{DMatrix, SymmetricEigen};

use super::ModesError;
use crate::model::{sparse_mul_add, StructuralModel};
use crate::rod::rayleigh_ritz;

/// Relative size below which an eigenvalue of `C^T C` (or `nu = 1 / omega^2`) is zero: a
/// direction of the stuck rows' null space (or a massless direction).
const NULL_SPACE_THRESHOLD: f64 = 1e-12;

/// One mode of the linearised structure (module documentation of [`crate::modes`]).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct LinearMode {
    /// Which mode (1: the lowest finite natural frequency).
    pub index: usize,
    /// Natural frequency `omega_n` of `K phi = omega_n^2 M phi` on the stuck rows' null space.
    pub omega: f64,
    /// Modal damping ratio `zeta = phi^T D phi / (2 omega_n)` (exact for damping that the
    /// modes diagonalise, e.g. proportional `D = alpha M + beta K`).
    pub damping_ratio: f64,
    /// The shape `phi`, mass-normalised (`phi^T M phi = 1`), its largest entry positive.
    pub shape: Vec<f64>,
}

/// Mode `index` (1-based) of the model with its contacts open and the tangential rows of
/// its friction points held (stuck, `G_t u = 0`): the generalized eigenproblem
/// `K phi = omega^2 M phi` on the null space of those rows, solved densely (Rayleigh-Ritz
/// on an orthonormal basis of the null space; massless directions have no finite
/// frequency and are not counted). A reduced cyclic sector's mode is its harmonic 1's, on
/// the real model of the couplings at their phase (module `sector`: engine order 0 or
/// `N / 2` only, [`ModesError::TravellingWaveSector`] otherwise).
pub fn linear_mode(model: &StructuralModel, index: usize) -> Result<LinearMode, ModesError> {
    model.validate().map_err(crate::hb::HbError::from)?;
    if model.cyclic.is_some() {
        return linear_mode(&super::sector::harmonic_model(model, 1)?, index);
    }
    let n = model.dofs();
    let basis = stuck_null_space(model);
    let product = |m: &crate::model::SparseMatrix| {
        let mut out = DMatrix::zeros(n, basis.ncols());
        for j in 0..basis.ncols() {
            let column: Vec<f64> = basis.column(j).iter().copied().collect();
            let mut y = vec![0.0; n];
            sparse_mul_add(m.as_ref(), 1.0, &column, &mut y);
            out.column_mut(j).copy_from_slice(&y);
        }
        out
    };
    let (nu, vectors) = rayleigh_ritz(&product(&model.stiffness), &product(&model.mass), &basis)
        .map_err(|e| ModesError::LinearMode(e.to_string()))?;
    let nu_max = nu.iter().copied().fold(0.0, f64::max);
    let finite: Vec<usize> = (0..nu.len())
        .filter(|&i| nu[i] > NULL_SPACE_THRESHOLD * nu_max)
        .collect();
    let Some(&column) = index.checked_sub(1).and_then(|i| finite.get(i)) else {
        return Err(ModesError::NoSuchMode {
            mode: index,
            available: finite.len(),
        });
    };
    // Ritz vectors are K-normalised: v^T M v = nu.
    let scale = 1.0 / nu[column].sqrt();
    let mut shape: Vec<f64> = vectors.column(column).iter().map(|v| v * scale).collect();
    let largest = shape
        .iter()
        .copied()
        .fold(0.0f64, |a, v| if v.abs() > a.abs() { v } else { a });
    if largest < 0.0 {
        shape.iter_mut().for_each(|v| *v = -*v);
    }
    let omega = scale;
    let damping = model.damping.as_ref().map_or(0.0, |d| {
        let mut dphi = vec![0.0; n];
        sparse_mul_add(d.as_ref(), 1.0, &shape, &mut dphi);
        dphi.iter().zip(&shape).map(|(a, b)| a * b).sum::<f64>()
    });
    Ok(LinearMode {
        index,
        omega,
        damping_ratio: damping / (2.0 * omega),
        shape,
    })
}

/// An orthonormal basis (columns) of the null space of the friction points' tangential
/// rows `C` (the identity without friction): the eigenvectors of `C^T C` with a zero
/// eigenvalue.
fn stuck_null_space(model: &StructuralModel) -> DMatrix<f64> {
    let n = model.dofs();
    if model.friction.is_empty() {
        return DMatrix::identity(n, n);
    }
    let mut ctc = DMatrix::zeros(n, n);
    for point in &model.friction {
        for (i, a) in point.tangent.entries() {
            for (j, b) in point.tangent.entries() {
                ctc[(i, j)] += a * b;
            }
        }
    }
    let scale = ctc.iter().fold(0.0f64, |m: f64, v: &f64| m.max(v.abs()));
    let eigen = SymmetricEigen::new(ctc);
    let kept: Vec<usize> = (0..n)
        .filter(|&i| eigen.eigenvalues[i].abs() <= NULL_SPACE_THRESHOLD * scale)
        .collect();
    DMatrix::from_fn(n, kept.len(), |r, c| eigen.eigenvectors[(r, kept[c])])
}
