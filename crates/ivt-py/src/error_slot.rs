//! The error slot of a user system: the first exception a Python callback
//! (`g`, `f`, `jac`) raised during a run, kept while the solver goes on with
//! NaN, and re-raised when the run returns. Shared by the callbacks of
//! user_problem.rs and user_jacobian.rs.

use pyo3::prelude::*;
use std::sync::{Arc, Mutex};

/// The first exception raised by a callback (the solver then sees NaN).
pub(crate) type ErrorSlot = Arc<Mutex<Option<PyErr>>>;

/// Keeps `e` in `slot` unless an earlier exception is there.
pub(crate) fn record(slot: &ErrorSlot, e: PyErr) {
    if let Ok(mut slot) = slot.lock() {
        if slot.is_none() {
            *slot = Some(e);
        }
    }
}

/// Whether a callback of the run already raised: later callbacks are not
/// called (their outputs are NaN), so a failed run ends without more Python.
pub(crate) fn failed(slot: &ErrorSlot) -> bool {
    slot.lock().is_ok_and(|s| s.is_some())
}
