//! Conversions between Python objects and the scene's TOML values and the JSON documents.

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};

use crate::errors::{bad_input, bad_type};

/// Deepest nesting of lists in a scene value (a scene key takes a number, a list of them,
/// or a list of such lists): deeper is refused before it can exhaust the stack, which a
/// list that contains itself would otherwise do.
pub const MAX_VALUE_DEPTH: usize = 8;

/// A Python value as a TOML value: bool, int, float, str, and lists or tuples (or numpy
/// arrays, through `tolist()`) of them, nested at most [`MAX_VALUE_DEPTH`] deep. `key`
/// names the value in the `SceneError` (`SceneTypeError` for a wrong type) that refuses it.
pub fn toml_value(value: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
    nested_toml_value(value, key, 0)
}

fn nested_toml_value(value: &Bound<'_, PyAny>, key: &str, depth: usize) -> PyResult<toml::Value> {
    if depth > MAX_VALUE_DEPTH {
        return Err(bad_input(format!(
            "`{key}`: lists nested more than {MAX_VALUE_DEPTH} deep (or a list that contains \
             itself): allowed a number, a string, a bool or a list of them"
        )));
    }
    if value.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(value.extract()?));
    }
    if value.is_instance_of::<PyInt>() {
        return value.extract().map(toml::Value::Integer).map_err(|_| {
            bad_input(format!(
                "`{key}`: the integer {value}: allowed integers of magnitude below 2^63"
            ))
        });
    }
    if value.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(value.extract()?));
    }
    if value.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(value.extract()?));
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items: Vec<Bound<'_, PyAny>> = value.try_iter()?.collect::<PyResult<_>>()?;
        return items
            .iter()
            .map(|item| nested_toml_value(item, key, depth + 1))
            .collect::<PyResult<Vec<_>>>()
            .map(toml::Value::Array);
    }
    // numpy arrays and scalars.
    if value.hasattr("tolist")? {
        let plain = value.call_method0("tolist")?;
        if !plain.is(value) {
            return nested_toml_value(&plain, key, depth + 1);
        }
    }
    Err(bad_type(format!(
        "`{key}`: a value of type {}: allowed a bool, int, float, str or a list of them",
        value.get_type().name()?
    )))
}

/// A TOML value as a Python object.
pub fn python_value<'py>(py: Python<'py>, value: &toml::Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match value {
        toml::Value::String(s) => s.into_pyobject(py)?.into_any(),
        toml::Value::Integer(i) => i.into_pyobject(py)?.into_any(),
        toml::Value::Float(f) => f.into_pyobject(py)?.into_any(),
        toml::Value::Boolean(b) => PyBool::new(py, *b).to_owned().into_any(),
        toml::Value::Datetime(d) => d.to_string().into_pyobject(py)?.into_any(),
        toml::Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(python_value(py, item)?)?;
            }
            list.into_any()
        }
        toml::Value::Table(table) => {
            let dict = PyDict::new(py);
            for (k, v) in table {
                dict.set_item(k, python_value(py, v)?)?;
            }
            dict.into_any()
        }
    })
}

/// A JSON document as Python objects (through `json.loads`, so that it is exactly what
/// `json.loads` of the command line's output gives).
pub fn python_json<'py>(py: Python<'py>, doc: &serde_json::Value) -> PyResult<Bound<'py, PyAny>> {
    py.import("json")?.call_method1("loads", (doc.to_string(),))
}
