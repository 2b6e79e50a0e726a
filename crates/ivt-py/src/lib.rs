//! Python bindings of the IVT toolkit: the native module `ivt._ivt` behind the
//! pure-Python package `ivt` (python/ivt). Thin by design: every function
//! converts arguments, calls the Rust crate, and converts the result; the
//! numerics live in `ivt-kin`, `ivt-hb`, `ivt-ctrl` and `ivt-sim`.
//!
//! Build and install into a virtualenv with `maturin develop --release` (or
//! `pip install crates/ivt-py`); `scripts/py-test` does it and runs pytest.
#![doc = include_str!("../README.md")]

use pyo3::prelude::*;

/// Add each `#[pyfunction]` named in the list to the module `m` (inside a
/// function returning `PyResult`).
macro_rules! add_functions {
    ($m:expr, [$($f:ident),* $(,)?]) => {
        $( $m.add_function(wrap_pyfunction!($f, $m)?)?; )*
    };
}

mod args;
mod callback_arrays;
mod ctrl;
mod ctrl_convert;
mod design;
mod error_slot;
mod fields;
mod flat_floats;
mod gears;
mod hb;
mod hb_analyses;
mod hb_bifurcation;
mod hb_cycle_fold;
mod hb_elements;
mod hb_family;
mod hb_folds;
mod hb_large;
mod hb_paths;
mod hb_reduced;
mod hb_sensitivity;
mod hb_shared;
mod hb_string;
mod hb_switch;
mod hb_torus;
mod interrupt;
mod kin;
mod sim;
mod steps;
mod to_python;
mod user_jacobian;
mod user_problem;
mod vectorize;

/// The native module; the public API is re-exported by the `ivt` package.
#[pymodule]
fn _ivt(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The NumPy C API now, at import: looked up lazily, a first array made
    // while a KeyboardInterrupt is pending (Ctrl-C during a call) fails the
    // lookup, which the numpy crate turns into a panic.
    numpy::PyArray1::<f64>::zeros(m.py(), 0, false);
    kin::register(m)?;
    ctrl::register(m)?;
    hb::register(m)?;
    sim::register(m)?;
    design::register(m)?;
    Ok(())
}
