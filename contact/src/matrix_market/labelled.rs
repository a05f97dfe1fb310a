//! Matrix files whose entries name their row and column by node and component (Abaqus'
//! `node, dof, node, dof, value` lines, Nastran's DMIG columns): the entries as read
//! ([`LabelledMatrix`]), the dof map they imply ([`labelled_dof_map`]: every (node, component)
//! named, sorted by node then component, as CalculiX numbers its rows) and the matrix on the
//! rows of a map ([`LabelledMatrix::on_rows`]).
//!
//! Symmetric storage: each off-diagonal pair is given once, in either triangle (mirrored), or
//! in both with equal values (a square listing, taken once); an entry given twice in the same
//! place is a defect (files of these codes list each entry once), named with both lines.

use std::collections::{BTreeSet, HashMap};
use std::path::Path;

use faer::sparse::Triplet;

use super::read::{push, value, Field};
use super::ImportError;
use crate::import::{DofMap, NodeComponent};
use crate::model::SparseMatrix;

/// One stored entry of a labelled matrix file.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LabelledEntry {
    /// The row's node and component.
    pub row: NodeComponent,
    /// The column's node and component.
    pub col: NodeComponent,
    /// The value.
    pub value: f64,
    /// The 1-based line of the file that gives it (for messages).
    pub line: usize,
}

/// How a file stores its matrix.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Storage {
    /// Symmetric: one triangle (the other its mirror), or both with equal values.
    Symmetric,
    /// Every entry as it is.
    General,
}

/// The entries of a labelled matrix file and how they are stored.
#[derive(Debug, Clone, PartialEq)]
pub struct LabelledMatrix {
    /// The entries in file order.
    pub entries: Vec<LabelledEntry>,
    /// Their storage.
    pub storage: Storage,
}

/// `node N component C`, for messages.
pub(super) fn label(l: NodeComponent) -> String {
    format!("node {} component {}", l.node, l.component)
}

/// A defect of a labelled file of format `format` (e.g. `"Abaqus matrix"`).
pub(super) fn defect(path: &Path, format: &'static str, message: String) -> ImportError {
    ImportError::FileFormat {
        path: path.to_path_buf(),
        format,
        message,
    }
}

/// A line reader's defect (reported as Matrix Market's) as one of the format `format`.
pub(super) fn relabelled(e: ImportError, format: &'static str) -> ImportError {
    match e {
        ImportError::MatrixMarket { path, message } => defect(&path, format, message),
        e => e,
    }
}

impl LabelledMatrix {
    /// The matrix on the rows of `map` (`N x N`, `N` the map's rows); an entry whose node and
    /// component the map lacks, or one given twice, is a defect of the file `path`.
    pub fn on_rows(
        &self,
        map: &DofMap,
        path: &Path,
        format: &'static str,
    ) -> Result<SparseMatrix, ImportError> {
        let error = |line: usize, m: String| defect(path, format, format!("line {line}: {m}"));
        let row = |l: NodeComponent, line: usize| {
            map.row(l.node, l.component).ok_or_else(|| {
                error(
                    line,
                    format!(
                        "{} is not a row of the model: allowed the nodes and components of \
                         the dof map",
                        label(l)
                    ),
                )
            })
        };
        // Per stored place: the line that gave it, its value and the row it was given on.
        let mut seen: HashMap<(usize, usize), (usize, f64, usize)> = HashMap::new();
        let mut triplets = Vec::new();
        for e in &self.entries {
            let (i, j) = (row(e.row, e.line)?, row(e.col, e.line)?);
            let place = match self.storage {
                Storage::Symmetric => (i.max(j), i.min(j)),
                Storage::General => (i, j),
            };
            if let Some(&(first, v, first_row)) = seen.get(&place) {
                let mirror = self.storage == Storage::Symmetric && i != j && first_row != i;
                if mirror && v == e.value {
                    continue;
                }
                let what = if mirror {
                    format!(
                        "its mirror on line {first} = {v:e}: allowed one triangle, or both \
                             with equal values"
                    )
                } else {
                    format!("given again (first on line {first}): allowed each entry once")
                };
                return Err(error(
                    e.line,
                    format!(
                        "entry ({}, {}) = {:e}: {what}",
                        label(e.row),
                        label(e.col),
                        e.value
                    ),
                ));
            }
            seen.insert(place, (e.line, e.value, i));
            let store = |t: Triplet<usize, usize, f64>, v: &mut Vec<_>| {
                push(v, t).map_err(|m| error(e.line, m))
            };
            store(Triplet::new(i, j, e.value), &mut triplets)?;
            if self.storage == Storage::Symmetric && i != j {
                store(Triplet::new(j, i, e.value), &mut triplets)?;
            }
        }
        let n = map.len();
        SparseMatrix::try_new_from_triplets(n, n, &triplets).map_err(|e| {
            defect(
                path,
                format,
                format!("cannot store the {n} x {n} matrix: {e:?}"),
            )
        })
    }
}

/// The dof map of `matrices`: every (node, component) any of them names, sorted by node,
/// then component (`None` when they name none).
pub fn labelled_dof_map(matrices: &[&LabelledMatrix]) -> Option<DofMap> {
    let labels: BTreeSet<NodeComponent> = matrices
        .iter()
        .flat_map(|m| m.entries.iter().flat_map(|e| [e.row, e.col]))
        .collect();
    if labels.is_empty() {
        return None;
    }
    // A set has no repeated element: `new` cannot refuse it.
    DofMap::new(labels.into_iter().collect()).ok()
}

/// A node label of a file (an integer `>= 1`).
pub(super) fn node_label(word: &str) -> Result<u64, String> {
    match word.trim().parse::<i64>() {
        Ok(n) if n >= 1 => Ok(n as u64),
        Ok(n) => Err(format!(
            "node `{n}` (an internal node of the code, such as a constraint's Lagrange \
             multiplier, when negative): allowed node labels >= 1"
        )),
        Err(_) => Err(format!("node `{}`: allowed an integer >= 1", word.trim())),
    }
}

/// A component of a file (`1..=6`: x, y, z, then the rotations).
pub(super) fn component_label(word: &str) -> Result<u8, String> {
    match word.trim().parse::<u8>() {
        Ok(c) if (1..=crate::import::MAX_COMPONENT).contains(&c) => Ok(c),
        _ => Err(format!(
            "component `{}`: allowed 1..=6 (1, 2, 3 translations, 4, 5, 6 rotations)",
            word.trim()
        )),
    }
}

/// A real number as Fortran and Nastran write it: `1.5E+3`, `1.5D+3`, or the exponent
/// without its letter (`1.5+3`, `-2.-4`); finite, of magnitude at most
/// [`super::MAX_ENTRY_MAGNITUDE`].
pub(super) fn fortran_real(word: &str) -> Result<f64, String> {
    let w = word.trim();
    let lettered = w.contains(['e', 'E', 'd', 'D']);
    let exponent_at = w
        .char_indices()
        .skip(1)
        .find(|&(_, c)| c == '+' || c == '-')
        .map(|(k, _)| k);
    let parsed = match (lettered, exponent_at) {
        (false, Some(k)) => format!("{}e{}", &w[..k], &w[k..]),
        _ => w.to_string(),
    };
    value(&parsed, Field::Real)
        .map_err(|m| m.replacen(&format!("`{parsed}`"), &format!("`{w}`"), 1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fortran_and_nastran_reals_read_as_their_decimal_value() {
        for (word, v) in [
            ("1.5E+3", 1500.0),
            ("1.5D+3", 1500.0),
            ("1.5+3", 1500.0),
            ("-2.-4", -2e-4),
            ("3.+5", 3e5),
            ("0.9871794872E+06", 987179.4872),
            (" -7 ", -7.0),
            ("0.123-100", 0.123e-100),
        ] {
            assert_eq!(fortran_real(word).unwrap(), v, "{word}");
        }
        for word in ["x", "1.5+", "inf", "1e300"] {
            assert!(fortran_real(word).is_err(), "{word}");
        }
    }
}
