//! Rows of `G` between cyclic sectors: a row `g . u + n . u_next` whose neighbour part
//! reads the next sector, `u_next(t) = u(t - EO T / N)`. On the harmonic-major
//! coefficients, harmonic `k` of the neighbour part is this sector's `(a_k, b_k)` rotated by
//! `theta = k phi`: `(a cos theta - b sin theta, a sin theta + b cos theta)`, so the row's
//! coefficient `j` reads the coefficients `j` and its partner of the same harmonic. `G^T`
//! takes the transposed rotation (the previous sector's force, rotated back). In complex
//! form `a - i b` the row of harmonic `k` is `g + e^{-i k phi} n` and its column of `G^T`
//! is `g + e^{+i k phi} n`. Every `G` and `G^T` map of harmonic balance goes through these
//! methods, so the dense, structured, condensed and penalty solves take such rows.

use faer::{c64, MatMut, MatRef};

use super::LinearData;
use crate::model::{ContactRow, StructuralModel};

/// The neighbour parts of the rows of `G` (none for a model without rows between sectors)
/// and the inter-sector phase `phi` of harmonic 1.
#[derive(Debug, Clone, Default)]
pub(crate) struct NeighbourParts {
    phase_step: f64,
    parts: Vec<Option<ContactRow>>,
}

impl NeighbourParts {
    /// The parts of the model's rows (`rows` rows of `G` in all).
    pub(crate) fn of(model: &StructuralModel, rows: usize) -> Self {
        let Some(coupling) = model
            .cyclic
            .as_ref()
            .filter(|c| !c.neighbour_rows.is_empty())
        else {
            return Self::default();
        };
        let mut parts = vec![None; rows];
        for n in &coupling.neighbour_rows {
            parts[n.row] = Some(n.part.clone());
        }
        Self {
            phase_step: coupling.phase_step,
            parts,
        }
    }

    fn part(&self, i: usize) -> Option<&ContactRow> {
        self.parts.get(i).and_then(Option::as_ref)
    }

    /// The coefficients `(l, weight)` of this sector that coefficient `j` of the neighbour
    /// reads (the rotation of its harmonic; `weight` 0 pads the constant).
    fn weights(&self, j: usize) -> [(usize, f64); 2] {
        let theta = j.div_ceil(2) as f64 * self.phase_step;
        let (cos, sin) = (theta.cos(), theta.sin());
        match j {
            0 => [(0, 1.0), (0, 0.0)],
            j if j % 2 == 1 => [(j, cos), (j + 1, -sin)],
            j => [(j - 1, sin), (j, cos)],
        }
    }

    /// `e^{-i k phi}`: the neighbour's harmonic `k` in complex form from this sector's.
    fn phase(&self, k: usize) -> c64 {
        let theta = k as f64 * self.phase_step;
        c64::new(theta.cos(), -theta.sin())
    }
}

impl LinearData {
    /// Coefficient `j` of row `i` of `G` applied to the harmonic-major coefficients `u`.
    pub(crate) fn row_dot(&self, i: usize, u: &[f64], j: usize) -> f64 {
        let n = self.dofs;
        let own = self.rows[i].dot_at(u, j * n);
        match self.neighbours.part(i) {
            None => own,
            Some(part) => (self.neighbours.weights(j).iter())
                .filter(|(_, w)| *w != 0.0)
                .fold(own, |s, &(l, w)| s + w * part.dot_at(u, l * n)),
        }
    }

    /// `out += alpha G_i^T e_j`: a force `alpha` on coefficient `j` of row `i` on the dofs.
    pub(crate) fn add_row_transpose(&self, i: usize, alpha: f64, out: &mut [f64], j: usize) {
        let n = self.dofs;
        self.rows[i].add_transpose_at(alpha, out, j * n);
        if let Some(part) = self.neighbours.part(i) {
            for (l, w) in self.neighbours.weights(j) {
                if w != 0.0 {
                    part.add_transpose_at(alpha * w, out, l * n);
                }
            }
        }
    }

    /// Calls `visit(l, dof, g)` for each entry of coefficient `j` of row `i`: it reads
    /// `u[l N + dof]` with the weight `g`.
    pub(crate) fn row_terms(&self, i: usize, j: usize, mut visit: impl FnMut(usize, usize, f64)) {
        self.rows[i].entries().for_each(|(d, a)| visit(j, d, a));
        if let Some(part) = self.neighbours.part(i) {
            for (l, w) in self.neighbours.weights(j) {
                if w != 0.0 {
                    part.entries().for_each(|(d, b)| visit(l, d, w * b));
                }
            }
        }
    }

    /// Row `i` of harmonic `k` in complex form applied to column `col` of `z`.
    pub(crate) fn row_complex(&self, i: usize, k: usize, z: MatRef<'_, c64>, col: usize) -> c64 {
        let dot = |row: &ContactRow| {
            (row.entries()).fold(c64::new(0.0, 0.0), |s, (d, a)| s + z[(d, col)] * a)
        };
        let own = dot(&self.rows[i]);
        match self.neighbours.part(i) {
            None => own,
            Some(part) => own + self.neighbours.phase(k) * dot(part),
        }
    }

    /// `z[:, col] += scale G_i^T` of harmonic `k` in complex form (`g + e^{+i k phi} n`).
    pub(crate) fn add_row_column(
        &self,
        i: usize,
        k: usize,
        scale: c64,
        mut z: MatMut<'_, c64>,
        col: usize,
    ) {
        for (d, a) in self.rows[i].entries() {
            z[(d, col)] += scale * a;
        }
        if let Some(part) = self.neighbours.part(i) {
            let phase = scale * self.neighbours.phase(k).conj();
            for (d, b) in part.entries() {
                z[(d, col)] += phase * b;
            }
        }
    }
}
