//! The numpy arrays that pass between the solver and a vectorized Python
//! callback (`g` or `jac` of a user system), built and read with as little
//! work per call as is safe: the solver's buffers never reach Python (`x`, `v`
//! are copied every call), the phase array of each sample grid is built once
//! and handed out read-only, and a C-contiguous float64 result is copied
//! without numpy's conversion machinery.

use numpy::ndarray::Array2;
use numpy::{
    AllowTypeChange, IntoPyArray, PyArrayDyn, PyArrayLikeDyn, PyArrayMethods, PyUntypedArrayMethods,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::Mutex;

/// Distinct sample grids whose phase arrays are kept (the residual's, Hsu's,
/// an event's refined one, with room to spare; one-sample grids are not kept).
const GRIDS: usize = 4;

/// The argument arrays of a vectorized callback, with the read-only phase
/// arrays of the last [`GRIDS`] sample grids.
#[derive(Default)]
pub(crate) struct SampleArrays {
    phases: Mutex<Vec<(Vec<f64>, Py<PyAny>)>>,
}

impl SampleArrays {
    /// `x`, `v` as new (N, n) arrays and `theta` as a read-only (N,) array.
    pub(crate) fn args<'py>(
        &self,
        py: Python<'py>,
        n: usize,
        x: &[f64],
        v: &[f64],
        theta: &[f64],
    ) -> PyResult<[Bound<'py, PyAny>; 3]> {
        let shape = |a: &[f64]| {
            Array2::from_shape_vec((theta.len(), n), a.to_vec())
                .map(|a| a.into_pyarray(py).into_any())
                .map_err(|e| PyValueError::new_err(e.to_string()))
        };
        Ok([shape(x)?, shape(v)?, self.phase(py, theta)?])
    }

    /// The read-only phase array of `theta`'s grid: kept from an earlier call
    /// with the same phases, else built (and kept, the oldest grid dropped,
    /// unless it has one sample).
    fn phase<'py>(&self, py: Python<'py>, theta: &[f64]) -> PyResult<Bound<'py, PyAny>> {
        let mut kept = self
            .phases
            .lock()
            .map_err(|_| PyValueError::new_err("internal: phase cache poisoned"))?;
        if let Some((_, array)) = kept.iter().find(|(t, _)| t.as_slice() == theta) {
            return Ok(array.bind(py).clone());
        }
        let array = theta.to_vec().into_pyarray(py).into_any();
        // Read-only, and the memory belongs to Rust: numpy cannot make it
        // writeable again, so no callback can change a later call's phases.
        let flags = PyDict::new(py);
        flags.set_item("write", false)?;
        array.call_method("setflags", (), Some(&flags))?;
        if theta.len() < 2 {
            // A one-sample evaluation: its phase changes every call.
            return Ok(array);
        }
        if kept.len() == GRIDS {
            kept.remove(0);
        }
        kept.push((theta.to_vec(), array.clone().unbind()));
        Ok(array)
    }
}

/// ValueError naming `what` when `ob` holds complex numbers: a Python or
/// numpy complex scalar, a complex numpy array, or a list or tuple with a
/// complex entry. Converting them to floats would drop the imaginary part
/// silently (numpy only warns), so every complex input is refused.
pub(crate) fn refuse_complex(what: &str, ob: &Bound<'_, PyAny>) -> PyResult<()> {
    if holds_complex(ob, 2) {
        return Err(PyValueError::new_err(format!(
            "{what} is complex: its imaginary part would be dropped. Complex inputs are refused \
             (structural damping K(1 + iη) included: give a real damping matrix c, e.g. \
             c = η·k/ω at one frequency ω, or Rayleigh c = α·m + β·k)"
        )));
    }
    Ok(())
}

/// Whether `ob` is complex ([`refuse_complex`]), looking `depth` levels
/// into lists and tuples.
fn holds_complex(ob: &Bound<'_, PyAny>, depth: usize) -> bool {
    use numpy::{PyArrayDescrMethods, PyUntypedArray};
    use pyo3::types::{PyComplex, PyList, PyTuple};
    if ob.is_instance_of::<PyComplex>() {
        return true;
    }
    if let Ok(a) = ob.cast::<PyUntypedArray>() {
        return a.dtype().kind() == b'c';
    }
    depth > 0
        && (ob.is_instance_of::<PyList>() || ob.is_instance_of::<PyTuple>())
        && ob
            .try_iter()
            .is_ok_and(|it| it.flatten().any(|e| holds_complex(&e, depth - 1)))
}

/// A callback's array result as its shape and its values in row-major order,
/// or `None` if it is not an array of floats. A C-contiguous float64 array is
/// copied directly; anything else is converted by numpy first.
pub(crate) fn float_array(ob: &Bound<'_, PyAny>) -> Option<(Vec<usize>, Vec<f64>)> {
    if let Ok(a) = ob.cast::<PyArrayDyn<f64>>() {
        if a.is_c_contiguous() {
            if let Ok(values) = a.to_vec() {
                return Some((a.shape().to_vec(), values));
            }
        }
    }
    let a = ob
        .extract::<PyArrayLikeDyn<'_, f64, AllowTypeChange>>()
        .ok()?;
    Some((a.shape().to_vec(), a.as_array().iter().copied().collect()))
}
