//! Node coordinates of a finite-element mesh, read from the `*NODE` blocks of a CalculiX or
//! Abaqus input deck (`.inp`): data lines `node, x, y, z` (a missing coordinate is 0), node
//! labels `>= 1`, each node once. Other keywords' blocks and `**` comments are skipped;
//! `*INCLUDE, INPUT=file` is followed ([`MAX_INCLUDE_DEPTH`] deep, relative to the including
//! file, cycles refused). With the coordinates, a contact's normal can be computed from the
//! geometry ([`radial_direction`]). The `*ELEMENT` blocks give the cells ([`MeshElements`]).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

pub use super::deck::MAX_INCLUDE_DEPTH;
use super::deck::{Deck, IncludeError};
use super::dof_map::read_text;
use super::DofMapError;

/// Why a mesh could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MeshError {
    /// The file could not be read (missing, not a regular file, too large, not text).
    #[error("{0}")]
    File(DofMapError),
    /// A data line of a `*NODE` block is not a node and its coordinates.
    #[error("{path}: line {line}: `{text}`: {problem}: allowed `node, x, y, z` (node >= 1)")]
    Line {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// The line's text (cut at 60 characters).
        text: String,
        /// What is wrong with it.
        problem: String,
    },
    /// An `*INCLUDE` could not be followed.
    #[error("{0}")]
    Include(#[from] IncludeError),
    /// A data line of an `*ELEMENT` block is not an element and its nodes.
    #[error("{path}: line {line}: `{text}`: {problem}: allowed `element, node, node, ...` (labels >= 1; a line ending in a comma continues)")]
    ElementLine {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// The line's text (cut at 60 characters).
        text: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The deck has no node.
    #[error("{path}: no *NODE block with a node: allowed an input deck with its nodes")]
    Empty {
        /// The file.
        path: PathBuf,
    },
}

/// The coordinates of a mesh's nodes by node label.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MeshNodes {
    coordinates: HashMap<u64, [f64; 3]>,
}

impl MeshNodes {
    /// Reads the `*NODE` blocks of the input deck `path` (module documentation).
    pub fn read_inp(path: &Path) -> Result<Self, MeshError> {
        let text = read_text(path).map_err(MeshError::File)?;
        Self::parse_inp(&text, path)
    }

    /// Parses the text of the input deck `path` (its includes are read from disk).
    pub fn parse_inp(text: &str, path: &Path) -> Result<Self, MeshError> {
        let deck = Deck::parse(text, path)?;
        let mut coordinates = HashMap::new();
        let mut first_line = HashMap::new();
        for (line, t) in block_lines(&deck, "*NODE") {
            let error = |problem: String| MeshError::Line {
                path: deck.file_of(line).to_path_buf(),
                line: line.line,
                text: shown(t),
                problem,
            };
            let words: Vec<&str> = t.split(',').map(str::trim).collect();
            let words = match words.last() {
                Some(&"") => &words[..words.len() - 1],
                _ => &words[..],
            };
            if !(2..=4).contains(&words.len()) {
                return Err(error(format!("{} fields", words.len())));
            }
            let node = match words[0].parse::<u64>() {
                Ok(n) if n >= 1 => n,
                _ => return Err(error(format!("node `{}`", words[0]))),
            };
            let mut x = [0.0; 3];
            for (c, w) in words[1..].iter().enumerate() {
                x[c] = w
                    .replace(['D', 'd'], "e")
                    .parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite())
                    .ok_or_else(|| error(format!("coordinate `{w}`")))?;
            }
            let place = (deck.file_of(line).display().to_string(), line.line);
            if let Some(first) = first_line.insert(node, place) {
                let at = if first.0 == deck.file_of(line).display().to_string() {
                    format!("line {}", first.1)
                } else {
                    format!("{} line {}", first.0, first.1)
                };
                return Err(error(format!("node {node} again (first on {at})")));
            }
            coordinates.insert(node, x);
        }
        if coordinates.is_empty() {
            return Err(MeshError::Empty {
                path: path.to_path_buf(),
            });
        }
        Ok(Self { coordinates })
    }

    /// Every node and its coordinates, by ascending label.
    pub fn sorted(&self) -> Vec<(u64, [f64; 3])> {
        let mut nodes: Vec<(u64, [f64; 3])> =
            self.coordinates.iter().map(|(n, x)| (*n, *x)).collect();
        nodes.sort_unstable_by_key(|(n, _)| *n);
        nodes
    }

    /// The coordinates of `node`, if the mesh has it.
    pub fn coordinates(&self, node: u64) -> Option<[f64; 3]> {
        self.coordinates.get(&node).copied()
    }

    /// Number of nodes.
    pub fn len(&self) -> usize {
        self.coordinates.len()
    }

    /// No node (only a default value; a read mesh has one).
    pub fn is_empty(&self) -> bool {
        self.coordinates.is_empty()
    }
}

/// The data lines of the deck's blocks whose keyword is `keyword` (case-insensitive), with
/// the parameters of the block's keyword line: `(line, text)`.
fn block_lines<'d>(deck: &'d Deck, keyword: &str) -> Vec<(&'d super::deck::DeckLine, &'d str)> {
    keyword_blocks(deck, keyword)
        .into_iter()
        .flat_map(|(_, lines)| lines)
        .collect()
}

/// The blocks of `keyword`: each keyword line's text and its data lines.
fn keyword_blocks<'d>(
    deck: &'d Deck,
    keyword: &str,
) -> Vec<(&'d str, Vec<(&'d super::deck::DeckLine, &'d str)>)> {
    let mut blocks: Vec<(&str, Vec<_>)> = Vec::new();
    let mut inside = false;
    for line in &deck.lines {
        let t = line.text.as_str();
        if t.starts_with('*') {
            let word = t.split(',').next().unwrap_or("").trim();
            inside = word.eq_ignore_ascii_case(keyword);
            if inside {
                blocks.push((t, Vec::new()));
            }
        } else if inside {
            if let Some(b) = blocks.last_mut() {
                b.1.push((line, t));
            }
        }
    }
    blocks
}

/// A line's text as a message shows it: escaped, cut at 60 characters.
fn shown(t: &str) -> String {
    t.chars()
        .take(60)
        .collect::<String>()
        .escape_default()
        .to_string()
}

/// One element of a mesh: its label, its type as the deck names it (upper case, e.g.
/// `C3D8`) and its nodes in the deck's order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MeshElement {
    /// The element label (`>= 1`).
    pub label: u64,
    /// `TYPE=` of its `*ELEMENT` block, upper case (empty when the block names none).
    pub kind: String,
    /// Its node labels.
    pub nodes: Vec<u64>,
}

/// The elements of an input deck's `*ELEMENT` blocks (`*ELEMENT, TYPE=C3D8`, data lines
/// `element, node, node, ...`; a line ending in a comma continues on the next line).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MeshElements {
    /// In the deck's order.
    pub elements: Vec<MeshElement>,
}

impl MeshElements {
    /// Reads the `*ELEMENT` blocks of the input deck `path` and its includes.
    pub fn read_inp(path: &Path) -> Result<Self, MeshError> {
        let text = read_text(path).map_err(MeshError::File)?;
        Self::parse_inp(&text, path)
    }

    /// Parses the `*ELEMENT` blocks of the deck `path` whose text is `text`.
    pub fn parse_inp(text: &str, path: &Path) -> Result<Self, MeshError> {
        let deck = Deck::parse(text, path)?;
        let mut elements = Vec::new();
        for (head, lines) in keyword_blocks(&deck, "*ELEMENT") {
            let kind = head
                .split(',')
                .skip(1)
                .find_map(|p| {
                    let (k, v) = p.split_once('=')?;
                    k.trim()
                        .eq_ignore_ascii_case("TYPE")
                        .then(|| v.trim().to_uppercase())
                })
                .unwrap_or_default();
            let mut pending: Option<(&super::deck::DeckLine, Vec<u64>)> = None;
            for (line, t) in lines {
                let error = |problem: String| MeshError::ElementLine {
                    path: deck.file_of(line).to_path_buf(),
                    line: line.line,
                    text: shown(t),
                    problem,
                };
                let continues = t.ends_with(',');
                let mut labels = pending.take().unwrap_or((line, Vec::new()));
                for w in t.trim_end_matches(',').split(',').map(str::trim) {
                    match w.parse::<u64>() {
                        Ok(n) if n >= 1 => labels.1.push(n),
                        _ => return Err(error(format!("label `{w}`"))),
                    }
                }
                if continues {
                    pending = Some(labels);
                } else if labels.1.len() < 2 {
                    return Err(error("an element without nodes".into()));
                } else {
                    elements.push(element(&kind, &labels.1));
                }
            }
            // A block's last line may end in a comma: its element ends with the block.
            if let Some((_, labels)) = pending.filter(|p| p.1.len() >= 2) {
                elements.push(element(&kind, &labels));
            }
        }
        Ok(Self { elements })
    }
}

/// The element of type `kind` whose label and nodes are `labels`.
fn element(kind: &str, labels: &[u64]) -> MeshElement {
    MeshElement {
        label: labels[0],
        kind: kind.to_string(),
        nodes: labels[1..].to_vec(),
    }
}

/// The unit vector from the axis through `origin` along `axis` to `point`, perpendicular to
/// the axis: `r / |r|` with `r = d - (d . a) a`, `d = point - origin`, `a = axis / |axis|`.
/// `None` when `axis` is zero or not finite, or `point` is on the axis (`|r|` at most
/// `1e-12` of `|d|`).
pub fn radial_direction(point: [f64; 3], origin: [f64; 3], axis: [f64; 3]) -> Option<[f64; 3]> {
    let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let norm_a = dot(axis, axis).sqrt();
    if !(norm_a.is_finite() && norm_a > 0.0) {
        return None;
    }
    let a = axis.map(|v| v / norm_a);
    let d = [0, 1, 2].map(|i| point[i] - origin[i]);
    let along = dot(d, a);
    let r = [0, 1, 2].map(|i| d[i] - along * a[i]);
    let norm_r = dot(r, r).sqrt();
    if !(norm_r.is_finite() && norm_r > 1e-12 * dot(d, d).sqrt()) {
        return None;
    }
    Some(r.map(|v| v / norm_r))
}

#[cfg(test)]
mod tests {
    use super::*;

    const DECK: &str = "*HEADING\nmesh\n*NODE, NSET=NALL\n1, 0, 0, 0\n2, 3.0, 4.0, 5\n\
                        ** a comment\n7, 1.5, -2,\n*NODE OUTPUT\nU\n*ELEMENT, TYPE=C3D8\n\
                        1, 1, 2, 7, 1, 2, 7, 1, 2\n*node\n9, 1.0D1\n";

    #[test]
    fn node_blocks_give_coordinates_and_other_blocks_are_skipped() {
        let mesh = MeshNodes::parse_inp(DECK, Path::new("m.inp")).unwrap();
        assert_eq!(mesh.len(), 4);
        assert_eq!(mesh.coordinates(2), Some([3.0, 4.0, 5.0]));
        assert_eq!(mesh.coordinates(7), Some([1.5, -2.0, 0.0]));
        assert_eq!(mesh.coordinates(9), Some([10.0, 0.0, 0.0]));
        assert_eq!(mesh.coordinates(3), None);
    }

    #[test]
    fn every_defect_names_the_file_the_line_and_what_is_allowed() {
        for (text, words) in [
            (
                "*NODE\n1, 0, 0\n1, 1, 1\n",
                &["line 3", "node 1 again", "line 2"][..],
            ),
            ("*NODE\n0, 1, 1\n", &["line 2", "node `0`", "node >= 1"]),
            ("*NODE\n4, 1, x\n", &["line 2", "coordinate `x`"]),
            ("*NODE\n4, 1, 2, 3, 4\n", &["line 2", "5 fields"]),
            ("*ELEMENT\n1, 2, 3\n", &["no *NODE block"]),
        ] {
            let e = MeshNodes::parse_inp(text, Path::new("m.inp"))
                .unwrap_err()
                .to_string();
            for w in words {
                assert!(e.contains(w), "`{w}` not in: {e}");
            }
            assert!(e.starts_with("m.inp: "), "{e}");
        }
    }

    #[test]
    fn element_blocks_give_types_and_nodes_and_a_trailing_comma_continues_the_line() {
        let deck = "*NODE\n1, 0, 0, 0\n*ELEMENT, TYPE=c3d8, ELSET=E\n\
                    4, 1, 2, 3, 4, 5, 6, 7, 8\n*ELEMENT, ELSET=F, TYPE=C3D20\n\
                    5, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15,\n\
                    16, 17, 18, 19, 20\n*BOUNDARY\n1, 1, 3\n";
        let e = MeshElements::parse_inp(deck, Path::new("m.inp"))
            .unwrap()
            .elements;
        assert_eq!(e.len(), 2);
        assert_eq!((e[0].label, e[0].kind.as_str()), (4, "C3D8"));
        assert_eq!(e[0].nodes, (1..=8).collect::<Vec<u64>>());
        assert_eq!((e[1].label, e[1].kind.as_str()), (5, "C3D20"));
        assert_eq!(e[1].nodes, (1..=20).collect::<Vec<u64>>());
        let bad = MeshElements::parse_inp("*ELEMENT, TYPE=S4\n1, 2, x\n", Path::new("m.inp"));
        let bad = bad.unwrap_err().to_string();
        assert!(
            bad.starts_with("m.inp: line 2: `1, 2, x`: label `x`"),
            "{bad}"
        );
    }

    #[test]
    fn the_radial_direction_is_the_hand_computed_one() {
        // About the z axis through (1, 1, 0): the point (4, 5, 7) is at (3, 4) in the plane,
        // so the normal is (3, 4, 0) / 5 whatever its height.
        let n = radial_direction([4.0, 5.0, 7.0], [1.0, 1.0, 0.0], [0.0, 0.0, 2.0]).unwrap();
        assert_eq!(n, [0.6, 0.8, 0.0]);
        // About the axis (1, 1, 0) / sqrt 2 through 0: (1, 0, 1) has the component 1/2 along
        // (1, 1, 0), leaving (1/2, -1/2, 1) of norm sqrt(3/2).
        let n = radial_direction([1.0, 0.0, 1.0], [0.0; 3], [1.0, 1.0, 0.0]).unwrap();
        let s = (1.5f64).sqrt();
        for (got, want) in n.iter().zip([0.5 / s, -0.5 / s, 1.0 / s]) {
            assert!((got - want).abs() < 1e-15, "{n:?}");
        }
        assert_eq!(
            radial_direction([0.0, 0.0, 3.0], [0.0; 3], [0.0, 0.0, 1.0]),
            None
        );
        assert_eq!(radial_direction([1.0, 0.0, 0.0], [0.0; 3], [0.0; 3]), None);
    }
}
