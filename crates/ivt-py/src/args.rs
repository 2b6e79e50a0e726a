//! Count arguments (harmonics, samples, grid points, orders, timer ticks):
//! the bindings take them as `i64` and convert here, so that a negative or
//! too large value raises a `ValueError` naming the argument (pyo3's unsigned
//! extraction raises an `OverflowError` that does not name it). Upper limits
//! of the numerics are checked by the Rust crates, before they allocate.

use pyo3::exceptions::{PyOverflowError, PyValueError};
use pyo3::prelude::*;

/// `v` as the unsigned type `T` (`usize`, `u32`, `u16`), refused by name
/// when it is negative or does not fit.
///
/// # Errors
/// `ValueError`: "argument `name` = v must be >= 0 and fit in T".
pub fn count<T: TryFrom<i64>>(name: &str, v: i64) -> PyResult<T> {
    T::try_from(v).map_err(|_| {
        PyValueError::new_err(format!(
            "argument `{name}` = {v} must be >= 0 and fit in {}",
            std::any::type_name::<T>()
        ))
    })
}

/// `from_py_with` of every count argument: a Python int as `i64`. An int
/// beyond the 64-bit range is a `ValueError` (pyo3 adds the note "while
/// processing '<argument>'"), not an `OverflowError`.
///
/// # Errors
/// `TypeError` for a non-integer, `ValueError` beyond the 64-bit range.
pub fn int64(ob: &Bound<'_, PyAny>) -> PyResult<i64> {
    ob.extract::<i64>().map_err(|e| {
        if e.is_instance_of::<PyOverflowError>(ob.py()) {
            PyValueError::new_err(format!(
                "integer argument {} is outside the 64-bit range",
                ob.repr().map_or_else(|_| "?".into(), |r| r.to_string())
            ))
        } else {
            e
        }
    })
}

/// [`int64`] for an optional argument (None stays None).
///
/// # Errors
/// As [`int64`].
pub fn opt_int64(ob: &Bound<'_, PyAny>) -> PyResult<Option<i64>> {
    if ob.is_none() {
        Ok(None)
    } else {
        int64(ob).map(Some)
    }
}
