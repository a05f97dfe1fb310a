//! Nastran DMIG matrices in a punch file (`.pch`, as `EXTSEOUT` or a DMAP `MATPCH` writes
//! the stiffness `KAAX` and mass `MAAX`) or in bulk data. A matrix is a header card
//! `DMIG, NAME, 0, IFO, TIN, TOUT, POLAR, , NCOL` (IFO 6: symmetric, one triangle given; 1:
//! square; TIN 1 or 2: real, single or double precision) and one card per column
//! `DMIG, NAME, GJ, CJ, , G1, C1, A1, B1, G2, C2, A2, B2, ...` (column node and component,
//! then row node, component and value; B, the imaginary part, blank).
//!
//! Cards are read in small fields (eight characters after the eight of the card's name),
//! large fields (`DMIG*`: four fields of sixteen characters a line) or free fields (commas),
//! continued on lines whose first field is blank or starts with `+` or `*`; lines starting
//! with `$` are comments and cards other than DMIG are skipped. Reals may be written as
//! Nastran does (`1.5+3`, `2.D-4`). Every defect names the file, the line, the field, what
//! was found and what is allowed.

use std::io::BufRead;
use std::path::Path;

use super::labelled::{
    component_label, defect, fortran_real, node_label, relabelled, LabelledEntry, LabelledMatrix,
    Storage,
};
use super::read::{open_lines, quoted, text_lines, Lines};
use super::ImportError;
use crate::import::{NodeComponent, Part};

/// The format's name in messages.
const FORMAT: &str = super::MatrixFormat::NastranDmig.file_kind();

/// A matrix of a DMIG file: its name and its entries.
#[derive(Debug, Clone, PartialEq)]
pub struct DmigMatrix {
    /// The header's NAME (e.g. `KAAX`).
    pub name: String,
    /// Its entries (symmetric storage for IFO 6, general for IFO 1).
    pub matrix: LabelledMatrix,
}

/// Reads every DMIG matrix of the file `path` (module documentation), in file order.
pub fn read_dmig(path: &Path) -> Result<Vec<DmigMatrix>, ImportError> {
    parse(&mut open_lines(path).map_err(nastran)?, path)
}

/// Parses DMIG text (`path` for messages only).
pub fn parse_dmig(text: &str, path: &Path) -> Result<Vec<DmigMatrix>, ImportError> {
    parse(&mut text_lines(text), path)
}

/// The matrix of `matrices` that is the model's `part`: the only one, else the only one
/// whose name starts with `K` (stiffness), `M` (mass) or `B` (damping), as Nastran names
/// them (`KAAX`, `MAAX`, `BAAX`).
pub fn select_dmig<'a>(
    matrices: &'a [DmigMatrix],
    part: Part,
    path: &Path,
) -> Result<&'a LabelledMatrix, ImportError> {
    if let [only] = matrices {
        return Ok(&only.matrix);
    }
    let letter = match part {
        Part::Stiffness => 'K',
        Part::Mass => 'M',
        _ => 'B',
    };
    let candidates: Vec<&DmigMatrix> = matrices
        .iter()
        .filter(|m| m.name.starts_with(letter))
        .collect();
    match candidates.as_slice() {
        [one] => Ok(&one.matrix),
        _ => {
            let names: Vec<&str> = matrices.iter().map(|m| m.name.as_str()).collect();
            Err(defect(
                path,
                FORMAT,
                format!(
                    "the {part} is not one matrix of {}: allowed one matrix, or one whose name \
                     starts with `{letter}` (KAAX, MAAX, BAAX for the stiffness, mass, damping)",
                    names.join(", ")
                ),
            ))
        }
    }
}

/// A line reader's defect as this format's.
fn nastran(e: ImportError) -> ImportError {
    relabelled(e, FORMAT)
}

/// A field of a card: its text (trimmed), its line and its place on the line (2..=9 in
/// small fields, 2..=5 in large ones: field 1 is the card's name or the continuation mark).
#[derive(Debug, Clone)]
struct Field {
    text: String,
    line: usize,
    place: usize,
}

/// A bulk data card: its name (`DMIG`) and the fields after it, continuation lines appended.
#[derive(Debug, Clone)]
struct Card {
    name: String,
    fields: Vec<Field>,
    line: usize,
}

/// The first field and the data fields of a line (module documentation).
fn split_line(line: &str) -> Result<(String, Vec<String>), String> {
    if line.contains('\t') {
        return Err("a tab: allowed blanks (fixed fields) or commas (free fields)".into());
    }
    if line.contains(',') {
        let mut words = line.split(',').map(|w| w.trim().to_string());
        let first = words.next().unwrap_or_default();
        let mut fields: Vec<String> = words.collect();
        // A short free-field line leaves its last fields blank.
        let per_line = if first.ends_with('*') { 4 } else { 8 };
        let padded = fields.len().div_ceil(per_line).max(1) * per_line;
        fields.resize(padded, String::new());
        return Ok((first, fields));
    }
    let chars: Vec<char> = line.chars().collect();
    let cut = |from: usize, to: usize| -> String {
        let (a, b) = (from.min(chars.len()), to.min(chars.len()));
        chars[a..b].iter().collect::<String>().trim().to_string()
    };
    let first = cut(0, 8);
    let (width, count) = if first.ends_with('*') || first.starts_with('*') {
        (16, 4)
    } else {
        (8, 8)
    };
    let fields = (0..count)
        .map(|k| cut(8 + k * width, 8 + (k + 1) * width))
        .collect();
    Ok((first, fields))
}

/// The cards of the file, comments skipped.
fn cards<R: BufRead>(lines: &mut Lines<R>, path: &Path) -> Result<Vec<Card>, ImportError> {
    let mut cards: Vec<Card> = Vec::new();
    while let Some(line) = lines.next(path).map_err(nastran)? {
        if line.trim().is_empty() || line.trim_start().starts_with('$') {
            continue;
        }
        let at = lines.line();
        let (first, data) = split_line(&line).map_err(|m| nastran(lines.error(path, m)))?;
        let fields = data.into_iter().enumerate().map(|(k, text)| Field {
            text,
            line: at,
            place: k + 2,
        });
        let continuation = first.is_empty() || first.starts_with(['+', '*']);
        match cards.last_mut() {
            Some(card) if continuation => card.fields.extend(fields),
            None if continuation => {
                let m = format!(
                    "{} continues no card: allowed a card name (DMIG) first",
                    quoted(&line)
                );
                return Err(nastran(lines.error(path, m)));
            }
            _ => cards.push(Card {
                name: first.trim_end_matches('*').to_uppercase(),
                fields: fields.collect(),
                line: at,
            }),
        }
    }
    Ok(cards)
}

/// A defect of the card's data field `k` (0-based after the card's name), named by its line
/// and its place on the line.
fn field_error(path: &Path, card: &Card, k: usize, m: String) -> ImportError {
    let (line, place) = match card.fields.get(k) {
        Some(f) => (f.line, f.place.to_string()),
        None => (
            card.fields.last().map_or(card.line, |f| f.line),
            "after the last".to_string(),
        ),
    };
    defect(path, FORMAT, format!("line {line}: field {place}: {m}"))
}

/// The text of field `k` of `card` (empty when the card is shorter).
fn text(card: &Card, k: usize) -> &str {
    card.fields.get(k).map_or("", |f| f.text.as_str())
}

fn parse<R: BufRead>(lines: &mut Lines<R>, path: &Path) -> Result<Vec<DmigMatrix>, ImportError> {
    let mut matrices: Vec<DmigMatrix> = Vec::new();
    for card in cards(lines, path)?.iter().filter(|c| c.name == "DMIG") {
        let name = text(card, 0).to_uppercase();
        if name.is_empty() {
            return Err(field_error(
                path,
                card,
                0,
                "no NAME: allowed the matrix's name".into(),
            ));
        }
        let known = matrices.iter().position(|m| m.name == name);
        if text(card, 1) == "0" {
            if known.is_some() {
                let m = format!("a second header of {name}: allowed one header per matrix");
                return Err(field_error(path, card, 1, m));
            }
            matrices.push(DmigMatrix {
                name,
                matrix: header(card, path)?,
            });
            continue;
        }
        let Some(k) = known else {
            let m =
                format!("a column of {name} before its header: allowed the header (GJ = 0) first");
            return Err(field_error(path, card, 1, m));
        };
        column(card, path, &mut matrices[k].matrix.entries)?;
    }
    if matrices.is_empty() {
        return Err(defect(
            path,
            FORMAT,
            "no DMIG matrix: allowed a DMIG header card and its column cards".into(),
        ));
    }
    Ok(matrices)
}

/// An empty matrix of the storage the header `card` declares (IFO 6 or 1, real TIN).
fn header(card: &Card, path: &Path) -> Result<LabelledMatrix, ImportError> {
    let storage = match text(card, 2) {
        "6" => Storage::Symmetric,
        "1" => Storage::General,
        other => {
            let m = format!(
                "IFO `{other}`: allowed 6 (symmetric) or 1 (square) for a stiffness, mass or \
                 damping matrix"
            );
            return Err(field_error(path, card, 2, m));
        }
    };
    if !matches!(text(card, 3), "1" | "2") {
        let kind = match text(card, 3) {
            "3" | "4" => " (a complex matrix)",
            _ => "",
        };
        let m = format!(
            "TIN `{}`{kind}: allowed 1 or 2 (real; a structure's matrices are real)",
            text(card, 3)
        );
        return Err(field_error(path, card, 3, m));
    }
    Ok(LabelledMatrix {
        entries: Vec::new(),
        storage,
    })
}

/// Appends the entries of the column `card` to `entries`.
fn column(card: &Card, path: &Path, entries: &mut Vec<LabelledEntry>) -> Result<(), ImportError> {
    let error = |k: usize, m: String| field_error(path, card, k, m);
    let label = |k: usize| -> Result<NodeComponent, ImportError> {
        Ok(NodeComponent {
            node: node_label(text(card, k)).map_err(|m| error(k, m))?,
            component: component_label(text(card, k + 1)).map_err(|m| error(k + 1, m))?,
        })
    };
    let col = label(1)?;
    if !text(card, 3).is_empty() {
        let m = format!("`{}`: allowed blank (the field after CJ)", text(card, 3));
        return Err(error(3, m));
    }
    let mut k = 4;
    while k < card.fields.len() {
        if (k..k + 4).all(|f| text(card, f).is_empty()) {
            k += 4;
            continue;
        }
        let row = label(k)?;
        let value = fortran_real(text(card, k + 2)).map_err(|m| error(k + 2, m))?;
        if !text(card, k + 3).is_empty() {
            let m = format!(
                "imaginary part `{}`: allowed blank (a real matrix)",
                text(card, k + 3)
            );
            return Err(error(k + 3, m));
        }
        if entries.len() == entries.capacity() && entries.try_reserve(1).is_err() {
            return Err(error(
                k,
                format!("out of memory after {} entries", entries.len()),
            ));
        }
        entries.push(LabelledEntry {
            row,
            col,
            value,
            line: card.fields[k].line,
        });
        k += 4;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::matrix_market::labelled_dof_map;

    /// `[[2, -1], [-1, 2]]` on node 5's components 1 and 2, `M = I`.
    const SMALL: &str = "$ small fields\n\
DMIG    KAAX           0       6       2       0                       2\n\
DMIG    KAAX           5       1               5       1      2.\n\
DMIG    KAAX           5       2               5       1     -1.       \n\
+              5       2     2.0\n\
DMIG    MAAX           0       6       2\n\
DMIG    MAAX           5       1               5       1     1.0\n\
DMIG    MAAX           5       2               5       2      1.\n";

    const LARGE: &str =
        "DMIG*   KAAX                           0               6               2\n\
DMIG*   KAAX                           5               2\n\
*                      5               1-1.000000000D+00\n\
*                      5               2 2.000000000D+00\n\
DMIG*   KAAX                           5               1\n\
*                      5               1           2.0+0\n";

    const FREE: &str =
        "DMIG,KAAX,0,6,2,0,,,2\nDMIG,KAAX,5,1,,5,1,2.,,5,2,-1.\nDMIG,KAAX,5,2,,5,2,2.\n";

    fn stiffness(text: &str) -> faer::Mat<f64> {
        let all = parse_dmig(text, Path::new("m.pch")).unwrap();
        let k = select_dmig(&all, Part::Stiffness, Path::new("m.pch")).unwrap();
        let map = labelled_dof_map(&[k]).unwrap();
        assert_eq!(map.len(), 2);
        assert_eq!(map.row(5, 2), Some(1));
        k.on_rows(&map, Path::new("m.pch"), FORMAT)
            .unwrap()
            .to_dense()
    }

    #[test]
    fn small_large_and_free_fields_give_the_same_matrix() {
        let expected = faer::mat![[2.0, -1.0], [-1.0, 2.0]];
        for text in [SMALL, LARGE, FREE] {
            assert_eq!(stiffness(text), expected, "{text}");
        }
        let all = parse_dmig(SMALL, Path::new("m.pch")).unwrap();
        assert_eq!(all.len(), 2);
        let m = select_dmig(&all, Part::Mass, Path::new("m.pch")).unwrap();
        assert_eq!(m.entries.len(), 2);
    }

    #[test]
    fn every_defect_names_the_file_the_line_the_field_and_what_is_allowed() {
        let e = |text: &str| match parse_dmig(text, Path::new("m.pch")) {
            Ok(all) => select_dmig(&all, Part::Damping, Path::new("m.pch"))
                .map(|_| String::new())
                .unwrap_or_else(|e| e.to_string()),
            Err(e) => e.to_string(),
        };
        for (text, words) in [
            (
                "DMIG,K,0,2,2\n",
                &["line 1", "field 4", "IFO `2`", "6 (symmetric)"][..],
            ),
            ("DMIG,K,0,6,3\n", &["line 1", "field 5", "TIN `3`", "real"]),
            (
                "$ header\nDMIG,KAAX,0,6,4\n",
                &[
                    "line 2",
                    "field 5",
                    "TIN `4` (a complex matrix)",
                    "allowed 1 or 2",
                ],
            ),
            ("DMIG,K,5,1,,5,1,2.\n", &["line 1", "before its header"]),
            (
                "DMIG,K,0,6,2\nDMIG,K,5,1,,5,7,2.\n",
                &["line 2", "field 7", "component `7`", "1..=6"],
            ),
            (
                "DMIG,K,0,6,2\nDMIG,K,5,1,,5,1,2.\n,5,2,abc\n",
                &["line 3", "field 4", "`abc`", "real number"],
            ),
            (
                "DMIG,K,0,6,2\nDMIG,K,5,1,,5,1,2.,1.\n",
                &["line 2", "field 9", "imaginary part `1.`", "blank"],
            ),
            ("+,1,2\n", &["line 1", "continues no card"]),
            ("$ only\nGRID,1\n", &["no DMIG matrix"]),
            (
                "DMIG,KAAX,0,6,2\nDMIG,MAAX,0,6,2\n",
                &["damping matrix", "KAAX, MAAX", "`B`"],
            ),
            ("DMIG\t,K\n", &["line 1", "tab"]),
        ] {
            let e = e(text);
            for w in words {
                assert!(e.contains(w), "`{w}` not in: {e}");
            }
            assert!(e.starts_with("m.pch: not a valid Nastran DMIG file"), "{e}");
        }
    }
}
