//! Harwell-Boeing matrix files (Duff, Grimes and Lewis, 1992), as Ansys' `HBMAT` writes
//! them (`Jobname.matrix`; the rows' nodes and dofs are in its mapping file,
//! [`crate::import::DofMap::read_ansys_mapping`]).
//!
//! Four header lines (a fifth when right-hand sides follow): the title and key; the line
//! counts `TOTCRD PTRCRD INDCRD VALCRD RHSCRD`; the type (`RSA`: real symmetric assembled,
//! the lower triangle stored, or `RUA`: real unsymmetric) with `NROW NCOL NNZERO NELTVL`;
//! the Fortran formats of the pointers, the row indices and the values (`(10I8)`,
//! `(4E20.12)`, `(1P3D25.16)`, ...). Then `NCOL + 1` column pointers (1-based, the first 1,
//! the last `NNZERO + 1`, non-decreasing), `NNZERO` row indices and `NNZERO` values, each
//! in the fixed-width fields of its format (values may touch: `-1.0E+00-2.0E+00`).
//! Right-hand sides are not read. Every defect names the file, the line, what was found
//! and what is allowed.

use std::io::BufRead;
use std::path::Path;

use faer::sparse::Triplet;

use super::labelled::{defect, fortran_real, relabelled};
use super::read::{open_lines, push, quoted, text_lines, Lines, MAX_MATRIX_DIMENSION};
use super::ImportError;
use crate::model::SparseMatrix;

/// The format's name in messages.
const FORMAT: &str = super::MatrixFormat::HarwellBoeing.file_kind();

/// Reads the Harwell-Boeing file `path` (module documentation).
pub fn read_harwell_boeing(path: &Path) -> Result<SparseMatrix, ImportError> {
    parse(&mut open_lines(path).map_err(hb)?, path)
}

/// Parses Harwell-Boeing text (`path` for messages only).
pub fn parse_harwell_boeing(text: &str, path: &Path) -> Result<SparseMatrix, ImportError> {
    parse(&mut text_lines(text), path)
}

/// A line reader's defect as this format's.
fn hb(e: ImportError) -> ImportError {
    relabelled(e, FORMAT)
}

/// A Fortran edit descriptor's fields per line and their width: `(10I8)` is 10 of 8.
#[derive(Debug, Clone, Copy, PartialEq)]
struct FieldFormat {
    per_line: usize,
    width: usize,
}

/// The fields per line and width of a Fortran format such as `(10I8)`, `(4E20.12)`,
/// `(1P,3D25.16)`; `kinds` the descriptor letters allowed.
fn field_format(text: &str, kinds: &str) -> Result<FieldFormat, String> {
    let t = text.trim().to_uppercase().replace(' ', "");
    let bad = || {
        format!(
            "format `{}`: allowed a Fortran format `(nXw)` or `(nXw.d)` with X one of {kinds} \
             (e.g. `(10I8)`, `(4E20.12)`)",
            text.trim()
        )
    };
    let inner = t
        .strip_prefix('(')
        .and_then(|t| t.strip_suffix(')'))
        .ok_or_else(bad)?;
    // A scale factor (`1P` or `1P,`) changes how values are printed, not where they are.
    let inner = match inner.split_once('P') {
        Some((scale, rest)) if scale.chars().all(|c| c.is_ascii_digit() || c == '-') => {
            rest.trim_start_matches(',')
        }
        _ => inner,
    };
    let letter_at = inner
        .find(|c: char| c.is_ascii_alphabetic())
        .ok_or_else(bad)?;
    let (count, rest) = inner.split_at(letter_at);
    if !kinds.contains(&rest[..1]) {
        return Err(bad());
    }
    let per_line = if count.is_empty() {
        1
    } else {
        count.parse::<usize>().map_err(|_| bad())?
    };
    let width = rest[1..].split('.').next().unwrap_or("");
    let width = width.parse::<usize>().map_err(|_| bad())?;
    if per_line == 0 || width == 0 || per_line > 1000 || width > 100 {
        return Err(bad());
    }
    Ok(FieldFormat { per_line, width })
}

/// The header: the shape and the formats.
#[derive(Debug, Clone, Copy)]
struct Header {
    rows: usize,
    cols: usize,
    nonzeros: usize,
    symmetric: bool,
    pointers: FieldFormat,
    indices: FieldFormat,
    values: FieldFormat,
}

/// The next line of the header, or the named defect at the end of the file.
fn header_line<R: BufRead>(
    lines: &mut Lines<R>,
    path: &Path,
    what: &str,
) -> Result<String, ImportError> {
    lines.next(path).map_err(hb)?.ok_or_else(|| {
        defect(
            path,
            FORMAT,
            format!("the file ends before its {what} line: allowed the four header lines"),
        )
    })
}

/// The integers of a header line (blank-separated).
fn integers(line: &str, count: usize, names: &str) -> Result<Vec<usize>, String> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let bad = || {
        format!(
            "{}: allowed `{names}` ({count} integers >= 0)",
            quoted(line)
        )
    };
    if words.len() < count {
        return Err(bad());
    }
    words[..count]
        .iter()
        .map(|w| w.parse::<usize>().map_err(|_| bad()))
        .collect()
}

fn header<R: BufRead>(lines: &mut Lines<R>, path: &Path) -> Result<Header, ImportError> {
    let error = |lines: &Lines<R>, m: String| hb(lines.error(path, m));
    header_line(lines, path, "title")?;
    let counts = header_line(lines, path, "line count")?;
    let counts =
        integers(&counts, 5, "TOTCRD PTRCRD INDCRD VALCRD RHSCRD").map_err(|m| error(lines, m))?;
    let shape = header_line(lines, path, "type")?;
    let kind: String = shape.chars().take(3).collect::<String>().to_uppercase();
    let symmetric = match kind.as_str() {
        "RSA" => true,
        "RUA" => false,
        _ => {
            let m = format!(
                "type `{kind}`: allowed RSA (real symmetric assembled) or RUA (real \
                 unsymmetric assembled)"
            );
            return Err(error(lines, m));
        }
    };
    let rest: String = shape.chars().skip(3).collect();
    let size = integers(&rest, 3, "NROW NCOL NNZERO").map_err(|m| error(lines, m))?;
    let (rows, cols, nonzeros) = (size[0], size[1], size[2]);
    if rows != cols || rows == 0 || rows > MAX_MATRIX_DIMENSION {
        let m =
            format!("a {rows} x {cols} matrix: allowed square, 1 to {MAX_MATRIX_DIMENSION} rows");
        return Err(error(lines, m));
    }
    let n = rows as u128;
    let capacity = if symmetric { n * (n + 1) / 2 } else { n * n };
    if nonzeros as u128 > capacity {
        let m = format!("NNZERO {nonzeros}: allowed at most {capacity} for this size and type");
        return Err(error(lines, m));
    }
    let formats = header_line(lines, path, "format")?;
    let column =
        |from: usize, to: usize| -> String { formats.chars().skip(from).take(to - from).collect() };
    let pointers = field_format(&column(0, 16), "I").map_err(|m| error(lines, m))?;
    let indices = field_format(&column(16, 32), "I").map_err(|m| error(lines, m))?;
    let values = field_format(&column(32, 52), "EDFG").map_err(|m| error(lines, m))?;
    if counts[4] > 0 {
        header_line(lines, path, "right-hand side")?;
    }
    Ok(Header {
        rows,
        cols,
        nonzeros,
        symmetric,
        pointers,
        indices,
        values,
    })
}

/// `count` fields of `format` from the lines that follow, each parsed by `parse`.
fn fields<R: BufRead, T>(
    lines: &mut Lines<R>,
    path: &Path,
    (count, what, format): (usize, &str, FieldFormat),
    parse: impl Fn(&str) -> Result<T, String>,
) -> Result<Vec<T>, ImportError> {
    let mut out = Vec::new();
    out.try_reserve(count.min(1 << 20))
        .map_err(|_| hb(lines.error(path, "out of memory".into())))?;
    while out.len() < count {
        let Some(line) = lines.next(path).map_err(hb)? else {
            return Err(defect(
                path,
                FORMAT,
                format!("the file ends after {} of its {count} {what}", out.len()),
            ));
        };
        let chars: Vec<char> = line.chars().collect();
        let on_line = format.per_line.min(count - out.len());
        for k in 0..on_line {
            let (a, b) = (k * format.width, (k + 1) * format.width);
            let field: String = chars[a.min(chars.len())..b.min(chars.len())]
                .iter()
                .collect();
            let v = parse(&field)
                .map_err(|m| hb(lines.error(path, format!("{what} {}: {m}", out.len() + 1))))?;
            out.push(v);
        }
    }
    Ok(out)
}

fn parse<R: BufRead>(lines: &mut Lines<R>, path: &Path) -> Result<SparseMatrix, ImportError> {
    let h = header(lines, path)?;
    let index = |upper: usize| {
        move |field: &str| match field.trim().parse::<usize>() {
            Ok(k) if (1..=upper).contains(&k) => Ok(k - 1),
            _ => Err(format!("`{}`: allowed 1..={upper}", field.trim())),
        }
    };
    let pointers = (h.cols + 1, "column pointers", h.pointers);
    let pointers = fields(lines, path, pointers, index(h.nonzeros + 1))?;
    let indices = (h.nonzeros, "row indices", h.indices);
    let rows = fields(lines, path, indices, index(h.rows))?;
    let values = (h.nonzeros, "values", h.values);
    let values = fields(lines, path, values, fortran_real)?;
    let bad_pointers = pointers[0] != 0
        || pointers[h.cols] != h.nonzeros
        || pointers.windows(2).any(|w| w[0] > w[1]);
    if bad_pointers {
        return Err(defect(
            path,
            FORMAT,
            format!(
                "column pointers {} ... {}: allowed non-decreasing from 1 to NNZERO + 1 = {}",
                pointers[0] + 1,
                pointers[h.cols] + 1,
                h.nonzeros + 1
            ),
        ));
    }
    let mut triplets = Vec::new();
    for j in 0..h.cols {
        for k in pointers[j]..pointers[j + 1] {
            let (i, v) = (rows[k], values[k]);
            if h.symmetric && i < j {
                return Err(defect(
                    path,
                    FORMAT,
                    format!(
                        "row index {} of column {} (entry {}) is above the diagonal: allowed \
                         the lower triangle (row >= column) in an RSA file",
                        i + 1,
                        j + 1,
                        k + 1
                    ),
                ));
            }
            let error = |m: String| defect(path, FORMAT, m);
            push(&mut triplets, Triplet::new(i, j, v)).map_err(error)?;
            if h.symmetric && i != j {
                push(&mut triplets, Triplet::new(j, i, v)).map_err(error)?;
            }
        }
    }
    let n = h.rows;
    SparseMatrix::try_new_from_triplets(n, n, &triplets).map_err(|e| {
        defect(
            path,
            FORMAT,
            format!("cannot store the {n} x {n} matrix: {e:?}"),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `[[4, -1, 0], [-1, 4, -2], [0, -2, 5]]`, lower triangle.
    const SYMMETRIC: &str = "\
small test matrix                                                       KEY     
             4             1             1             2             0
RSA                        3             3             5             0
(4I5)           (5I3)           (3E12.4)            
    1    3    5    6
  1  2  2  3  3
  0.4000E+01 -0.1000E+01  0.4000E+01
 -0.2000D+01  0.5000+001
";

    #[test]
    fn a_symmetric_file_is_its_lower_triangle_mirrored() {
        let a = parse_harwell_boeing(SYMMETRIC, Path::new("k.matrix")).unwrap();
        let expected = faer::mat![[4.0, -1.0, 0.0], [-1.0, 4.0, -2.0], [0.0, -2.0, 5.0]];
        assert_eq!(a.to_dense(), expected);
        let unsymmetric = SYMMETRIC
            .replace("RSA", "RUA")
            .replace("  1  2  2  3  3", "  1  2  1  2  3");
        let b = parse_harwell_boeing(&unsymmetric, Path::new("k.matrix")).unwrap();
        assert_eq!(b.to_dense()[(0, 1)], 4.0);
        assert_eq!(b.to_dense()[(1, 0)], -1.0);
    }

    #[test]
    fn fortran_formats_give_fields_per_line_and_width() {
        for (text, per_line, width) in [
            ("(10I8)", 10, 8),
            ("(4E20.12)", 4, 20),
            ("(1P,3D25.16)", 3, 25),
            ("(1P4E20.12)", 4, 20),
            (" (I6) ", 1, 6),
        ] {
            let f = field_format(text, "IEDFG").unwrap();
            assert_eq!((f.per_line, f.width), (per_line, width), "{text}");
        }
        assert!(field_format("10I8", "I").is_err());
        assert!(field_format("(4E20.12)", "I").is_err());
    }

    #[test]
    fn every_defect_names_the_file_the_line_and_what_is_allowed() {
        for (edit, words) in [
            (("RSA", "CSA"), &["line 3", "type `CSA`", "RSA"][..]),
            (("(5I3)", "(5X3)"), &["line 4", "format `(5X3)`", "(10I8)"]),
            (
                ("  1  2  2  3  3", "  1  2  2  3  4"),
                &["line 6", "row indices 5", "`4`", "1..=3"],
            ),
            (
                ("  1  2  2  3  3", "  1  2  1  3  3"),
                &["row index 1 of column 2", "lower triangle"],
            ),
            (
                ("    1    3    5    6", "    1    5    3    6"),
                &["column pointers", "non-decreasing"],
            ),
            (
                ("-0.1000E+01", "-0.1000E+0x"),
                &["line 7", "values 2", "real number"],
            ),
            (
                (" -0.2000D+01  0.5000+001\n", ""),
                &["ends after 3 of its 5 values"],
            ),
            (
                (
                    "RSA                        3             3",
                    "RSA                        3             2",
                ),
                &["line 3", "3 x 2", "square"],
            ),
        ] {
            let text = SYMMETRIC.replace(edit.0, edit.1);
            let e = parse_harwell_boeing(&text, Path::new("k.matrix"))
                .unwrap_err()
                .to_string();
            for w in words {
                assert!(e.contains(w), "`{w}` not in: {e}");
            }
            assert!(
                e.starts_with("k.matrix: not a valid Harwell-Boeing file"),
                "{e}"
            );
        }
    }
}
