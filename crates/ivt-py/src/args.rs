//! Integer arguments (harmonics, samples, grid points, orders, timer ticks,
//! step offsets): the bindings take them through [`int`] (or [`int64`]) and
//! convert them with [`count`], so that a value outside the Rust type's range
//! raises a `ValueError` that names the argument and the range, where pyo3's
//! own conversion raises an `OverflowError` naming neither. Upper limits of
//! the numerics are checked by the Rust crates, before they allocate.
//! Float arguments that set a physical quantity are checked through its key
//! in [`ivt_kin::params`] ([`check_arg`]).

use ivt_kin::params::{check_as, Boundary};
use pyo3::exceptions::{PyOverflowError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyBool;

/// Check float argument `name` against key `key` of the one description of
/// user-settable numbers ([`ivt_kin::params`]; the pair must be one of its
/// `ALIASES`): the text after the name is the scene's and the CLI's for the
/// same quantity.
///
/// # Errors
/// `ValueError`: "argument `name` = 1e300 mm/rad does not fit the
/// controller's f32 …" or "… is outside [lo, hi] unit", the value as typed.
pub fn check_arg(name: &'static str, key: &str, value: f64) -> PyResult<()> {
    check_as(Boundary::Python, name, key, value)
        .map_err(|refused| PyValueError::new_err(format!("argument `{name}` {refused}")))
}

/// An integer type an argument converts to, with its range.
pub trait IntRange: TryFrom<i128> {
    /// Smallest value.
    const MIN: i128;
    /// Largest value.
    const MAX: i128;
}

macro_rules! int_range {
    ($($t:ty),*) => {
        $(impl IntRange for $t {
            const MIN: i128 = <$t>::MIN as i128;
            const MAX: i128 = <$t>::MAX as i128;
        })*
    };
}
int_range!(u8, u16, u32, u64, usize, i32, i64);

/// `v` as the integer type `T` (`usize`, `u32`, `u16`, `i32`, ...), refused
/// by name when it lies outside `T`'s range.
///
/// # Errors
/// `ValueError`: "argument `name` = v must be >= MIN and <= MAX".
pub fn count<T: IntRange>(name: &str, v: impl Into<i128>) -> PyResult<T> {
    let v = v.into();
    T::try_from(v).map_err(|_| {
        PyValueError::new_err(format!(
            "argument `{name}` = {v} must be >= {} and <= {}",
            T::MIN,
            T::MAX
        ))
    })
}

/// `from_py_with` of integer arguments: a Python int (not a bool, not a
/// float) as `i128`, so that [`count`] sees 2⁶³, 2⁶⁴ and negative values and
/// refuses them by name. pyo3 prefixes a `TypeError` with the argument's name.
///
/// # Errors
/// `TypeError` for a non-integer or a bool, `ValueError` beyond ±2¹²⁷ (pyo3
/// adds the note "while processing '<argument>'").
pub fn int(ob: &Bound<'_, PyAny>) -> PyResult<i128> {
    if ob.is_instance_of::<PyBool>() {
        return Err(PyTypeError::new_err("must be an integer, not bool"));
    }
    ob.extract::<i128>().map_err(|e| {
        if e.is_instance_of::<PyOverflowError>(ob.py()) {
            PyValueError::new_err(format!(
                "integer argument {} is out of range",
                ob.repr().map_or_else(|_| "?".into(), |r| r.to_string())
            ))
        } else {
            e
        }
    })
}

/// [`int`] for an optional argument (None stays None).
///
/// # Errors
/// As [`int`].
pub fn opt_int(ob: &Bound<'_, PyAny>) -> PyResult<Option<i128>> {
    if ob.is_none() {
        Ok(None)
    } else {
        int(ob).map(Some)
    }
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

/// [`int`] limited to the 64-bit range, for arguments converted later with
/// [`count`].
///
/// # Errors
/// As [`int`]; `ValueError` beyond the 64-bit range.
pub fn int64(ob: &Bound<'_, PyAny>) -> PyResult<i64> {
    let v = int(ob)?;
    i64::try_from(v).map_err(|_| {
        PyValueError::new_err(format!(
            "integer argument {v} is out of range: must be in [{}, {}]",
            i64::MIN,
            i64::MAX
        ))
    })
}
