//! The friction points' blocks on their contacts' forces in the condensed system.

use faer::{Mat, MatMut};
use semismooth::linalg::LinearSolveError;

use crate::hb::LinearData;

/// The blocks `X_f = dR_t / dLambda_n` of the friction points on contacts (row `t` of the
/// friction point, row `p` of its contact), as the condensed system uses them.
#[derive(Debug, Default)]
pub(crate) struct CrossBlocks {
    /// `(t, p)` of each friction point on a contact, in the order of the Jacobian's blocks
    /// (`None` under a prescribed load: no block).
    rows: Vec<Option<(usize, usize)>>,
    blocks: Vec<Mat<f64>>,
}

impl CrossBlocks {
    /// Empty blocks for the friction points of `lin`.
    pub(crate) fn new(lin: &LinearData) -> Self {
        let size = lin.size();
        let rows: Vec<Option<(usize, usize)>> = lin
            .friction
            .iter()
            .enumerate()
            .map(|(f, &(_, normal))| match normal {
                crate::model::NormalForce::Contact(p) => Some((lin.normal_rows() + f, p)),
                crate::model::NormalForce::Prescribed(_) => None,
            })
            .collect();
        let blocks = rows.iter().map(|_| Mat::zeros(size, size)).collect();
        Self { rows, blocks }
    }

    /// Copies the Jacobian's blocks (a non-finite entry is an error).
    pub(crate) fn copy_from(&mut self, source: &[Mat<f64>]) -> Result<(), LinearSolveError> {
        for (block, from) in self.blocks.iter_mut().zip(source) {
            block.copy_from(from);
            for col in 0..block.ncols() {
                let column = block.col_as_slice(col);
                if let Some((row, &value)) = column.iter().enumerate().find(|(_, v)| !v.is_finite())
                {
                    return Err(LinearSolveError::NonFiniteEntry { row, col, value });
                }
            }
        }
        Ok(())
    }

    /// The block `X` of friction point `f` (unused under a prescribed load).
    pub(crate) fn block_mut(&mut self, f: usize) -> &mut Mat<f64> {
        &mut self.blocks[f]
    }

    /// The `(t, p, X)` of each friction point on a contact.
    pub(super) fn each(&self) -> impl Iterator<Item = (usize, usize, &Mat<f64>)> + '_ {
        self.rows
            .iter()
            .zip(&self.blocks)
            .filter_map(|(rows, x)| rows.map(|(t, p)| (t, p, x)))
    }

    /// `out[j m + t] += sum_l X[j, l] p[l m + p]` for every block (harmonic-major vectors).
    pub(crate) fn apply_add(&self, m: usize, x: &[f64], out: &mut [f64]) {
        for (t, p, block) in self.each() {
            for l in 0..block.ncols() {
                let xl = x[l * m + p];
                if xl == 0.0 {
                    continue;
                }
                for (j, v) in block.col_as_slice(l).iter().enumerate() {
                    out[j * m + t] += v * xl;
                }
            }
        }
    }

    /// `S[(j m + t, l m + p)] += X[j, l]` for every block.
    pub(super) fn add_to(&self, m: usize, mut out: MatMut<'_, f64>) {
        for (t, p, block) in self.each() {
            for l in 0..block.ncols() {
                for (j, v) in block.col_as_slice(l).iter().enumerate() {
                    out[(j * m + t, l * m + p)] += v;
                }
            }
        }
    }
}
