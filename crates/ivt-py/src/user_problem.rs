//! User systems for `ivt.hb`: `M x'' + C x' + K x + g(x, v, θ) = f(θ)` with `g`
//! and `f` Python callables (per sample, or vectorized over all AFT samples).
//! The system is an ivt-hb [`GeneralProblem`]; this module adds only the Python
//! calls and the capture of the first exception a callback raises.

use ivt_hb::problem::{per_sample, Nonlinearity};
use ivt_hb::{GeneralProblem, HbOptions};
use numpy::{IntoPyArray, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use std::sync::{Arc, Mutex};

/// The first exception raised by a callback (the solver then sees NaN).
type ErrorSlot = Arc<Mutex<Option<PyErr>>>;

/// The excitation `f(θ)` of a user system (a Python callable or none).
type PyExcitation = Box<dyn Fn(f64, &mut [f64]) + Send + Sync>;

/// A user system: the ivt-hb general problem with Python `g` and `f`.
pub(crate) type PyProblem = GeneralProblem<PyNonlinearity, PyExcitation>;

/// The Python `g(x, v, theta)`: per sample, or (`vectorized`) once for all
/// samples with (N, n_dof) arrays and a (N,) phase array, returning (N, n_dof).
pub(crate) struct PyNonlinearity {
    g: Py<PyAny>,
    n: usize,
    vectorized: bool,
    error: ErrorSlot,
}

fn record(slot: &ErrorSlot, e: PyErr) {
    if let Ok(mut slot) = slot.lock() {
        if slot.is_none() {
            *slot = Some(e);
        }
    }
}

/// Calls `func(*args)` and writes its `out.len()` floats into `out` (NaN and the
/// exception recorded on error).
fn call_into(
    slot: &ErrorSlot,
    func: &Py<PyAny>,
    args: impl FnOnce(Python<'_>) -> PyResult<Bound<'_, pyo3::types::PyTuple>>,
    out: &mut [f64],
) {
    let n = out.len();
    let r = Python::attach(|py| -> PyResult<()> {
        let res = func.bind(py).call1(args(py)?)?;
        let v: Vec<f64> = if let Ok(x) = res.extract::<f64>() {
            vec![x]
        } else {
            res.extract()?
        };
        if v.len() != n {
            return Err(PyValueError::new_err(format!(
                "callback returned {} values for n_dof = {n}",
                v.len()
            )));
        }
        out.copy_from_slice(&v);
        Ok(())
    });
    if let Err(e) = r {
        record(slot, e);
        out.fill(f64::NAN);
    }
}

impl PyNonlinearity {
    /// One call of a vectorized `g` on `theta.len()` samples (sample-major).
    fn call_vectorized(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        let (n, ns) = (self.n, theta.len());
        let r = Python::attach(|py| -> PyResult<()> {
            let shape = |a: &[f64]| {
                numpy::ndarray::Array2::from_shape_vec((ns, n), a.to_vec())
                    .map(|a| a.into_pyarray(py))
                    .map_err(|e| PyValueError::new_err(e.to_string()))
            };
            let args = (shape(x)?, shape(v)?, theta.to_vec().into_pyarray(py));
            let res = self.g.bind(py).call1(args)?;
            let arr = res
                .extract::<numpy::PyArrayLikeDyn<'_, f64, numpy::AllowTypeChange>>()
                .map_err(|_| {
                    PyTypeError::new_err("vectorized `g` must return an array of floats")
                })?;
            let a = arr.as_array();
            if a.len() != ns * n || (a.ndim() == 2 && a.shape() != [ns, n]) {
                return Err(PyValueError::new_err(format!(
                    "vectorized `g` returned shape {:?}, expected ({ns}, {n})",
                    a.shape()
                )));
            }
            for (o, val) in out.iter_mut().zip(a.iter()) {
                *o = *val;
            }
            Ok(())
        });
        if let Err(e) = r {
            record(&self.error, e);
            out.fill(f64::NAN);
        }
    }
}

impl Nonlinearity for PyNonlinearity {
    fn eval(&self, x: &[f64], v: &[f64], theta: f64, out: &mut [f64]) {
        if self.vectorized {
            self.call_vectorized(x, v, &[theta], out);
            return;
        }
        call_into(
            &self.error,
            &self.g,
            |py| {
                pyo3::types::PyTuple::new(
                    py,
                    [
                        x.to_vec().into_pyarray(py).into_any(),
                        v.to_vec().into_pyarray(py).into_any(),
                        pyo3::types::PyFloat::new(py, theta).into_any(),
                    ],
                )
            },
            out,
        );
    }
    fn eval_samples(&self, x: &[f64], v: &[f64], theta: &[f64], out: &mut [f64]) {
        if self.vectorized {
            self.call_vectorized(x, v, theta, out);
        } else {
            per_sample(self.n, x, v, theta, out, |x, v, th, out| {
                self.eval(x, v, th, out)
            });
        }
    }
}

/// An n×n float64 matrix (array-like) as row-major data.
fn matrix(name: &str, ob: &Bound<'_, PyAny>) -> PyResult<(usize, Vec<f64>)> {
    // A scalar is a 1×1 matrix (single DOF).
    let (n, data) = if let Ok(x) = ob.extract::<f64>() {
        (1, vec![x])
    } else {
        let a = ob
            .extract::<numpy::PyArrayLike2<'_, f64, numpy::AllowTypeChange>>()
            .map_err(|_| {
                PyTypeError::new_err(format!(
                    "argument `{name}` must be a square matrix of floats"
                ))
            })?;
        let n = match a.shape() {
            &[rows, cols] if rows == cols && rows > 0 => rows,
            shape => {
                return Err(PyValueError::new_err(format!(
                    "argument `{name}` must be square and non-empty, got shape {shape:?}"
                )))
            }
        };
        (n, a.as_array().iter().copied().collect())
    };
    if let Some(bad) = data.iter().find(|v| !v.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "argument `{name}` has a non-finite entry ({bad})"
        )));
    }
    Ok((n, data))
}

/// The user system of `solve`, `frc` and `limit_cycle` from its Python arguments.
#[allow(clippy::too_many_arguments)]
pub(crate) fn user_problem(
    m: &Bound<'_, PyAny>,
    c: &Bound<'_, PyAny>,
    k: &Bound<'_, PyAny>,
    g: &Bound<'_, PyAny>,
    f: Option<&Bound<'_, PyAny>>,
    velocity_dependent: bool,
    vectorized: bool,
) -> PyResult<PyProblem> {
    let (nm, m) = matrix("m", m)?;
    let (nc, c) = matrix("c", c)?;
    let (nk, k) = matrix("k", k)?;
    if nm != nc || nm != nk {
        return Err(PyValueError::new_err(format!(
            "`m`, `c`, `k` must have the same size, got {nm}, {nc}, {nk}"
        )));
    }
    if !g.is_callable() {
        return Err(PyTypeError::new_err(
            "argument `g` must be callable g(x, v, theta)",
        ));
    }
    if let Some(f) = f {
        if !f.is_callable() {
            return Err(PyTypeError::new_err(
                "argument `f` must be callable f(theta) or None",
            ));
        }
    }
    let error = ErrorSlot::default();
    let excitation: PyExcitation = match f {
        Some(f) => {
            let (f, slot) = (f.clone().unbind(), Arc::clone(&error));
            Box::new(move |theta, out| {
                call_into(&slot, &f, |py| pyo3::types::PyTuple::new(py, [theta]), out)
            })
        }
        None => Box::new(|_, out| out.fill(0.0)),
    };
    let g = PyNonlinearity {
        g: g.clone().unbind(),
        n: nm,
        vectorized,
        error,
    };
    Ok(GeneralProblem::new(nm, m, c, k, g, excitation).with_velocity_dependent(velocity_dependent))
}

/// The first exception a callback raised during a run, if any.
pub(crate) fn callback_error(problem: &PyProblem) -> Option<PyErr> {
    problem
        .nonlinearity()
        .error
        .lock()
        .ok()
        .and_then(|mut s| s.take())
}

/// The tolerance keywords of `solve`, `frc` and `limit_cycle` applied to `opts`:
/// ‖r‖₂ ≤ `tol + rtol·S` (`tol` absolute, S the force scale of ivt-hb's
/// `HbOptions`); `max_iter` caps the iterations of one solve.
pub(crate) fn with_tolerances(
    opts: HbOptions,
    tol: f64,
    rtol: f64,
    max_iter: usize,
) -> PyResult<HbOptions> {
    if !(rtol.is_finite() && tol.is_finite() && rtol >= 0.0 && tol >= 0.0 && rtol + tol > 0.0) {
        return Err(PyValueError::new_err(format!(
            "tolerances must be finite, >= 0 and not both 0, got tol = {tol}, rtol = {rtol}"
        )));
    }
    if max_iter == 0 {
        return Err(PyValueError::new_err("argument `max_iter` must be >= 1"));
    }
    Ok(opts.with_tolerances(rtol, tol).with_max_iter(max_iter))
}
