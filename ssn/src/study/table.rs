//! The results table of a study: one row per case, made from the case records alone (so a
//! merged sharded run and a whole run give the same table). Columns: `case`, the varied
//! scene keys (a list value, as drawn by `size = N`, becomes `key[0]`,
//! `key[1]`, ...), `converged`, `termination`, `error`, then the quantities of the run
//! kind ([`quantities`]). Wall times are left out, so two runs of one study give equal
//! tables. Written as CSV (numbers in shortest round-trip notation, an empty cell for a
//! missing value) and, with the `parquet` feature, as Parquet (typed columns, nulls).

use serde_json::Value;

use super::RunKind;

/// A cell of the table.
#[derive(Debug, Clone, PartialEq)]
pub enum Cell {
    /// No value (a failed case, a non-finite number).
    Null,
    /// An integer.
    Int(i64),
    /// A number.
    Float(f64),
    /// A truth value.
    Bool(bool),
    /// Text.
    Text(String),
}

impl Cell {
    fn from_json(v: &Value) -> Cell {
        match v {
            Value::Null => Cell::Null,
            Value::Bool(b) => Cell::Bool(*b),
            Value::Number(n) => match n.as_i64() {
                Some(i) => Cell::Int(i),
                None => n.as_f64().map_or(Cell::Null, Cell::Float),
            },
            Value::String(s) => Cell::Text(s.clone()),
            other => Cell::Text(other.to_string()),
        }
    }

    fn float(v: Option<f64>) -> Cell {
        v.filter(|x| x.is_finite()).map_or(Cell::Null, Cell::Float)
    }
}

/// The type of a column, from its cells: integers, numbers (integers and numbers mixed),
/// truth values, or text (anything else).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnType {
    /// 64-bit integers.
    Int,
    /// Doubles.
    Float,
    /// Booleans.
    Bool,
    /// UTF-8 text.
    Text,
}

/// A named column.
#[derive(Debug, Clone, PartialEq)]
pub struct Column {
    /// The header.
    pub name: String,
    /// One cell per row.
    pub cells: Vec<Cell>,
}

impl Column {
    /// The column's type ([`ColumnType`]); a column of nulls only is text (as the `error`
    /// column of a study where every case ran: Parquet readers give None, not NaN).
    pub fn column_type(&self) -> ColumnType {
        let mut kind: Option<ColumnType> = None;
        for c in &self.cells {
            let k = match c {
                Cell::Null => continue,
                Cell::Int(_) => ColumnType::Int,
                Cell::Float(_) => ColumnType::Float,
                Cell::Bool(_) => ColumnType::Bool,
                Cell::Text(_) => ColumnType::Text,
            };
            kind = Some(match (kind, k) {
                (None, k) => k,
                (Some(a), b) if a == b => a,
                (Some(ColumnType::Int), ColumnType::Float)
                | (Some(ColumnType::Float), ColumnType::Int) => ColumnType::Float,
                _ => ColumnType::Text,
            });
        }
        kind.unwrap_or(ColumnType::Text)
    }

    /// The cell of `row` as text: shortest round-trip numbers, `true`/`false`, empty for
    /// null.
    fn text(&self, row: usize) -> String {
        self.cells[row].text()
    }
}

impl Cell {
    /// The cell as text: shortest round-trip numbers, `true`/`false`, empty for null.
    fn text(&self) -> String {
        match self {
            Cell::Null => String::new(),
            Cell::Int(i) => i.to_string(),
            Cell::Float(f) => format!("{f:?}"),
            Cell::Bool(b) => b.to_string(),
            Cell::Text(s) => s.clone(),
        }
    }
}

/// The table of a study (module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Table {
    /// The columns, all of one length.
    pub columns: Vec<Column>,
}

/// The quantities of a run kind: a column name and how it is read from the command line's
/// JSON document of the case.
///
/// - `solve`: `omega_ratio`, `iterations`, `residual_norm`, `tip_min`, `tip_max`,
///   `max_penetration`, `contact_force_mean`, and over the contacts the largest
///   excursion `contact_amplitude_max` (max over contacts of `max(|displacement_min|,
///   |displacement_max|)`), with `contact_amplitude_argmax` the contact (from 0) reaching
///   it;
/// - `sweep`: `points`, `peak_amplitude` and `peak_omega_ratio`, `folds` (their number),
///   `stable_points`, `unstable_points`, `undecided_points`;
/// - `solutions`: `solutions`, `stable_solutions`, `unstable_solutions`,
///   `amplitude_max` and `amplitude_min` (over the solutions, of `max(|tip_min|,
///   |tip_max|)`).
pub fn quantities(kind: RunKind, doc: &Value) -> Vec<(&'static str, Cell)> {
    match kind {
        RunKind::Solve => solve_quantities(doc),
        RunKind::Sweep => sweep_quantities(doc),
        RunKind::Solutions => solutions_quantities(doc),
    }
}

/// The friction points' numbers of a case's document: a solve's `friction` list, a
/// sweep's at its peak (the point of `peak_amplitude`); none for `solutions`.
fn case_friction(kind: RunKind, doc: &Value) -> Vec<Value> {
    let list = match kind {
        RunKind::Solve => &doc["friction"],
        RunKind::Sweep => {
            let amplitude: Vec<f64> = (doc["amplitude"].as_array().into_iter().flatten())
                .map(|v| v.as_f64().unwrap_or(f64::NAN))
                .collect();
            match finite_argmax(&amplitude) {
                Some((peak, _)) => &doc["friction"][peak],
                None => &Value::Null,
            }
        }
        RunKind::Solutions => &Value::Null,
    };
    list.as_array().cloned().unwrap_or_default()
}

/// The columns of the friction points, after the quantities: for friction point `f` (from
/// 0, as the JSON's `point`) `friction{f}_<name>` for each name of
/// [`FrictionSummary::NAMES`] (a solve's values; a sweep's at its peak), as many points as
/// the case with the most has (null where a case has fewer or failed).
fn friction_columns(kind: RunKind, records: &[Value]) -> Vec<Column> {
    use semismooth_contact::contacts::FrictionSummary;
    let lists: Vec<Vec<Value>> = (records.iter())
        .map(|r| case_friction(kind, &r["result"]))
        .collect();
    let count = lists.iter().map(Vec::len).max().unwrap_or(0);
    let mut columns = Vec::with_capacity(count * FrictionSummary::NAMES.len());
    for f in 0..count {
        for name in FrictionSummary::NAMES {
            columns.push(Column {
                name: format!("friction{f}_{name}"),
                cells: (lists.iter())
                    .map(|list| list.get(f).map_or(Cell::Null, |p| num(&p[name])))
                    .collect(),
            });
        }
    }
    columns
}

/// A number of the JSON document as a cell.
fn num(v: &Value) -> Cell {
    Cell::float(v.as_f64())
}

/// An integer of the JSON document as a cell.
fn int(v: &Value) -> Cell {
    v.as_i64().map_or(Cell::Null, Cell::Int)
}

/// The quantities of a `solve` case ([`quantities`]).
fn solve_quantities(doc: &Value) -> Vec<(&'static str, Cell)> {
    let excursions: Vec<f64> = doc["contacts"]
        .as_array()
        .map(|cs| {
            cs.iter()
                .map(|c| {
                    let lo = c["displacement_min"].as_f64().unwrap_or(f64::NAN);
                    let hi = c["displacement_max"].as_f64().unwrap_or(f64::NAN);
                    lo.abs().max(hi.abs())
                })
                .collect()
        })
        .unwrap_or_default();
    let argmax = finite_argmax(&excursions);
    vec![
        ("omega_ratio", num(&doc["omega_ratio"])),
        ("iterations", int(&doc["iterations"])),
        ("residual_norm", num(&doc["residual_norm"])),
        ("tip_min", num(&doc["tip_min"])),
        ("tip_max", num(&doc["tip_max"])),
        ("max_penetration", num(&doc["max_penetration"])),
        ("contact_force_mean", num(&doc["contact_force_mean"])),
        ("contact_amplitude_max", Cell::float(argmax.map(|a| *a.1))),
        (
            "contact_amplitude_argmax",
            argmax.map_or(Cell::Null, |a| Cell::Int(a.0 as i64)),
        ),
    ]
}

/// The quantities of a `sweep` case ([`quantities`]).
fn sweep_quantities(doc: &Value) -> Vec<(&'static str, Cell)> {
    let absent = doc.is_null();
    let amplitude: Vec<f64> = doc["amplitude"]
        .as_array()
        .map(|a| a.iter().map(|v| v.as_f64().unwrap_or(f64::NAN)).collect())
        .unwrap_or_default();
    let peak = finite_argmax(&amplitude);
    let stable = doc["stable"].as_array().cloned().unwrap_or_default();
    let count = |want: &Value| {
        if absent {
            Cell::Null
        } else {
            Cell::Int(stable.iter().filter(|s| *s == want).count() as i64)
        }
    };
    vec![
        ("points", int(&doc["points"])),
        ("peak_amplitude", Cell::float(peak.map(|p| *p.1))),
        (
            "peak_omega_ratio",
            Cell::float(peak.and_then(|p| doc["omega_ratio"][p.0].as_f64())),
        ),
        (
            "folds",
            doc["folds"]
                .as_array()
                .map_or(Cell::Null, |f| Cell::Int(f.len() as i64)),
        ),
        ("stable_points", count(&Value::Bool(true))),
        ("unstable_points", count(&Value::Bool(false))),
        ("undecided_points", count(&Value::Null)),
    ]
}

/// The quantities of a `solutions` case ([`quantities`]).
fn solutions_quantities(doc: &Value) -> Vec<(&'static str, Cell)> {
    let absent = doc.is_null();
    let solutions = doc["solutions"].as_array().cloned().unwrap_or_default();
    let amplitudes: Vec<f64> = solutions
        .iter()
        .map(|s| {
            let lo = s["tip_min"].as_f64().unwrap_or(f64::NAN);
            let hi = s["tip_max"].as_f64().unwrap_or(f64::NAN);
            lo.abs().max(hi.abs())
        })
        .filter(|a| a.is_finite())
        .collect();
    let count = |want: &Value| {
        if absent {
            Cell::Null
        } else {
            Cell::Int(solutions.iter().filter(|s| &s["stable"] == want).count() as i64)
        }
    };
    vec![
        (
            "solutions",
            if absent {
                Cell::Null
            } else {
                Cell::Int(solutions.len() as i64)
            },
        ),
        ("stable_solutions", count(&Value::Bool(true))),
        ("unstable_solutions", count(&Value::Bool(false))),
        (
            "amplitude_max",
            Cell::float(amplitudes.iter().copied().reduce(f64::max)),
        ),
        (
            "amplitude_min",
            Cell::float(amplitudes.iter().copied().reduce(f64::min)),
        ),
    ]
}

impl Table {
    /// The table of `records` (each `{case, values, converged, result | error}`) in their
    /// order, with a column per key of `keys` (list values spread over `key[i]` columns).
    pub fn from_records(kind: RunKind, keys: &[String], records: &[Value]) -> Table {
        let mut columns = vec![Column {
            name: "case".into(),
            cells: records
                .iter()
                .map(|r| Cell::from_json(&r["case"]))
                .collect(),
        }];
        for key in keys {
            let values: Vec<&Value> = records.iter().map(|r| &r["values"][key]).collect();
            let width = values
                .iter()
                .filter_map(|v| v.as_array().map(Vec::len))
                .max();
            match width {
                Some(width) => {
                    for i in 0..width {
                        columns.push(Column {
                            name: format!("{key}[{i}]"),
                            cells: values.iter().map(|v| Cell::from_json(&v[i])).collect(),
                        });
                    }
                }
                None => columns.push(Column {
                    name: key.clone(),
                    cells: values.iter().map(|v| Cell::from_json(v)).collect(),
                }),
            }
        }
        let text = |r: &Value, k: &str| Cell::from_json(&r[k]);
        columns.push(Column {
            name: "converged".into(),
            cells: records.iter().map(|r| text(r, "converged")).collect(),
        });
        columns.push(Column {
            name: "termination".into(),
            cells: records
                .iter()
                .map(|r| match kind {
                    // The solutions document has no termination: its branch's convergence.
                    RunKind::Solutions => Cell::from_json(&r["result"]["branch_converged"]),
                    _ => Cell::from_json(&r["result"]["termination"]),
                })
                .collect(),
        });
        columns.push(Column {
            name: "error".into(),
            cells: records.iter().map(|r| text(r, "error")).collect(),
        });
        let rows: Vec<Vec<(&str, Cell)>> = records
            .iter()
            .map(|r| quantities(kind, &r["result"]))
            .collect();
        let names: Vec<&str> = quantities(kind, &Value::Null)
            .into_iter()
            .map(|(n, _)| n)
            .collect();
        for (j, name) in names.iter().enumerate() {
            columns.push(Column {
                name: (*name).to_string(),
                cells: rows.iter().map(|row| row[j].1.clone()).collect(),
            });
        }
        columns.extend(friction_columns(kind, records));
        Table { columns }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.columns.first().map_or(0, |c| c.cells.len())
    }

    /// The column named `name`.
    pub fn column(&self, name: &str) -> Option<&Column> {
        self.columns.iter().find(|c| c.name == name)
    }

    /// The table as CSV: a header line, one line per row; text with a comma, a quote or a
    /// line break is quoted (RFC 4180).
    pub fn csv(&self) -> String {
        let quote = |s: &str| {
            if s.contains([',', '"', '\n', '\r']) {
                format!("\"{}\"", s.replace('"', "\"\""))
            } else {
                s.to_string()
            }
        };
        let mut out = self
            .columns
            .iter()
            .map(|c| quote(&c.name))
            .collect::<Vec<_>>()
            .join(",");
        out.push('\n');
        for row in 0..self.rows() {
            let cells: Vec<String> = self.columns.iter().map(|c| quote(&c.text(row))).collect();
            out.push_str(&cells.join(","));
            out.push('\n');
        }
        out
    }

    /// The table as a Parquet file (one row group, uncompressed, every column optional:
    /// nulls where a case has no value).
    #[cfg(feature = "parquet")]
    pub fn parquet(&self) -> Result<Vec<u8>, parquet::errors::ParquetError> {
        use parquet::data_type::{BoolType, ByteArray, ByteArrayType, DoubleType, Int64Type};
        use parquet::file::writer::SerializedFileWriter;
        use parquet::schema::types::Type;
        use std::sync::Arc;

        let fields = self
            .columns
            .iter()
            .map(|c| {
                let (physical, logical) = match c.column_type() {
                    ColumnType::Int => (parquet::basic::Type::INT64, None),
                    ColumnType::Float => (parquet::basic::Type::DOUBLE, None),
                    ColumnType::Bool => (parquet::basic::Type::BOOLEAN, None),
                    ColumnType::Text => (
                        parquet::basic::Type::BYTE_ARRAY,
                        Some(parquet::basic::LogicalType::String),
                    ),
                };
                Type::primitive_type_builder(&c.name, physical)
                    .with_repetition(parquet::basic::Repetition::OPTIONAL)
                    .with_logical_type(logical)
                    .build()
                    .map(Arc::new)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let schema = Arc::new(
            Type::group_type_builder("ssn_study")
                .with_fields(fields)
                .build()?,
        );
        let mut bytes = Vec::new();
        let mut writer = SerializedFileWriter::new(&mut bytes, schema, Default::default())?;
        let mut group = writer.next_row_group()?;
        for c in &self.columns {
            let Some(mut column) = group.next_column()? else {
                break;
            };
            match c.column_type() {
                ColumnType::Int => write_column::<Int64Type>(&mut column, c, |cell| match cell {
                    Cell::Int(i) => Some(*i),
                    _ => None,
                })?,
                ColumnType::Float => {
                    write_column::<DoubleType>(&mut column, c, |cell| match cell {
                        Cell::Int(i) => Some(*i as f64),
                        Cell::Float(f) => Some(*f),
                        _ => None,
                    })?
                }
                ColumnType::Bool => write_column::<BoolType>(&mut column, c, |cell| match cell {
                    Cell::Bool(b) => Some(*b),
                    _ => None,
                })?,
                ColumnType::Text => write_column::<ByteArrayType>(&mut column, c, |cell| {
                    (*cell != Cell::Null).then(|| ByteArray::from(cell.text().as_str()))
                })?,
            }
            column.close()?;
        }
        group.close()?;
        writer.close()?;
        Ok(bytes)
    }
}

/// Writes the cells of `c` to `column` as the Parquet type `T`: the values `value` finds
/// in the cells, and a definition level per row (0 for a null cell).
#[cfg(feature = "parquet")]
fn write_column<T: parquet::data_type::DataType>(
    column: &mut parquet::file::writer::SerializedColumnWriter<'_>,
    c: &Column,
    value: impl Fn(&Cell) -> Option<T::T>,
) -> Result<(), parquet::errors::ParquetError> {
    let defined: Vec<i16> = c
        .cells
        .iter()
        .map(|cell| i16::from(*cell != Cell::Null))
        .collect();
    let values: Vec<T::T> = c.cells.iter().filter_map(value).collect();
    column
        .typed::<T>()
        .write_batch(&values, Some(&defined), None)?;
    Ok(())
}

/// The index and value of the largest finite entry of `values` (`None` without one).
fn finite_argmax(values: &[f64]) -> Option<(usize, &f64)> {
    values
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .max_by(|a, b| a.1.total_cmp(b.1))
}
