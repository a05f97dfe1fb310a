//! The semi-discrete structural model with unilateral contact.
//!
//! `M u'' + D u' + K u = f(t) + G^T lambda(t)`, with contact rows
//! `G u - g <= 0, lambda <= 0, (G u - g) . lambda = 0` (lambda is the force the obstacle
//! applies, non-positive: it pushes the structure back).

use faer::sparse::SparseColMat;

/// Sparse symmetric matrix storage used for `M`, `D` and `K` (column-compressed, faer).
pub type SparseMatrix = SparseColMat<usize, f64>;

/// One unilateral contact: the obstacle limits degree of freedom `dof` to
/// `u[dof] - gap <= 0`. Row of `G` is the unit vector on `dof`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// Index of the constrained degree of freedom (0-based among the free unknowns).
    pub dof: usize,
    /// Initial gap `g` (negative: preloaded against the obstacle at rest).
    pub gap: f64,
}

/// Periodic external force `f(t) = amplitude * cos(omega t)` (a fixed spatial shape).
#[derive(Debug, Clone, PartialEq)]
pub struct HarmonicForcing {
    /// Nodal amplitude vector (length `N`).
    pub amplitude: Vec<f64>,
    /// Angular frequency `omega` (rad per unit time); the period is `2 pi / omega`.
    pub omega: f64,
}

/// The whole semi-discrete model: only the effects it declares are present
/// (`damping = None` means no damping matrix; empty `contacts` means a linear problem).
#[derive(Debug, Clone)]
pub struct StructuralModel {
    /// Mass matrix `M` (N x N, symmetric positive semi-definite).
    pub mass: SparseMatrix,
    /// Damping matrix `D`, absent when undamped.
    pub damping: Option<SparseMatrix>,
    /// Stiffness matrix `K` (N x N, symmetric positive definite).
    pub stiffness: SparseMatrix,
    /// External periodic force.
    pub forcing: HarmonicForcing,
    /// Unilateral contacts (rows of `G` and gaps `g`).
    pub contacts: Vec<ContactPoint>,
}

impl StructuralModel {
    /// Number of degrees of freedom `N`.
    pub fn dofs(&self) -> usize {
        self.stiffness.nrows()
    }

    /// Number of contact constraints `m`.
    pub fn contact_count(&self) -> usize {
        self.contacts.len()
    }
}
