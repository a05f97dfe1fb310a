//! Ansys' mapping file (`HBMAT, ..., Mapping = YES` writes `Fname.mapping` beside the
//! Harwell-Boeing matrix): a title line, then one line per matrix equation,
//! `equation node dof` with the dof a label (`UX`, `UY`, `UZ`, `ROTX`, `ROTY`, `ROTZ`:
//! components 1 to 6). Every equation `1..=N` once, in any order.

use std::path::Path;

use super::dof_map::read_text;
use super::{DofMap, DofMapError, NodeComponent};

/// The dof labels of Ansys, component 1 first.
const LABELS: [&str; 6] = ["UX", "UY", "UZ", "ROTX", "ROTY", "ROTZ"];

/// What a line of the mapping file may be.
const ALLOWED: &str = "`equation node dof` (equation 1..=N once each, node >= 1, dof one of \
                       UX, UY, UZ, ROTX, ROTY, ROTZ)";

impl DofMap {
    /// Reads Ansys' mapping file `path`: a title line, then `equation node dof` lines (dof
    /// `UX`, `UY`, `UZ`, `ROTX`, `ROTY`, `ROTZ`), every equation `1..=N` once.
    pub fn read_ansys_mapping(path: &Path) -> Result<Self, DofMapError> {
        Self::parse_ansys_mapping(&read_text(path)?, path)
    }

    /// Parses the text of an Ansys mapping file (`path` for messages only).
    pub fn parse_ansys_mapping(text: &str, path: &Path) -> Result<Self, DofMapError> {
        let error = |line: usize, t: &str, problem: String| {
            let cut: String = t.chars().take(60).collect();
            DofMapError::Line {
                path: path.to_path_buf(),
                line,
                text: cut.escape_default().to_string(),
                problem,
                allowed: ALLOWED.to_string(),
            }
        };
        let mut by_equation: Vec<(usize, NodeComponent, usize)> = Vec::new();
        for (k, line) in text.lines().enumerate() {
            let t = line.trim();
            // The title line (and any other line not starting with a number) is skipped.
            if !t.starts_with(|c: char| c.is_ascii_digit()) {
                continue;
            }
            let words: Vec<&str> = t.split_whitespace().collect();
            let [equation, node, dof] = words.as_slice() else {
                return Err(error(k + 1, t, format!("{} words", words.len())));
            };
            let equation = equation
                .parse::<usize>()
                .ok()
                .filter(|&e| e >= 1)
                .ok_or_else(|| error(k + 1, t, format!("equation `{equation}`")))?;
            let node = node
                .parse::<u64>()
                .ok()
                .filter(|&n| n >= 1)
                .ok_or_else(|| error(k + 1, t, format!("node `{node}`")))?;
            let component = LABELS
                .iter()
                .position(|l| l.eq_ignore_ascii_case(dof))
                .ok_or_else(|| error(k + 1, t, format!("dof `{dof}`")))?;
            let component = component as u8 + 1;
            by_equation.push((equation, NodeComponent { node, component }, k + 1));
        }
        if by_equation.is_empty() {
            return Err(DofMapError::Empty {
                path: path.to_path_buf(),
            });
        }
        by_equation.sort_by_key(|e| e.0);
        let n = by_equation.len();
        for (k, &(equation, _, line)) in by_equation.iter().enumerate() {
            if equation != k + 1 {
                let problem = match equation.cmp(&(k + 1)) {
                    std::cmp::Ordering::Less => format!("equation {equation} again"),
                    _ => format!("equation {equation} with equation {} missing", k + 1),
                };
                return Err(error(
                    line,
                    &format!("{equation}"),
                    format!("{problem} (N = {n})"),
                ));
            }
        }
        let lines: Vec<usize> = by_equation.iter().map(|e| e.2).collect();
        let rows = by_equation.into_iter().map(|e| e.1).collect();
        Self::new(rows).map_err(|(first, k)| {
            let r = |row: usize| lines[row];
            DofMapError::Line {
                path: path.to_path_buf(),
                line: r(k),
                text: String::new(),
                problem: format!("the node and dof of line {} again", r(first)),
                allowed: ALLOWED.to_string(),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn equations_in_any_order_give_the_rows_by_equation() {
        let text = "Matrix Eqn   Node  DOF\n   2   7  uy\n   1   7  UX\n   3  12  ROTZ\n";
        let map = DofMap::parse_ansys_mapping(text, Path::new("m.mapping")).unwrap();
        assert_eq!(map.len(), 3);
        assert_eq!(map.row(7, 1), Some(0));
        assert_eq!(map.row(7, 2), Some(1));
        assert_eq!(map.row(12, 6), Some(2));
    }

    #[test]
    fn every_defect_names_the_file_the_line_and_what_is_allowed() {
        for (text, words) in [
            (
                "Eqn Node DOF\n1 7 UX\n2 7 TEMP\n",
                &["line 3", "dof `TEMP`", "ROTZ"][..],
            ),
            ("1 7 UX\n2 0 UY\n", &["line 2", "node `0`"]),
            ("1 7 UX\n1 8 UY\n", &["equation 1 again"]),
            ("1 7 UX\n3 8 UY\n", &["equation 2 missing"]),
            ("1 7 UX\n2 7 ux\n", &["line 2", "again"]),
            ("1 7\n", &["line 1", "2 words"]),
            ("title only\n", &["no row"]),
        ] {
            let e = DofMap::parse_ansys_mapping(text, Path::new("m.mapping"))
                .unwrap_err()
                .to_string();
            for w in words {
                assert!(e.contains(w), "`{w}` not in: {e}");
            }
            assert!(e.starts_with("m.mapping: "), "{e}");
        }
    }
}
