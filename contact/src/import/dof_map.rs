//! The map between matrix rows and the (node, component) pairs of a finite-element mesh.
//!
//! A dof map file has one line per matrix row, in row order, naming the row's node and
//! component: `node.component` as CalculiX's `.dof` files write it (`12.1`), or
//! `node component` (`12 1`). Nodes are integers `>= 1`; components are `1..=`
//! [`MAX_COMPONENT`] (1, 2, 3 for x, y, z; 4, 5, 6 for the rotations). Blank lines and lines
//! starting with `#` are skipped. Every defect names the file, the line, the text found and
//! what is allowed; a (node, component) named twice is a defect.

use std::collections::HashMap;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Largest component number: 1, 2, 3 translate along x, y, z; 4, 5, 6 rotate about them.
pub const MAX_COMPONENT: u8 = 6;

/// Largest dof map file read (bytes).
pub const MAX_DOF_MAP_BYTES: u64 = 1 << 30;

/// A node and one of its components (1-based, as finite-element codes number them).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct NodeComponent {
    /// The node number (`>= 1`).
    pub node: u64,
    /// The component (`1..=MAX_COMPONENT`).
    pub component: u8,
}

/// The rows of a model's matrices by node and component, both ways: [`DofMap::row`] and
/// [`DofMap::node_component`]. Each (node, component) names at most one row.
#[derive(Debug, Clone, PartialEq)]
pub struct DofMap {
    rows: Vec<NodeComponent>,
    index: HashMap<NodeComponent, usize>,
}

/// Why a dof map could not be read: the file, and for a defect of a line the line, the text
/// found and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum DofMapError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The system error.
        source: std::io::Error,
    },
    /// The path is not a regular file (a FIFO could block forever, a device never end).
    #[error("{path}: not a regular file: allowed a regular dof map file")]
    NotRegular {
        /// The file.
        path: PathBuf,
    },
    /// The file is larger than [`MAX_DOF_MAP_BYTES`].
    #[error("{path}: more than {limit} bytes: allowed at most {limit} bytes for a dof map")]
    TooLarge {
        /// The file.
        path: PathBuf,
        /// The limit.
        limit: u64,
    },
    /// A line is not a node and a component.
    #[error("{path}: line {line}: `{text}`: {problem}: allowed {allowed}")]
    Line {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// The line's text (escaped, cut at 60 characters).
        text: String,
        /// What is wrong with it.
        problem: String,
        /// What is allowed.
        allowed: String,
    },
    /// A (node, component) names two rows.
    #[error(
        "{path}: line {line}: node {node} component {component} again (first on line \
         {first_line}): allowed each node and component once (one row each)"
    )]
    Duplicate {
        /// The file.
        path: PathBuf,
        /// 1-based line of the second occurrence.
        line: usize,
        /// 1-based line of the first.
        first_line: usize,
        /// The node.
        node: u64,
        /// The component.
        component: u8,
    },
    /// The file names no row.
    #[error(
        "{path}: no row: allowed one line per matrix row (`node.component` or `node component`)"
    )]
    Empty {
        /// The file.
        path: PathBuf,
    },
}

/// What a line of a dof map may be.
const ALLOWED_LINE: &str = "`node.component` (as CalculiX's .dof files, e.g. `12.1`) or \
                            `node component`, node >= 1, component 1..=6 (1, 2, 3: x, y, z)";

impl DofMap {
    /// The map whose row `k` is `rows[k]`; `Err((first, k))` when `rows[k]` repeats
    /// `rows[first]`.
    pub fn new(rows: Vec<NodeComponent>) -> Result<Self, (usize, usize)> {
        let mut index = HashMap::with_capacity(rows.len());
        for (k, r) in rows.iter().enumerate() {
            if let Some(first) = index.insert(*r, k) {
                return Err((first, k));
            }
        }
        Ok(Self { rows, index })
    }

    /// Reads the dof map file `path` (module documentation): a regular file of at most
    /// [`MAX_DOF_MAP_BYTES`] bytes.
    pub fn read(path: &Path) -> Result<Self, DofMapError> {
        Self::parse(&read_text(path)?, path)
    }

    /// Parses dof map text (`path` for messages only).
    pub fn parse(text: &str, path: &Path) -> Result<Self, DofMapError> {
        let data = || {
            text.lines().enumerate().filter(|(_, line)| {
                let t = line.trim();
                !(t.is_empty() || t.starts_with('#'))
            })
        };
        let mut rows = Vec::new();
        for (k, line) in data() {
            let t = line.trim();
            rows.push(node_component(t).map_err(|m| line_error(path, k + 1, t, &m))?);
        }
        if rows.is_empty() {
            return Err(DofMapError::Empty {
                path: path.to_path_buf(),
            });
        }
        Self::new(rows).map_err(|(first, k)| {
            // The lines of the two rows (data lines are counted again: a rare path).
            let line = |row: usize| data().nth(row).map_or(0, |(l, _)| l + 1);
            let again = data().nth(k).map(|(_, l)| l.trim()).unwrap_or("");
            let r = node_component(again).unwrap_or(NodeComponent {
                node: 0,
                component: 0,
            });
            DofMapError::Duplicate {
                path: path.to_path_buf(),
                line: line(k),
                first_line: line(first),
                node: r.node,
                component: r.component,
            }
        })
    }

    /// Number of rows.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// No row (a map built by [`DofMap::new`] from nothing; a file always has one).
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The 0-based row of `node`'s `component`, if the map names it.
    pub fn row(&self, node: u64, component: u8) -> Option<usize> {
        self.index.get(&NodeComponent { node, component }).copied()
    }

    /// The node and component of the 0-based `row`, if the map has that row.
    pub fn node_component(&self, row: usize) -> Option<NodeComponent> {
        self.rows.get(row).copied()
    }

    /// The components the map names for `node`, ascending (empty: an unknown node).
    pub fn components(&self, node: u64) -> Vec<u8> {
        (1..=MAX_COMPONENT)
            .filter(|&c| self.row(node, c).is_some())
            .collect()
    }

    /// The smallest and largest node numbers (`None` for an empty map).
    pub fn node_range(&self) -> Option<(u64, u64)> {
        let nodes = self.rows.iter().map(|r| r.node);
        Some((nodes.clone().min()?, nodes.max()?))
    }
}

/// The text of the regular file `path` of at most [`MAX_DOF_MAP_BYTES`] bytes.
pub(super) fn read_text(path: &Path) -> Result<String, DofMapError> {
    let io = |source| DofMapError::Io {
        path: path.to_path_buf(),
        source,
    };
    let not_regular = || DofMapError::NotRegular {
        path: path.to_path_buf(),
    };
    if !std::fs::metadata(path).map_err(io)?.is_file() {
        return Err(not_regular());
    }
    let file = std::fs::File::open(path).map_err(io)?;
    // The path may have been replaced between the two looks: check what was opened.
    if !file.metadata().map_err(io)?.is_file() {
        return Err(not_regular());
    }
    let mut bytes = Vec::new();
    file.take(MAX_DOF_MAP_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(io)?;
    if bytes.len() as u64 > MAX_DOF_MAP_BYTES {
        return Err(DofMapError::TooLarge {
            path: path.to_path_buf(),
            limit: MAX_DOF_MAP_BYTES,
        });
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        let line = 1 + e.as_bytes()[..e.utf8_error().valid_up_to()]
            .iter()
            .filter(|b| **b == b'\n')
            .count();
        line_error(path, line, "", "not text (invalid UTF-8)")
    })?;
    Ok(text)
}

/// A line's node and component.
fn node_component(t: &str) -> Result<NodeComponent, String> {
    let words: Vec<&str> = t.split_whitespace().collect();
    let (node, component) = match words.as_slice() {
        [one] => one
            .split_once('.')
            .ok_or_else(|| "neither `node.component` nor `node component`".to_string())?,
        [node, component] => (*node, *component),
        _ => return Err(format!("{} words", words.len())),
    };
    let node = match node.parse::<u64>() {
        Ok(n) if n >= 1 => n,
        _ => return Err(format!("node `{node}`")),
    };
    let component = match component.parse::<u8>() {
        Ok(c) if (1..=MAX_COMPONENT).contains(&c) => c,
        _ => return Err(format!("component `{component}`")),
    };
    Ok(NodeComponent { node, component })
}

/// A defect of line `line` whose text is `text`.
pub(super) fn line_error(path: &Path, line: usize, text: &str, problem: &str) -> DofMapError {
    let cut: String = text.chars().take(60).collect();
    let more = if text.chars().count() > 60 { "..." } else { "" };
    DofMapError::Line {
        path: path.to_path_buf(),
        line,
        text: format!("{}{more}", cut.escape_default()),
        problem: problem.to_string(),
        allowed: ALLOWED_LINE.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(text: &str) -> String {
        DofMap::parse(text, Path::new("m.dof"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn both_notations_give_the_same_rows_and_the_map_inverts() {
        let dotted = DofMap::parse("  7.1\n7.2\n\n# a comment\n3.3\n12.6\n", Path::new("a"));
        let spaced = DofMap::parse("7 1\n7 2\n3 3\n12\t6\n", Path::new("b"));
        let (dotted, spaced) = (dotted.unwrap(), spaced.unwrap());
        assert_eq!(dotted, spaced);
        assert_eq!(dotted.len(), 4);
        for (row, (node, component)) in [(7, 1), (7, 2), (3, 3), (12, 6)].into_iter().enumerate() {
            assert_eq!(dotted.row(node, component), Some(row));
            let back = dotted.node_component(row).unwrap();
            assert_eq!((back.node, back.component), (node, component));
        }
        assert_eq!(dotted.row(7, 3), None);
        assert_eq!(dotted.row(8, 1), None);
        assert_eq!(dotted.node_component(4), None);
        assert_eq!(dotted.components(7), vec![1, 2]);
        assert!(dotted.components(5).is_empty());
        assert_eq!(dotted.node_range(), Some((3, 12)));
    }

    #[test]
    fn every_defect_names_the_file_the_line_the_text_and_what_is_allowed() {
        for (text, words) in [
            (
                "1.1\n1.x\n",
                &["m.dof: line 2", "`1.x`", "component `x`", "1..=6"][..],
            ),
            ("1.1\n1.7\n", &["line 2", "component `7`", "1..=6"]),
            ("1.1\n\n0.1\n", &["line 3", "node `0`", "node >= 1"]),
            ("-2 1\n", &["line 1", "node `-2`"]),
            ("12\n", &["line 1", "`12`", "node.component"]),
            ("1 2 3\n", &["line 1", "3 words"]),
            (
                "1.1\n2.1\n1 1\n",
                &["line 3", "node 1 component 1 again", "line 1", "once"],
            ),
            (
                "\n# nothing\n",
                &["m.dof", "no row", "one line per matrix row"],
            ),
        ] {
            let e = error(text);
            for w in words {
                assert!(e.contains(w), "`{w}` not in: {e}");
            }
            assert!(e.starts_with("m.dof: "), "{e}");
        }
    }

    #[test]
    fn a_missing_file_and_a_directory_are_named() {
        let missing = DofMap::read(Path::new("/nonexistent/m.dof")).unwrap_err();
        assert!(matches!(missing, DofMapError::Io { .. }), "{missing}");
        let dir = DofMap::read(Path::new(env!("CARGO_MANIFEST_DIR"))).unwrap_err();
        assert!(matches!(dir, DofMapError::NotRegular { .. }), "{dir}");
    }
}
