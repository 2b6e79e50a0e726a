//! Keyword overrides of plain Rust parameter structs (plant, gear geometry):
//! one table of (name, getter, setter) per struct, so that constructors,
//! `params()` dicts and pickling share the names.

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Getter and setter of one `f64` field of `T`, by its Python name.
pub type Field<T> = (&'static str, fn(&T) -> f64, fn(&mut T, f64));

/// The `&[Field<T>]` table of the named `f64` fields of `T` (Python name =
/// Rust field name): `field_table!(T; a, b)`.
macro_rules! field_table {
    ($ty:ty; $($name:ident),* $(,)?) => {
        &[$(
            (
                stringify!($name),
                |p: &$ty| p.$name,
                |p: &mut $ty, v: f64| p.$name = v,
            )
        ),*]
    };
}
pub(crate) use field_table;

/// Set the fields named in `kw` (all must be floats in `fields`); keys that
/// `extra` accepts (returns `Ok(true)`) are handled by it instead.
///
/// # Errors
/// `TypeError` for an unknown name or a non-float value, or `extra`'s error.
pub fn apply<T>(
    what: &str,
    fields: &[Field<T>],
    target: &mut T,
    kw: Option<&Bound<'_, PyDict>>,
    mut extra: impl FnMut(&mut T, &str, &Bound<'_, PyAny>) -> PyResult<bool>,
) -> PyResult<()> {
    let Some(kw) = kw else { return Ok(()) };
    for (key, value) in kw.iter() {
        let key: String = key.extract()?;
        if extra(target, &key, &value)? {
            continue;
        }
        let Some((_, _, set)) = fields.iter().find(|(n, _, _)| *n == key) else {
            let names: Vec<&str> = fields.iter().map(|(n, _, _)| *n).collect();
            return Err(PyTypeError::new_err(format!(
                "unknown {what} parameter `{key}` (known: {})",
                names.join(", ")
            )));
        };
        let v: f64 = value.extract().map_err(|_| {
            PyTypeError::new_err(format!("{what} parameter `{key}` must be a float"))
        })?;
        set(target, v);
    }
    Ok(())
}

/// All fields of `source` as a dict.
///
/// # Errors
/// Only if Python cannot build the dict.
pub fn to_dict<'py, T>(
    py: Python<'py>,
    fields: &[Field<T>],
    source: &T,
) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, get, _) in fields {
        d.set_item(name, get(source))?;
    }
    Ok(d)
}

/// `name=value` for the fields that differ from `reference` (for `__repr__`).
pub fn changed<T>(fields: &[Field<T>], value: &T, reference: &T) -> Vec<String> {
    fields
        .iter()
        .filter(|(_, get, _)| get(value) != get(reference))
        .map(|(n, get, _)| format!("{n}={}", get(value)))
        .collect()
}
