//! The bordered EPMC Jacobian solved through the structured harmonic-balance solver: one
//! factorization of the inner (deflated) HB Jacobian per iteration, no dense matrix.
//!
//! The EPMC Jacobian of an [`Epmc::deflated`](super::Epmc::deflated) problem is
//! `[[J~ - s E, F_w, F_xi], [r_phase^T, 0, 0], [r_amp^T, 0, 0]]`, with `E = sum_j e_j e_j^T`
//! over the grounded dof's entry `e_j` of every harmonic block `j = 0..2H`. With the
//! entries `q_j = e_j . x` as `2H + 1` more unknowns it is the bordered system
//!
//! ```text
//! [[J~,        F_w, F_xi, -s e_0 .. -s e_2H],   [x ]   [f]
//!  [r_phase^T, 0,   0,     0              ],    [w ]   [g_phase]
//!  [r_amp^T,   0,   0,     0              ],  . [xi] = [g_amp]
//!  [-s e_j^T,  0,   0,     s I            ]]    [q ]   [0]
//! ```
//!
//! whose inner block `J~` (the HB Jacobian of the grounded model) is factored once by
//! [`StructuredHbSolver`] (per-harmonic sparse LU, condensation onto the contact unknowns)
//! and whose border, `2H + 3` wide, costs `2H + 3` more structured solves
//! ([`BorderedSolver`]). Eliminating `q` gives back the EPMC Jacobian, so the solution is
//! the dense LU's to round-off.

use semismooth::linalg::{BorderedError, BorderedSolver, LinearSolveError};
use semismooth::{Factorize, LinearSolve};

use super::EpmcJacobian;
use crate::hb::StructuredHbSolver;

/// [`Factorize`] and [`LinearSolve`] for the [`EpmcJacobian`] of a deflated
/// [`Epmc`](super::Epmc) (module documentation): per factorization one structured
/// factorization of the inner HB Jacobian and `2H + 3` structured solves; per solve one.
/// A Jacobian without deflation is refused ([`LinearSolveError::NotFactored`]: it has no
/// regular inner block to factor).
#[derive(Debug, Default)]
pub struct EpmcStructuredSolver {
    inner: StructuredHbSolver,
    border: Option<BorderedSolver>,
    /// `B`, `C` (column-major, `len x k`) and `D` (`k x k`).
    columns: Vec<f64>,
    rows: Vec<f64>,
    corner: Vec<f64>,
    /// The border's right-hand side and solution (`k`).
    extra: Vec<f64>,
}

impl EpmcStructuredSolver {
    /// A solver with the structured HB solver's defaults.
    pub fn new() -> Self {
        Self::default()
    }

    /// The structured solver of the inner block (its counters).
    pub fn inner(&self) -> &StructuredHbSolver {
        &self.inner
    }

    /// Factorizations of the inner block and structured solves so far.
    pub fn counters(&self) -> semismooth::linalg::BorderedCounters {
        self.border
            .as_ref()
            .map(BorderedSolver::counters)
            .unwrap_or_default()
    }
}

/// The linear-solve error of a bordered one (a singular border is a singular matrix whose
/// pivot sits after the `len` inner unknowns).
fn linear_error(error: BorderedError, len: usize) -> LinearSolveError {
    match error {
        BorderedError::Factorization(e) | BorderedError::Solve(e) => e,
        BorderedError::SingularBorder {
            index,
            pivot,
            scale,
        } => LinearSolveError::Singular {
            index: len + index,
            pivot: pivot.abs(),
            max_pivot: scale,
        },
        BorderedError::NonFinite => LinearSolveError::NonFiniteEntry {
            row: 0,
            col: 0,
            value: f64::NAN,
        },
        BorderedError::DimensionMismatch {
            expected, found, ..
        } => LinearSolveError::DimensionMismatch { expected, found },
        _ => LinearSolveError::NotFactored,
    }
}

impl Factorize<EpmcJacobian> for EpmcStructuredSolver {
    fn factor(&mut self, jac: &EpmcJacobian) -> Result<(), LinearSolveError> {
        let Some(spring) = jac.deflation else {
            return Err(LinearSolveError::NotFactored);
        };
        let len = jac.columns.len() / 2;
        let n = jac.row.len();
        let blocks = 2 * jac.inner.harmonics() + 1;
        let k = blocks + 2;
        if self.border.as_ref().map(BorderedSolver::dims) != Some((len, k)) {
            self.border = Some(BorderedSolver::new(len, k));
            self.columns = vec![0.0; len * k];
            self.rows = vec![0.0; len * k];
            self.corner = vec![0.0; k * k];
            self.extra = vec![0.0; k];
        }
        self.columns.fill(0.0);
        self.rows.fill(0.0);
        self.corner.fill(0.0);
        self.columns[..2 * len].copy_from_slice(&jac.columns);
        // Phase on U_s1 (block 2), amplitude on U_c1 (block 1).
        self.rows[2 * n..3 * n].copy_from_slice(&jac.row);
        self.rows[len + n..len + 2 * n].copy_from_slice(&jac.row);
        let s = spring.stiffness;
        for j in 0..blocks {
            let column = (2 + j) * len;
            self.columns[column + j * n + spring.dof] = -s;
            self.rows[column + j * n + spring.dof] = -s;
            self.corner[(2 + j) * (k + 1)] = s;
        }
        let border = self.border.as_mut().ok_or(LinearSolveError::NotFactored)?;
        border
            .factor(
                &mut self.inner,
                &jac.inner,
                &self.columns,
                &self.rows,
                &self.corner,
            )
            .map_err(|e| linear_error(e, len))
    }
}

impl LinearSolve for EpmcStructuredSolver {
    fn solve_in_place(&mut self, rhs: &mut [f64]) -> Result<(), LinearSolveError> {
        let Some(border) = self.border.as_mut() else {
            return Err(LinearSolveError::NotFactored);
        };
        let (len, _) = border.dims();
        if rhs.len() != len + 2 {
            return Err(LinearSolveError::DimensionMismatch {
                expected: len + 2,
                found: rhs.len(),
            });
        }
        let (f, g) = rhs.split_at_mut(len);
        self.extra.fill(0.0);
        self.extra[..2].copy_from_slice(g);
        border
            .solve(&mut self.inner, f, &mut self.extra)
            .map_err(|e| linear_error(e, len))?;
        g.copy_from_slice(&self.extra[..2]);
        Ok(())
    }
}
