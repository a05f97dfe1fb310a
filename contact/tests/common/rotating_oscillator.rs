//! What the friction-disk tests share: the isotropic oscillator under the rotating load
//! `F (cos w t, sin w t)`, the radius of the circle it slides on under a slip limit `b`
//! (closed form), diagonal matrices and SSN-HB solved from zero.
//!
//! A point sliding on a circle feels a force of constant magnitude `b` opposite to its
//! velocity; with `z = x + i y = Z e^{i w t}` the friction force is `-b i Z / |Z| e^{i w t}`,
//! so `(k - m w^2 + i (c w + b / r)) r = F` in modulus with `r = |Z|`:
//! `((k - m w^2)^2 + c^2 w^2) r^2 + 2 c w b r + b^2 - F^2 = 0`.

#![allow(dead_code)]

use semismooth::newton::Tolerances;
use semismooth::polyalgorithm::{solve_smoothing, PolyalgorithmOptions};
use semismooth::{Factorize, GeneralizedJacobian, Smoothing};
use semismooth_contact::model::SparseMatrix;

// The oscillator and its load.
pub const MASS: f64 = 1.0;
pub const DAMPING: f64 = 0.05;
pub const STIFFNESS: f64 = 1.0;
pub const FORCE: f64 = 1.0;
pub const OMEGA: f64 = 1.3;

/// A diagonal `n x n` matrix.
pub fn diagonal(values: &[f64]) -> SparseMatrix {
    let entries: Vec<_> = (values.iter().enumerate())
        .map(|(i, v)| faer::sparse::Triplet::new(i, i, *v))
        .collect();
    SparseMatrix::try_new_from_triplets(values.len(), values.len(), &entries).unwrap()
}

/// The radius of the circle the oscillator slides on under the slip limit `b < F`
/// (module documentation).
pub fn circle_radius(b: f64) -> f64 {
    let w = OMEGA;
    let a = (STIFFNESS - MASS * w * w).powi(2) + (DAMPING * w).powi(2);
    let half_linear = DAMPING * w * b;
    (-half_linear + (half_linear * half_linear - a * (b * b - FORCE * FORCE)).sqrt()) / a
}

/// `problem` solved from zero along its smoothing path with `solver` to
/// `|F| <= tolerance` (asserted converged).
pub fn solved_from_zero<P, S>(problem: &mut P, solver: &mut S, tolerance: f64) -> Vec<f64>
where
    P: GeneralizedJacobian + Smoothing,
    S: Factorize<P::Jacobian> + ?Sized,
{
    let mut x = vec![0.0; problem.dim()];
    let newton = PolyalgorithmOptions {
        tolerances: Tolerances::absolute(tolerance),
        ..PolyalgorithmOptions::default()
    };
    let report = solve_smoothing(problem, solver, &mut x, &newton).unwrap();
    assert!(report.converged(), "{:?}", report.termination);
    x
}

/// The largest entry-wise difference of two vectors.
pub fn max_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()))
}
