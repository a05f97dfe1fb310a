//! The semi-discrete structural model with unilateral contact.
//!
//! `M u'' + D u' + K u = f(t) + G^T lambda(t)`, with contact rows
//! `G u - g <= 0, lambda <= 0, (G u - g) . lambda = 0` (lambda is the force the obstacle
//! applies, non-positive: it pushes the structure back).

use faer::sparse::SparseColMat;
use semismooth::{Factorize, LinearSolve};

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

    /// Stiffness scale seen by the contacts: the mean of `K[dof, dof]` over the contact
    /// dofs (1 when there is no contact). It converts a length into a force and is the
    /// default for the complementarity constant `c` and the unit of penalty stiffnesses.
    pub fn contact_stiffness_scale(&self) -> f64 {
        if self.contacts.is_empty() {
            return 1.0;
        }
        let sum: f64 = self
            .contacts
            .iter()
            .map(|c| diagonal_entry(&self.stiffness, c.dof))
            .sum();
        sum / self.contacts.len() as f64
    }
}

impl StructuralModel {
    /// Static stiffness seen by the contacts: the mean over the contacts of
    /// `1 / (G K^{-1} G^T)_ii`, the force that moves contact `i` by a unit length with the
    /// rest of the structure free. Independent of the mesh (for the rod: `EA / x_node`);
    /// `None` without contacts or when `K` cannot be factored.
    pub fn static_contact_stiffness(&self) -> Option<f64> {
        if self.contacts.is_empty() {
            return None;
        }
        let mut lu = semismooth::linalg::FaerSparseLu::new();
        lu.factor(&self.stiffness).ok()?;
        let mut sum = 0.0;
        let mut rhs = vec![0.0; self.dofs()];
        for c in &self.contacts {
            rhs.iter_mut().for_each(|v| *v = 0.0);
            rhs[c.dof] = 1.0;
            lu.solve_in_place(&mut rhs).ok()?;
            let compliance = rhs[c.dof];
            if !(compliance.is_finite() && compliance > 0.0) {
                return None;
            }
            sum += 1.0 / compliance;
        }
        Some(sum / self.contacts.len() as f64)
    }

    /// Default complementarity constant `c` of SSN-HB: ten times the static contact
    /// stiffness (the contact stiffness scale when `K` cannot be factored).
    ///
    /// `c` converts a length into a force. Measured on the canonical rod (H = 20): with
    /// `c` between 1 and 30 times the static stiffness Newton converges from zero in 7-14
    /// iterations for 20 to 100,000 elements, and 10 gives the smallest truncation error;
    /// the local stiffness `K[tip, tip] = EA/h` grows with the mesh and from 200 elements on
    /// Newton no longer converges with it.
    pub fn default_complementarity_constant(&self) -> f64 {
        self.static_contact_stiffness()
            .map(|k| DEFAULT_C_FACTOR * k)
            .unwrap_or_else(|| self.contact_stiffness_scale())
    }
}

/// Ratio of the default complementarity constant `c` to the static contact stiffness.
pub const DEFAULT_C_FACTOR: f64 = 10.0;

/// Entry `(i, i)` of a column-compressed matrix (0 when not stored).
pub fn diagonal_entry(matrix: &SparseMatrix, i: usize) -> f64 {
    let m = matrix.as_ref();
    let rows = m.row_idx_of_col(i);
    let vals = m.val_of_col(i);
    rows.zip(vals.iter())
        .filter(|(r, _)| *r == i)
        .map(|(_, v)| *v)
        .sum()
}
