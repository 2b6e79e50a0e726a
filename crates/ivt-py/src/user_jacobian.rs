//! The optional Python Jacobian `jac(x, v, theta) -> (dg_dx, dg_dv)` of a user
//! system's `g`: per sample two (n, n) arrays, or (`vectorized`) for (N, n)
//! inputs two (N, n, n) arrays. `dg_dv` may be `None` (zero). It replaces the
//! central differences of `g` in every Jacobian assembly (ivt-hb's
//! [`Nonlinearity::jacobian_samples`](ivt_hb::Nonlinearity::jacobian_samples)).

use crate::callback_arrays::{float_array, SampleArrays};
use crate::error_slot::{failed, record, ErrorSlot};
use ivt_hb::problem::per_sample;
use numpy::IntoPyArray;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

/// The Python `jac` of a user system (see the module docs).
pub(crate) struct PyJacobian {
    jac: Py<PyAny>,
    n: usize,
    vectorized: bool,
    arrays: SampleArrays,
    error: ErrorSlot,
}

impl PyJacobian {
    /// `jac` for `n` DOFs, called per sample or (`vectorized`) once for all.
    pub(crate) fn new(jac: Py<PyAny>, n: usize, vectorized: bool, error: ErrorSlot) -> Self {
        Self {
            jac,
            n,
            vectorized,
            arrays: SampleArrays::default(),
            error,
        }
    }

    /// `[∂g/∂x | ∂g/∂v]` at `theta.len()` samples into `dg` (`2n²` per sample);
    /// NaN and the exception recorded when `jac` raises or returns a bad value.
    pub(crate) fn eval_samples(&self, x: &[f64], v: &[f64], theta: &[f64], dg: &mut [f64]) {
        if self.vectorized {
            self.call(x, v, theta, true, dg);
        } else {
            per_sample(self.n, x, v, theta, dg, |x, v, th, dg| {
                self.call(x, v, &[th], false, dg)
            });
        }
    }

    /// One call of `jac`: with (N, n) arrays and a (N,) phase array when
    /// `batch`, else with (n,) arrays and a float.
    fn call(&self, x: &[f64], v: &[f64], theta: &[f64], batch: bool, dg: &mut [f64]) {
        if failed(&self.error) {
            dg.fill(f64::NAN);
            return;
        }
        let (n, ns) = (self.n, theta.len());
        let r = Python::attach(|py| -> PyResult<()> {
            let res = if batch {
                let [xs, vs, ths] = self.arrays.args(py, n, x, v, theta)?;
                self.jac.bind(py).call1((xs, vs, ths))?
            } else {
                let th = theta.first().copied().unwrap_or(f64::NAN);
                let args = (x.to_vec().into_pyarray(py), v.to_vec().into_pyarray(py), th);
                self.jac.bind(py).call1(args)?
            };
            let (dx, dv) = pair(&res)?;
            let shape: &[usize] = if batch { &[ns, n, n] } else { &[n, n] };
            let dx = block("dg_dx", &dx, shape)?;
            let dv = if dv.is_none() {
                None
            } else {
                Some(block("dg_dv", &dv, shape)?)
            };
            let n2 = n * n;
            // `block` checked the lengths: ns·n² entries each, one row block per sample.
            let mut dv_rows = dv.as_ref().map(|d| d.chunks_exact(n2));
            for (sample, rows) in dg.chunks_exact_mut(2 * n2).zip(dx.chunks_exact(n2)) {
                let (sx, sv) = sample.split_at_mut(n2);
                sx.copy_from_slice(rows);
                match dv_rows.as_mut().and_then(|it| it.next()) {
                    Some(d) => sv.copy_from_slice(d),
                    None => sv.fill(0.0),
                }
            }
            Ok(())
        });
        if let Err(e) = r {
            record(&self.error, e);
            dg.fill(f64::NAN);
        }
    }
}

/// The pair `(dg_dx, dg_dv)` that `jac` returned (a tuple or list of two).
fn pair<'py>(res: &Bound<'py, PyAny>) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    let items: Option<Vec<Bound<'py, PyAny>>> = res
        .extract::<(Bound<'py, PyAny>, Bound<'py, PyAny>)>()
        .map(|(a, b)| vec![a, b])
        .or_else(|_| res.extract::<Vec<Bound<'py, PyAny>>>())
        .ok();
    match items.map(<[Bound<'py, PyAny>; 2]>::try_from) {
        Some(Ok([dx, dv])) => Ok((dx, dv)),
        _ => Err(PyTypeError::new_err(
            "`jac` must return a pair (dg_dx, dg_dv) (dg_dv may be None)",
        )),
    }
}

/// One block that `jac` returned as row-major floats: its shape must be
/// `shape` (axes of length 1 aside, so a 1-DOF `jac` may return (N, 1) or a
/// float) and its entries finite.
fn block(name: &str, ob: &Bound<'_, PyAny>, shape: &[usize]) -> PyResult<Vec<f64>> {
    let (got, values) = float_array(ob).ok_or_else(|| {
        PyTypeError::new_err(format!("`jac` must return {name} as an array of floats"))
    })?;
    let squeeze = |s: &[usize]| s.iter().copied().filter(|&d| d != 1).collect::<Vec<_>>();
    if squeeze(&got) != squeeze(shape) {
        return Err(PyValueError::new_err(format!(
            "`jac` returned {name} of shape {got:?}, expected {shape:?}"
        )));
    }
    if let Some((k, bad)) = values.iter().enumerate().find(|(_, v)| !v.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "`jac` returned a non-finite {name} entry ({bad}) at flat index {k}"
        )));
    }
    Ok(values)
}
