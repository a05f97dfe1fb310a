//! The Matrix Market reader and writer of imported structures.
//!
//! Reads the subset a finite-element export uses: `%%MatrixMarket matrix` (the banner's
//! words in any case), `coordinate` or `array`, `real` or `integer` (Fortran `D` exponents
//! allowed), `general`, `symmetric` or `skew-symmetric` (one triangle stored, row >=
//! column). The file is read as it goes: only a regular file (a FIFO or a device could
//! block or never end), at most [`MAX_MATRIX_FILE_BYTES`] bytes and lines of at most
//! [`MAX_LINE_BYTES`]; the declared size is checked before anything is allocated for it
//! (at most [`MAX_MATRIX_DIMENSION`] rows and columns, entries that fit the declared size,
//! checked arithmetic); a storage that cannot be allocated is an error, never an abort.
//! Every defect names the line, what was found and what is allowed; entries must be finite
//! with magnitudes of at most [`MAX_ENTRY_MAGNITUDE`].

use std::io::{BufRead, BufReader, Read};
use std::path::Path;

use faer::sparse::Triplet;

use super::ImportError;
use crate::model::SparseMatrix;

/// Largest Matrix Market file read (bytes).
pub const MAX_MATRIX_FILE_BYTES: u64 = 1 << 30;

/// Longest line of a Matrix Market file (bytes); an entry line takes under 80.
pub const MAX_LINE_BYTES: u64 = 1 << 16;

/// Largest number of rows or columns declared (the largest built-in rod has as many dofs).
pub const MAX_MATRIX_DIMENSION: usize = 10_000_000;

pub use crate::import::MAX_ENTRY_MAGNITUDE;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Format {
    Coordinate,
    Array,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Field {
    /// Real numbers (Fortran `D` exponents allowed).
    Real,
    /// Integers.
    Integer,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Symmetry {
    General,
    Symmetric,
    SkewSymmetric,
}

/// Reads the Matrix Market file `path` (module documentation) as a sparse matrix; the
/// zeros of an array file are dropped, duplicate coordinate entries summed.
pub fn read_matrix(path: &Path) -> Result<SparseMatrix, ImportError> {
    parse(&mut open_lines(path)?, path)
}

/// The lines of the regular file `path`, bounded as a Matrix Market file's.
pub(super) fn open_lines(path: &Path) -> Result<Lines<impl BufRead>, ImportError> {
    let io = |source| ImportError::Io {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(ImportError::NotRegular {
            path: path.to_path_buf(),
        });
    }
    let file = std::fs::File::open(path).map_err(io)?;
    // The path may have been replaced between the two looks: check what was opened.
    if !file.metadata().map_err(io)?.is_file() {
        return Err(ImportError::NotRegular {
            path: path.to_path_buf(),
        });
    }
    Ok(Lines::new(BufReader::new(
        file.take(MAX_MATRIX_FILE_BYTES + 1),
    )))
}

/// Parses Matrix Market text (`path` for messages only).
pub fn parse_matrix(text: &str, path: &Path) -> Result<SparseMatrix, ImportError> {
    parse(&mut text_lines(text), path)
}

/// The lines of `text`, bounded as a file's.
pub(super) fn text_lines(text: &str) -> Lines<impl BufRead + '_> {
    Lines::new(BufReader::new(
        text.as_bytes().take(MAX_MATRIX_FILE_BYTES + 1),
    ))
}

/// A line reader that counts lines and bytes and bounds both.
pub(super) struct Lines<R> {
    input: R,
    line: usize,
    read: u64,
    buffer: Vec<u8>,
}

impl<R: BufRead> Lines<R> {
    fn new(input: R) -> Self {
        Self {
            input,
            line: 0,
            read: 0,
            buffer: Vec::new(),
        }
    }

    /// The 1-based number of the line last read.
    pub(super) fn line(&self) -> usize {
        self.line
    }

    /// The next line (without its end), `None` at the end of the file.
    pub(super) fn next(&mut self, path: &Path) -> Result<Option<String>, ImportError> {
        self.buffer.clear();
        let n = (&mut self.input)
            .take(MAX_LINE_BYTES + 1)
            .read_until(b'\n', &mut self.buffer)
            .map_err(|source| ImportError::Io {
                path: path.to_path_buf(),
                source,
            })?;
        if n == 0 {
            return Ok(None);
        }
        self.line += 1;
        self.read += n as u64;
        if self.read > MAX_MATRIX_FILE_BYTES {
            return Err(ImportError::TooLarge {
                path: path.to_path_buf(),
                limit: MAX_MATRIX_FILE_BYTES,
            });
        }
        if n as u64 > MAX_LINE_BYTES {
            return Err(self.error(
                path,
                format!("longer than {MAX_LINE_BYTES} bytes: allowed one entry per line"),
            ));
        }
        let text = std::str::from_utf8(&self.buffer)
            .map_err(|_| self.error(path, "not text (invalid UTF-8)".into()))?;
        Ok(Some(text.trim_end_matches(['\n', '\r']).to_string()))
    }

    /// A defect of the current line.
    pub(super) fn error(&self, path: &Path, message: String) -> ImportError {
        ImportError::MatrixMarket {
            path: path.to_path_buf(),
            message: format!("line {}: {message}", self.line),
        }
    }

    /// The next line that is neither a comment nor blank.
    fn next_data(&mut self, path: &Path) -> Result<Option<String>, ImportError> {
        while let Some(line) = self.next(path)? {
            let t = line.trim();
            if !(t.is_empty() || t.starts_with('%')) {
                return Ok(Some(line));
            }
        }
        Ok(None)
    }
}

/// The line quoted for a message (control characters escaped, long lines cut).
pub(super) fn quoted(line: &str) -> String {
    let t: String = line.trim().chars().take(60).collect();
    let cut = if line.trim().chars().count() > 60 {
        "..."
    } else {
        ""
    };
    format!("`{}{cut}`", t.escape_default())
}

fn header(line: &str) -> Result<(Format, Field, Symmetry), String> {
    let words: Vec<String> = line.split_whitespace().map(str::to_lowercase).collect();
    let allowed = "allowed `%%MatrixMarket matrix coordinate|array real|integer \
                   general|symmetric|skew-symmetric`";
    if words.first().map(String::as_str) != Some("%%matrixmarket") {
        return Err(format!(
            "{} is not a Matrix Market banner: {allowed}",
            quoted(line)
        ));
    }
    if words.len() != 5 {
        return Err(format!(
            "the banner {} has {} words: {allowed}",
            quoted(line),
            words.len()
        ));
    }
    let word = |i: usize| words[i].as_str();
    if word(1) != "matrix" {
        return Err(format!("object `{}`: {allowed}", word(1)));
    }
    let format = match word(2) {
        "coordinate" => Format::Coordinate,
        "array" => Format::Array,
        other => return Err(format!("format `{other}`: {allowed}")),
    };
    let field = match word(3) {
        "real" | "double" => Field::Real,
        "integer" => Field::Integer,
        other => {
            return Err(format!(
                "field `{other}`: {allowed} (a structure needs the values of its entries)"
            ))
        }
    };
    let symmetry = match word(4) {
        "general" => Symmetry::General,
        "symmetric" => Symmetry::Symmetric,
        "skew-symmetric" => Symmetry::SkewSymmetric,
        other => return Err(format!("symmetry `{other}`: {allowed}")),
    };
    Ok((format, field, symmetry))
}

/// A count of the size line: a non-negative integer.
fn count(word: &str, what: &str) -> Result<usize, String> {
    word.parse::<usize>()
        .map_err(|_| format!("{what} `{word}`: allowed a non-negative integer"))
}

/// A value of the field `field`: finite, magnitude at most [`MAX_ENTRY_MAGNITUDE`].
pub(super) fn value(word: &str, field: Field) -> Result<f64, String> {
    let v = match field {
        Field::Integer => word
            .parse::<i64>()
            .map(|v| v as f64)
            .map_err(|_| format!("value `{word}`: allowed an integer (the field is `integer`)"))?,
        Field::Real => word
            .replace(['D', 'd'], "e")
            .parse::<f64>()
            .map_err(|_| format!("value `{word}`: allowed a real number"))?,
    };
    if !v.is_finite() || v.abs() > MAX_ENTRY_MAGNITUDE {
        return Err(format!(
            "value `{word}` = {v:e}: allowed finite numbers of magnitude at most \
             {MAX_ENTRY_MAGNITUDE:e}"
        ));
    }
    Ok(v)
}

/// Appends to `v` without aborting when memory runs out.
pub(super) fn push(
    v: &mut Vec<Triplet<usize, usize, f64>>,
    t: Triplet<usize, usize, f64>,
) -> Result<(), String> {
    if v.len() == v.capacity() {
        v.try_reserve(1)
            .map_err(|_| format!("out of memory after {} entries", v.len()))?;
    }
    v.push(t);
    Ok(())
}

/// The declared shape of a file: what the banner says and the size line gives.
#[derive(Debug, Clone, Copy)]
struct Shape {
    format: Format,
    field: Field,
    symmetry: Symmetry,
    rows: usize,
    cols: usize,
    /// Values the file declares (coordinate) or holds (array).
    declared: usize,
}

/// Parses a file: its banner, its size line and its entries.
fn parse<R: BufRead>(lines: &mut Lines<R>, path: &Path) -> Result<SparseMatrix, ImportError> {
    let first = lines.next(path)?.ok_or_else(|| ImportError::MatrixMarket {
        path: path.to_path_buf(),
        message: "empty file: allowed a Matrix Market file (first line `%%MatrixMarket ...`)"
            .into(),
    })?;
    let (format, field, symmetry) = header(&first).map_err(|m| lines.error(path, m))?;
    let shape = size_line(lines, path, format, field, symmetry)?;
    let triplets = entries(lines, path, &shape)?;
    let (rows, cols) = (shape.rows, shape.cols);
    SparseMatrix::try_new_from_triplets(rows, cols, &triplets).map_err(|e| {
        ImportError::MatrixMarket {
            path: path.to_path_buf(),
            message: format!("cannot store the {rows} x {cols} matrix: {e:?}"),
        }
    })
}

/// The size line after the banner: `rows columns entries` (coordinate) or `rows columns`
/// (array), checked against the limits before anything is allocated.
fn size_line<R: BufRead>(
    lines: &mut Lines<R>,
    path: &Path,
    format: Format,
    field: Field,
    symmetry: Symmetry,
) -> Result<Shape, ImportError> {
    let size_line = lines.next_data(path)?.ok_or_else(|| {
        lines.error(
            path,
            "the file ends before its size line (`rows columns entries`)".into(),
        )
    })?;
    let words: Vec<&str> = size_line.split_whitespace().collect();
    let expected_words = if format == Format::Coordinate { 3 } else { 2 };
    if words.len() != expected_words {
        let shape = if format == Format::Coordinate {
            "`rows columns entries`"
        } else {
            "`rows columns`"
        };
        return Err(lines.error(
            path,
            format!("size line {}: allowed {shape}", quoted(&size_line)),
        ));
    }
    let rows = count(words[0], "rows").map_err(|m| lines.error(path, m))?;
    let cols = count(words[1], "columns").map_err(|m| lines.error(path, m))?;
    for (what, n) in [("rows", rows), ("columns", cols)] {
        if n > MAX_MATRIX_DIMENSION {
            return Err(lines.error(
                path,
                format!("{n} {what}: allowed at most {MAX_MATRIX_DIMENSION}"),
            ));
        }
    }
    if symmetry != Symmetry::General && rows != cols {
        return Err(lines.error(
            path,
            format!("a {rows} x {cols} matrix declared symmetric: allowed square"),
        ));
    }
    // Entries stored: at most rows x cols (or the triangle), checked in u128.
    let capacity = match symmetry {
        Symmetry::General => rows as u128 * cols as u128,
        _ => rows as u128 * (rows as u128 + 1) / 2,
    };
    let declared = match format {
        Format::Coordinate => {
            let n = count(words[2], "entries").map_err(|m| lines.error(path, m))?;
            if n as u128 > capacity {
                return Err(lines.error(
                    path,
                    format!(
                        "{n} entries declared for a {rows} x {cols} matrix: allowed at most \
                         {capacity}"
                    ),
                ));
            }
            n
        }
        Format::Array => {
            // Each value takes at least two bytes of the file.
            if capacity > u128::from(MAX_MATRIX_FILE_BYTES) / 2 {
                return Err(lines.error(
                    path,
                    format!(
                        "a dense {rows} x {cols} array has {capacity} values, more than a file \
                         of at most {MAX_MATRIX_FILE_BYTES} bytes holds: allowed the \
                         coordinate format for large matrices"
                    ),
                ));
            }
            capacity as usize
        }
    };
    Ok(Shape {
        format,
        field,
        symmetry,
        rows,
        cols,
        declared,
    })
}

/// The entries after the size line as triplets: exactly `shape.declared` values, a
/// symmetric file's lower triangle mirrored, an array's zeros dropped.
fn entries<R: BufRead>(
    lines: &mut Lines<R>,
    path: &Path,
    shape: &Shape,
) -> Result<Vec<Triplet<usize, usize, f64>>, ImportError> {
    let (declared, symmetry, format) = (shape.declared, shape.symmetry, shape.format);
    let mut triplets = Vec::new();
    triplets
        .try_reserve(declared.min(1 << 20))
        .map_err(|_| lines.error(path, "out of memory".into()))?;
    let mut stored = 0usize;
    while let Some(line) = lines.next_data(path)? {
        if stored == declared {
            return Err(lines.error(
                path,
                format!(
                    "{}: more entries than the {declared} declared",
                    quoted(&line)
                ),
            ));
        }
        let (i, j, v) = entry(&line, shape, stored).map_err(|m| lines.error(path, m))?;
        stored += 1;
        // A dense array's zeros are not entries; a coordinate file's stored zeros are kept
        // (its pattern reads back as written).
        if v == 0.0 && format == Format::Array {
            continue;
        }
        push(&mut triplets, Triplet::new(i, j, v)).map_err(|m| lines.error(path, m))?;
        let mirrored = match symmetry {
            _ if i == j => None,
            Symmetry::General => None,
            Symmetry::Symmetric => Some(v),
            Symmetry::SkewSymmetric => Some(-v),
        };
        if let Some(w) = mirrored {
            push(&mut triplets, Triplet::new(j, i, w)).map_err(|m| lines.error(path, m))?;
        }
    }
    if stored < declared {
        return Err(lines.error(
            path,
            format!("the file ends after {stored} of the {declared} entries it declares"),
        ));
    }
    Ok(triplets)
}

/// The `stored`-th entry of the file, on the data line `line`: its 0-based row, column and
/// value, checked against the shape (in range, in the stored triangle, a skew diagonal 0).
fn entry(line: &str, shape: &Shape, stored: usize) -> Result<(usize, usize, f64), String> {
    let words: Vec<&str> = line.split_whitespace().collect();
    let at = |i: usize, j: usize, m: String| format!("entry ({}, {}): {m}", i + 1, j + 1);
    let (i, j, v) = match shape.format {
        Format::Coordinate => {
            if words.len() != 3 {
                return Err(format!(
                    "{} is not an entry of this header's format: allowed `row column value`",
                    quoted(line)
                ));
            }
            let index = |word: &str, what: &str, n: usize| -> Result<usize, String> {
                match word.parse::<usize>() {
                    Ok(k) if (1..=n).contains(&k) => Ok(k - 1),
                    _ => Err(format!(
                        "{}: {what} index `{word}`: allowed 1..={n} (1-based)",
                        quoted(line)
                    )),
                }
            };
            let i = index(words[0], "row", shape.rows)?;
            let j = index(words[1], "column", shape.cols)?;
            let v = value(words[2], shape.field).map_err(|m| at(i, j, m))?;
            (i, j, v)
        }
        Format::Array => {
            if words.len() != 1 {
                return Err(format!(
                    "{} is not an entry of this header's format: allowed one value per line",
                    quoted(line)
                ));
            }
            let (i, j) = array_position(stored, shape.rows, shape.symmetry);
            let v = value(words[0], shape.field).map_err(|m| at(i, j, m))?;
            (i, j, v)
        }
    };
    if shape.symmetry != Symmetry::General && i < j {
        return Err(format!(
            "entry ({}, {}) above the diagonal: a symmetric file stores the lower triangle (row \
             >= column)",
            i + 1,
            j + 1
        ));
    }
    if shape.symmetry == Symmetry::SkewSymmetric && i == j && v != 0.0 {
        return Err(format!(
            "diagonal entry ({0}, {0}) = {v:e} of a skew-symmetric matrix: allowed 0",
            i + 1
        ));
    }
    Ok((i, j, v))
}

/// Row and column (0-based) of the `k`-th value of an array file: column-major, the lower
/// triangle only when symmetric.
fn array_position(k: usize, rows: usize, symmetry: Symmetry) -> (usize, usize) {
    if symmetry == Symmetry::General {
        return (k % rows.max(1), k / rows.max(1));
    }
    // Column j holds rows - j values (j..rows).
    let (mut j, mut first) = (0, 0);
    while k >= first + (rows - j) {
        first += rows - j;
        j += 1;
    }
    (j + (k - first), j)
}

/// The standard banner line of the files written here.
const BANNER: &str = "%%MatrixMarket matrix coordinate real general";

/// A sparse matrix as Matrix Market text (coordinate, real, general; every stored entry,
/// values in Rust's shortest round-trip notation, so reading it back is exact).
pub fn matrix_market_text(a: &SparseMatrix) -> String {
    use std::fmt::Write;
    let r = a.as_ref();
    let mut t = format!("{BANNER}\n{} {} {}\n", a.nrows(), a.ncols(), a.val().len());
    for j in 0..a.ncols() {
        for (i, &v) in r.row_idx_of_col(j).zip(r.val_of_col(j)) {
            let _ = writeln!(t, "{} {} {v:e}", i + 1, j + 1);
        }
    }
    t
}

/// A vector as an `n x 1` Matrix Market matrix (its nonzero entries).
pub fn vector_market_text(v: &[f64]) -> String {
    use std::fmt::Write;
    let nonzero = v.iter().filter(|x| **x != 0.0).count();
    let mut t = format!("{BANNER}\n{} 1 {nonzero}\n", v.len());
    for (i, &x) in v.iter().enumerate() {
        if x != 0.0 {
            let _ = writeln!(t, "{} 1 {x:e}", i + 1);
        }
    }
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error(text: &str) -> String {
        parse_matrix(text, Path::new("K.mtx"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn every_defect_names_the_line_what_was_found_and_what_is_allowed() {
        let c = "%%MatrixMarket matrix coordinate real general\n";
        for (text, words) in [
            ("", &["empty file"][..]),
            ("%%matrix market\n", &["line 1", "banner"]),
            (
                "%%MatrixMarket matrix coordinate pattern general\n2 2 1\n1 1\n",
                &["line 1", "field `pattern`", "real|integer"],
            ),
            (
                "%%MatrixMarket matrix coordinate complex general\n",
                &["line 1", "`complex`"],
            ),
            (
                "%%MatrixMarket matrix coordinate real hermitian\n",
                &["line 1", "`hermitian`"],
            ),
            (&format!("{c}2 2\n"), &["line 2", "`rows columns entries`"]),
            (
                &format!("{c}1000000000 1000000000 1\n1 1 1\n"),
                &["line 2", "1000000000 rows", "at most 10000000"],
            ),
            (
                &format!("{c}2 2 5\n"),
                &["line 2", "5 entries", "at most 4"],
            ),
            (&format!("{c}-1 2 1\n"), &["line 2", "rows `-1`"]),
            (
                &format!("{c}99999999999999999999 2 1\n"),
                &["line 2", "non-negative integer"],
            ),
            (
                &format!("{c}2 2 1\n0 1 1.0\n"),
                &["line 3", "row index `0`", "1..=2"],
            ),
            (
                &format!("{c}2 2 1\n1 3 1.0\n"),
                &["line 3", "column index `3`", "1..=2"],
            ),
            (
                &format!("{c}2 2 1\n1 1 x\n"),
                &["line 3", "value `x`", "real number"],
            ),
            (
                &format!("{c}2 2 1\n1 1 inf\n"),
                &["line 3", "entry (1, 1)", "finite"],
            ),
            (
                &format!("{c}2 2 1\n1 1 1e300\n"),
                &["line 3", "1e300", "at most 1e100"],
            ),
            (
                &format!("{c}2 2 1\n1 1\n"),
                &["line 3", "`1 1`", "row column value"],
            ),
            (
                &format!("{c}2 2 1\n1 1 1\n2 2 1\n"),
                &["line 4", "more entries than the 1"],
            ),
            (
                &format!("{c}2 2 3\n1 1 1\n"),
                &["line 3", "after 1 of the 3"],
            ),
            (
                "%%MatrixMarket matrix coordinate integer general\n1 1 1\n1 1 1.5\n",
                &["line 3", "`1.5`", "integer"],
            ),
            (
                "%%MatrixMarket matrix coordinate real symmetric\n2 2 1\n1 2 1\n",
                &["line 3", "(1, 2)", "lower triangle"],
            ),
            (
                "%%MatrixMarket matrix array real general\n100000 100000\n",
                &["line 2", "coordinate format"],
            ),
        ] {
            let e = error(text);
            for w in words {
                assert!(e.contains(w), "`{w}` not in: {e}");
            }
            assert!(e.starts_with("K.mtx: "), "{e}");
        }
    }

    #[test]
    fn coordinate_array_symmetric_and_integer_files_give_the_same_matrix() {
        // [[2, -1, 0], [-1, 2, -1], [0, -1, 1]]
        let full = [[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]];
        let texts = [
            "%%MatrixMarket matrix coordinate real symmetric\n% c\n\n3 3 5\n1 1 2\n2 1 -1\n2 2 2\n3 2 -1\n3 3 1\n",
            "%%matrixmarket MATRIX Coordinate Integer General\n3 3 7\n1 1 2\n2 1 -1\n1 2 -1\n2 2 2\n3 2 -1\n2 3 -1\n3 3 1\n",
            "%%MatrixMarket matrix array real general\n3 3\n2\n-1\n0\n-1\n2\n-1\n0\n-1\n1.0D0\n",
            "%%MatrixMarket matrix array real symmetric\n3 3\n2\n-1\n0\n2\n-1\n1\n",
        ];
        for text in texts {
            let a = parse_matrix(text, Path::new("K.mtx")).unwrap();
            for (i, row) in full.iter().enumerate() {
                for (j, &v) in row.iter().enumerate() {
                    let got = a
                        .as_ref()
                        .row_idx_of_col(j)
                        .zip(a.as_ref().val_of_col(j))
                        .find(|(r, _)| *r == i)
                        .map_or(0.0, |(_, v)| *v);
                    assert_eq!(got, v, "({i}, {j}) of {text}");
                }
            }
        }
        let skew = "%%MatrixMarket matrix coordinate real skew-symmetric\n2 2 1\n2 1 3\n";
        let a = parse_matrix(skew, Path::new("D.mtx")).unwrap();
        assert_eq!(a.val().len(), 2);
    }

    #[test]
    fn written_text_has_the_standard_banner_and_reads_back_bit_for_bit() {
        let values = [0.1, -1.0 / 3.0, 1e-300, 7.0];
        let triplets: Vec<_> = values
            .iter()
            .enumerate()
            .map(|(k, &v)| Triplet::new(k, (k + 1) % 4, v))
            .collect();
        let a = SparseMatrix::try_new_from_triplets(4, 4, &triplets).unwrap();
        let text = matrix_market_text(&a);
        assert!(text.starts_with("%%MatrixMarket matrix coordinate real general\n"));
        let b = parse_matrix(&text, Path::new("a.mtx")).unwrap();
        assert_eq!(a.val(), b.val());
        let v = vector_market_text(&[0.0, 2.5, 0.0]);
        assert_eq!(
            v,
            "%%MatrixMarket matrix coordinate real general\n3 1 1\n2 1 2.5e0\n"
        );
    }
}
