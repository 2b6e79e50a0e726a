//! Python bindings (pyo3 + numpy, built by maturin). Being built under issue 9; nothing here yet.
