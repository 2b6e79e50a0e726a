//! Elementwise application of scalar Rust functions to numpy arguments.
//!
//! Every numeric argument may be a Python number, a numpy scalar or any
//! array-like of floats; the arguments broadcast against each other by numpy's
//! rules. The result is a Python `float` when every argument is 0-dimensional,
//! else a new `float64` array of the broadcast shape. Inputs must be finite: a
//! NaN or infinity raises `ValueError` naming the argument and the flat index,
//! as does an error of the Rust function (its message is kept).

use numpy::ndarray::{ArrayD, ArrayViewD, IxDyn};
use numpy::{AllowTypeChange, IntoPyArray, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyFloat;
use std::fmt::Display;

/// A named numeric argument, converted to a read-only float64 array.
struct Input<'py> {
    name: &'static str,
    array: PyArrayLikeDyn<'py, f64, AllowTypeChange>,
}

/// Convert one argument; conversion failures name the argument and keep the
/// exception class numpy chose (`ValueError` for unparsable strings, else
/// `TypeError`).
fn extract<'py>(name: &'static str, ob: &Bound<'py, PyAny>) -> PyResult<Input<'py>> {
    match ob.extract::<PyArrayLikeDyn<'py, f64, AllowTypeChange>>() {
        Ok(like) => Ok(Input { name, array: like }),
        Err(e) => {
            let py = ob.py();
            let msg = format!("argument `{name}` must be a float or array of floats: {e}");
            if e.is_instance_of::<PyValueError>(py) {
                Err(PyValueError::new_err(msg))
            } else {
                Err(PyTypeError::new_err(msg))
            }
        }
    }
}

/// numpy's broadcasting rule over the shapes of `inputs`.
fn broadcast_shape(inputs: &[Input<'_>]) -> PyResult<Vec<usize>> {
    let ndim = inputs
        .iter()
        .map(|i| i.array.shape().len())
        .max()
        .unwrap_or(0);
    let mut shape = vec![1usize; ndim];
    for input in inputs {
        let s = input.array.shape();
        let offset = ndim - s.len();
        for (cur, &d) in shape.iter_mut().skip(offset).zip(s) {
            if *cur == 1 {
                *cur = d;
            } else if d != 1 && d != *cur {
                let shapes: Vec<String> = inputs
                    .iter()
                    .map(|i| format!("`{}` {:?}", i.name, i.array.shape()))
                    .collect();
                return Err(PyValueError::new_err(format!(
                    "arguments cannot be broadcast together: {}",
                    shapes.join(", ")
                )));
            }
        }
    }
    Ok(shape)
}

/// Apply `f` elementwise over the broadcast of the `N` named arguments and
/// return its `M` outputs (floats or arrays, see the module docs).
///
/// # Errors
/// `TypeError`/`ValueError` for arguments that are not numeric, do not
/// broadcast, or are not finite; `ValueError` with the Rust message when `f`
/// fails at some element.
pub fn map<'py, const N: usize, const M: usize, E: Display>(
    py: Python<'py>,
    args: [(&'static str, &Bound<'py, PyAny>); N],
    f: impl Fn([f64; N]) -> Result<[f64; M], E>,
) -> PyResult<[Bound<'py, PyAny>; M]> {
    let inputs = args
        .iter()
        .map(|(name, ob)| extract(name, ob))
        .collect::<PyResult<Vec<_>>>()?;
    let shape = broadcast_shape(&inputs)?;
    let views: Vec<ArrayViewD<'_, f64>> = inputs.iter().map(|i| i.array.as_array()).collect();
    let dim = IxDyn(&shape);
    let broadcast: Vec<ArrayViewD<'_, f64>> = views
        .iter()
        .map(|v| {
            v.broadcast(dim.clone())
                .ok_or_else(|| PyValueError::new_err("internal: broadcast failed"))
        })
        .collect::<PyResult<_>>()?;
    let len: usize = shape.iter().product();
    let mut iters: Vec<_> = broadcast.iter().map(|v| v.iter()).collect();
    let mut outputs: [Vec<f64>; M] = std::array::from_fn(|_| Vec::with_capacity(len));
    for index in 0..len {
        let mut x = [0.0; N];
        for ((it, input), xj) in iters.iter_mut().zip(&inputs).zip(&mut x) {
            let Some(&v) = it.next() else {
                return Err(PyValueError::new_err("internal: short broadcast iterator"));
            };
            if !v.is_finite() {
                return Err(PyValueError::new_err(format!(
                    "argument `{}` is not finite ({v}){}",
                    input.name,
                    at_index(&shape, index)
                )));
            }
            *xj = v;
        }
        let y =
            f(x).map_err(|e| PyValueError::new_err(format!("{e}{}", at_index(&shape, index))))?;
        for (out, v) in outputs.iter_mut().zip(y) {
            out.push(v);
        }
    }
    let scalar = shape.is_empty();
    let mut result = Vec::with_capacity(M);
    for out in outputs {
        let ob = if scalar {
            PyFloat::new(py, out.first().copied().unwrap_or(f64::NAN)).into_any()
        } else {
            ArrayD::from_shape_vec(dim.clone(), out)
                .map_err(|e| PyValueError::new_err(format!("internal: {e}")))?
                .into_pyarray(py)
                .into_any()
        };
        result.push(ob);
    }
    result
        .try_into()
        .map_err(|_| PyValueError::new_err("internal: output count"))
}

/// " at flat index k" for array arguments, nothing for scalars.
fn at_index(shape: &[usize], index: usize) -> String {
    if shape.is_empty() {
        String::new()
    } else {
        format!(" at flat index {index}")
    }
}

/// [`map`] for a function that cannot fail and has one output.
///
/// # Errors
/// As [`map`] for the arguments.
pub fn map1<'py, const N: usize>(
    py: Python<'py>,
    args: [(&'static str, &Bound<'py, PyAny>); N],
    f: impl Fn([f64; N]) -> f64,
) -> PyResult<Bound<'py, PyAny>> {
    let [y] = map(py, args, |x| Ok::<_, std::convert::Infallible>([f(x)]))?;
    Ok(y)
}

/// [`map`] for a function that cannot fail and returns a pair (the speed
/// pairs of Eq. 1–4 and 44–46): a tuple of two arrays, two floats for scalars.
///
/// # Errors
/// As [`map`] for the arguments.
pub fn map2<'py, const N: usize>(
    py: Python<'py>,
    args: [(&'static str, &Bound<'py, PyAny>); N],
    f: impl Fn([f64; N]) -> (f64, f64),
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let [a, b] = map(py, args, |x| {
        let (a, b) = f(x);
        Ok::<_, std::convert::Infallible>([a, b])
    })?;
    Ok((a, b))
}
