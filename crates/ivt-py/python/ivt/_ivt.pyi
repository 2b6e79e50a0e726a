"""The private native module (Rust, pyo3). Its submodules are typed by the
public stubs ivt/kin.pyi, ivt/ctrl.pyi, ...; import from those."""

from typing import Any

__version__: str
kin: Any
ctrl: Any
hb: Any
sim: Any
design: Any
