//! Abaqus matrix files: what `*MATRIX GENERATE` writes with `*MATRIX OUTPUT,
//! FORMAT=MATRIX INPUT` (`jobname_STIF1.mtx`, `jobname_MASS1.mtx`), the format `*MATRIX
//! INPUT` reads back: one entry per line, `row node, row dof, column node, column dof,
//! value` (commas or blanks between the fields), a symmetric matrix by one triangle, or by
//! both with equal values. Lines starting with `*` (keywords, `**` comments) and blank lines
//! are skipped. The node labels are the mesh's; the rows of the model are the (node, dof)
//! pairs the files name ([`super::labelled_dof_map`]). Every defect names the file, the
//! line, what was found and what is allowed.

use std::io::BufRead;
use std::path::Path;

use super::labelled::{
    component_label, defect, fortran_real, node_label, relabelled, LabelledEntry, LabelledMatrix,
    Storage,
};
use super::read::{open_lines, quoted, text_lines, Lines};
use super::ImportError;
use crate::import::NodeComponent;

/// The format's name in messages.
const FORMAT: &str = super::MatrixFormat::Abaqus.file_kind();

/// What an entry line may be.
const ALLOWED_ENTRY: &str = "`node, dof, node, dof, value` (as *MATRIX OUTPUT, FORMAT=MATRIX \
                             INPUT writes)";

/// Reads the Abaqus matrix file `path` (module documentation).
pub fn read_abaqus_matrix(path: &Path) -> Result<LabelledMatrix, ImportError> {
    parse(&mut open_lines(path).map_err(abaqus)?, path)
}

/// Parses Abaqus matrix text (`path` for messages only).
pub fn parse_abaqus_matrix(text: &str, path: &Path) -> Result<LabelledMatrix, ImportError> {
    parse(&mut text_lines(text), path)
}

/// A line reader's defect as this format's.
fn abaqus(e: ImportError) -> ImportError {
    relabelled(e, FORMAT)
}

fn parse<R: BufRead>(lines: &mut Lines<R>, path: &Path) -> Result<LabelledMatrix, ImportError> {
    let mut entries = Vec::new();
    while let Some(line) = lines.next(path).map_err(abaqus)? {
        let t = line.trim();
        if t.is_empty() || t.starts_with('*') {
            continue;
        }
        let e = entry(t, lines.line()).map_err(|m| abaqus(lines.error(path, m)))?;
        if entries.len() == entries.capacity() && entries.try_reserve(1).is_err() {
            let m = format!("out of memory after {} entries", entries.len());
            return Err(abaqus(lines.error(path, m)));
        }
        entries.push(e);
    }
    if entries.is_empty() {
        return Err(defect(
            path,
            FORMAT,
            format!("no entry: allowed one {ALLOWED_ENTRY} line per stored entry"),
        ));
    }
    Ok(LabelledMatrix {
        entries,
        storage: Storage::Symmetric,
    })
}

/// The entry of the data line `t` (line number `line`).
fn entry(t: &str, line: usize) -> Result<LabelledEntry, String> {
    let words: Vec<&str> = t
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|w| !w.is_empty())
        .collect();
    let [rn, rc, cn, cc, v] = words.as_slice() else {
        let hint = if words.len() == 3 {
            " (a `row column value` line has no node labels: write the matrices with \
             FORMAT=MATRIX INPUT, or read such files with format = \"calculix\" or \
             \"matrix-market\" and a dof_map)"
        } else {
            ""
        };
        return Err(format!(
            "{} has {} fields: allowed {ALLOWED_ENTRY}{hint}",
            quoted(t),
            words.len()
        ));
    };
    let at = |m: String| format!("{}: {m}", quoted(t));
    let label = |n: &str, c: &str| -> Result<NodeComponent, String> {
        Ok(NodeComponent {
            node: node_label(n).map_err(at)?,
            component: component_label(c).map_err(at)?,
        })
    };
    Ok(LabelledEntry {
        row: label(rn, rc)?,
        col: label(cn, cc)?,
        value: fortran_real(v).map_err(at)?,
        line,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::DofMap;
    use crate::matrix_market::labelled_dof_map;

    fn error(text: &str) -> String {
        match parse_abaqus_matrix(text, Path::new("b_STIF1.mtx")) {
            Ok(m) => {
                let map = labelled_dof_map(&[&m]).unwrap();
                m.on_rows(&map, Path::new("b_STIF1.mtx"), FORMAT)
                    .unwrap_err()
                    .to_string()
            }
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn either_triangle_or_both_give_the_same_matrix_on_rows_sorted_by_node() {
        let lower = "** K\n7,1, 7,1, 2.0\n7,2, 7,1, -1.0\n7,2, 7,2, 2.0\n3,1, 3,1, 5.\n";
        let upper = "7 1 7 1 2.0\n7 1 7 2 -1.0\n7 2 7 2 2.0\n3 1 3 1 5.0D0\n";
        let square = "7,1,7,1,2\n7,1,7,2,-1\n7,2,7,1,-1\n7,2,7,2,2\n3,1,3,1,5\n";
        let read = |t: &str| {
            let m = parse_abaqus_matrix(t, Path::new("a.mtx")).unwrap();
            let map = labelled_dof_map(&[&m]).unwrap();
            (m.on_rows(&map, Path::new("a.mtx"), FORMAT).unwrap(), map)
        };
        let (a, map) = read(lower);
        let expected = DofMap::new(
            [(3, 1), (7, 1), (7, 2)]
                .map(|(node, component)| NodeComponent { node, component })
                .to_vec(),
        )
        .unwrap();
        assert_eq!(map, expected);
        for text in [upper, square] {
            let (b, m) = read(text);
            assert_eq!(m, expected);
            assert_eq!(a.to_dense(), b.to_dense());
        }
        assert_eq!(a.to_dense()[(2, 1)], -1.0);
        assert_eq!(a.to_dense()[(0, 0)], 5.0);
    }

    #[test]
    fn every_defect_names_the_file_the_line_what_was_found_and_what_is_allowed() {
        for (text, words) in [
            (
                "1,1,1,1,1\n1 2 3\n",
                &[
                    "b_STIF1.mtx",
                    "line 2",
                    "3 fields",
                    "node, dof, node, dof, value",
                    "calculix",
                ][..],
            ),
            ("1,1,-4,1,1\n", &["line 1", "node `-4`", "Lagrange", ">= 1"]),
            ("1,1,2,7,1\n", &["line 1", "component `7`", "1..=6"]),
            ("1,1,1,1,x\n", &["line 1", "value `x`", "real number"]),
            ("** nothing\n", &["no entry"]),
            (
                "1,1,1,1,1\n2,1,1,1,3\n1,1,2,1,4\n",
                &["line 3", "mirror on line 2", "both with equal values"],
            ),
            (
                "1,1,1,1,1\n1,1,1,1,1\n",
                &["line 2", "given again (first on line 1)", "once"],
            ),
        ] {
            let e = error(text);
            for w in words {
                assert!(e.contains(w), "`{w}` not in: {e}");
            }
            assert!(
                e.starts_with("b_STIF1.mtx: not a valid Abaqus matrix file"),
                "{e}"
            );
        }
    }
}
