//! CalculiX matrix files: the `.sti` (stiffness) and `.mas` (mass) files that
//! `*FREQUENCY, SOLVER=MATRIXSTORAGE` writes, one line `i j value` per stored entry with
//! 1-based row and column on the free dofs, one triangle stored (CalculiX writes `i <= j`),
//! the other mirrored. The files have no header: the size `N` is the number of rows of the
//! `.dof` file written beside them ([`crate::import::DofMap`], one `node.component` per
//! row). The reader takes either triangle but not both (an entry of the other triangle is a
//! defect, not a second value); repeated entries are summed (assembly). Every defect names
//! the file, the line, what was found and what is allowed, as for Matrix Market files.

use std::io::BufRead;
use std::path::Path;

use faer::sparse::Triplet;

use super::read::{open_lines, push, quoted, text_lines, value, Field, Lines};
use super::ImportError;
use crate::model::SparseMatrix;

/// What an entry line of a CalculiX matrix file may be.
const ALLOWED_ENTRY: &str = "`row column value` (1-based, one triangle, as CalculiX's \
                             SOLVER=MATRIXSTORAGE writes)";

/// Reads the CalculiX matrix file `path` (module documentation) of a model of `dofs` rows.
pub fn read_calculix_matrix(path: &Path, dofs: usize) -> Result<SparseMatrix, ImportError> {
    parse(&mut open_lines(path).map_err(calculix)?, path, dofs)
}

/// Parses CalculiX matrix text of a model of `dofs` rows (`path` for messages only).
pub fn parse_calculix_matrix(
    text: &str,
    path: &Path,
    dofs: usize,
) -> Result<SparseMatrix, ImportError> {
    parse(&mut text_lines(text), path, dofs)
}

/// A symmetric matrix as CalculiX writes it: its upper triangle `i <= j`, column by column,
/// values in Rust's shortest round-trip notation (reading it back is exact).
pub fn calculix_matrix_text(a: &SparseMatrix) -> String {
    use std::fmt::Write;
    let r = a.as_ref();
    let mut t = String::new();
    for j in 0..a.ncols() {
        for (i, &v) in r.row_idx_of_col(j).zip(r.val_of_col(j)) {
            if i <= j {
                let _ = writeln!(t, "{} {} {v:e}", i + 1, j + 1);
            }
        }
    }
    t
}

/// A Matrix Market line reader's defect as a CalculiX file's.
fn calculix(e: ImportError) -> ImportError {
    match e {
        ImportError::MatrixMarket { path, message } => ImportError::CalculiX { path, message },
        e => e,
    }
}

/// Which triangle a file stores, fixed by its first entry off the diagonal.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Triangle {
    Upper,
    Lower,
}

fn parse<R: BufRead>(
    lines: &mut Lines<R>,
    path: &Path,
    dofs: usize,
) -> Result<SparseMatrix, ImportError> {
    let mut triplets = Vec::new();
    let mut triangle: Option<(Triangle, usize)> = None;
    while let Some(line) = lines.next(path).map_err(calculix)? {
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        let error = |m: String| calculix(lines.error(path, m));
        let (i, j, v) = entry(t, dofs).map_err(error)?;
        if i != j {
            let this = if i < j {
                Triangle::Upper
            } else {
                Triangle::Lower
            };
            match triangle {
                None => triangle = Some((this, lines.line())),
                Some((first, at)) if first != this => {
                    return Err(error(format!(
                        "entry ({}, {}) is in the other triangle than line {at}'s: allowed one \
                         triangle (the other is its mirror)",
                        i + 1,
                        j + 1
                    )))
                }
                Some(_) => {}
            }
        }
        push(&mut triplets, Triplet::new(i, j, v)).map_err(error)?;
        if i != j {
            push(&mut triplets, Triplet::new(j, i, v)).map_err(error)?;
        }
    }
    SparseMatrix::try_new_from_triplets(dofs, dofs, &triplets).map_err(|e| ImportError::CalculiX {
        path: path.to_path_buf(),
        message: format!("cannot store the {dofs} x {dofs} matrix: {e:?}"),
    })
}

/// The 0-based row, column and value of an entry line of a model of `dofs` rows.
fn entry(line: &str, dofs: usize) -> Result<(usize, usize, f64), String> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let [row, col, v] = words.as_slice() else {
        return Err(format!(
            "{} has {} words: allowed {ALLOWED_ENTRY}",
            quoted(line),
            words.len()
        ));
    };
    let index = |word: &str, what: &str| -> Result<usize, String> {
        match word.parse::<usize>() {
            Ok(k) if (1..=dofs).contains(&k) => Ok(k - 1),
            _ => Err(format!(
                "{}: {what} `{word}`: allowed 1..={dofs} (the dof file's rows)",
                quoted(line)
            )),
        }
    };
    let (i, j) = (index(row, "row")?, index(col, "column")?);
    let v = value(v, Field::Real).map_err(|m| format!("entry ({}, {}): {m}", i + 1, j + 1))?;
    Ok((i, j, v))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(text: &str) -> String {
        parse_calculix_matrix(text, Path::new("x.sti"), 3)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn either_triangle_is_mirrored_and_both_give_the_same_matrix() {
        let upper = "1 1 2.0\n1 2 -1.0\n2 2 2.0\n2 3 -1.0\n3 3 1.0\n";
        let lower = "1 1 2.0\n2 1 -1.0\n2 2 2.0\n3 2 -1.0\n3 3 1.0\n";
        let a = parse_calculix_matrix(upper, Path::new("a.sti"), 3).unwrap();
        let b = parse_calculix_matrix(lower, Path::new("b.sti"), 3).unwrap();
        assert_eq!(a.val(), b.val());
        assert_eq!(a.val().len(), 7);
        assert_eq!(calculix_matrix_text(&a), upper.replace(".0", "e0"));
    }

    #[test]
    fn written_text_reads_back_bit_for_bit() {
        let t = [
            (0, 0, 0.1),
            (0, 2, -1.0 / 3.0),
            (2, 0, -1.0 / 3.0),
            (1, 1, 1e-300),
        ];
        let t: Vec<_> = t.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
        let a = SparseMatrix::try_new_from_triplets(3, 3, &t).unwrap();
        let text = calculix_matrix_text(&a);
        let b = parse_calculix_matrix(&text, Path::new("a.sti"), 3).unwrap();
        assert_eq!(a.val(), b.val());
    }

    #[test]
    fn every_defect_names_the_file_the_line_the_text_and_what_is_allowed() {
        for (text, words) in [
            (
                "1 1 1\n1 2\n",
                &["x.sti", "line 2", "`1 2`", "2 words", "row column value"][..],
            ),
            (
                "1 1 1\n\n4 1 1\n",
                &["line 3", "row `4`", "1..=3", "dof file"],
            ),
            ("0 1 1\n", &["line 1", "row `0`"]),
            ("1 x 1\n", &["line 1", "column `x`"]),
            ("1 1 abc\n", &["line 1", "value `abc`", "real number"]),
            ("1 1 nan\n", &["line 1", "finite"]),
            (
                "1 2 1\n2 2 1\n3 1 1\n",
                &["line 3", "(3, 1)", "other triangle", "line 1"],
            ),
        ] {
            let e = error(text);
            for w in words {
                assert!(e.contains(w), "`{w}` not in: {e}");
            }
            assert!(e.starts_with("x.sti: "), "{e}");
        }
    }
}
