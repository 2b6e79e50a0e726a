"""IVT toolkit from Python: kinematics, harmonic balance, controller and
simulator of the infinitely variable transmission of Wang (2017).

Submodules (each mirrors a command group of the ``ivt`` command line, with the
same names and dict keys as its ``--json`` output, SPEC §6):

- :mod:`ivt.kin`   kinematics and plant coefficients (numpy-vectorized)
- :mod:`ivt.hb`    harmonic balance: Duffing, Mathieu–Duffing, user systems
- :mod:`ivt.ctrl`  the rig controller (f32, as on the MCU)
- :mod:`ivt.design` open-loop law and delay-loop stability from the model
- :mod:`ivt.sim`   scenes of the simulator → numpy arrays and the summary
- :mod:`ivt.scenes` the shipped scenes: ``names()``, ``path(name)``
- :mod:`ivt.sweep` grid / Monte-Carlo sweeps of scenes on threads or dask
- :mod:`ivt.plot`  figures of harmonic-balance results (matplotlib, the
  optional extra ``pip install 'ivt[plot]'``; imported on first use, so
  ``import ivt`` works without it)
- :func:`ivt.foxglove_layout` the Foxglove layout for a run's or a rig's MCAP

The numerics are the Rust crates of the workspace, reached through the private
native module ``ivt._ivt``; long calls release the GIL.
"""

import importlib
import pathlib
from typing import Any

from . import ctrl, design, hb, kin, scenes, sim, sweep
from ._ivt import __version__

__all__ = ["ctrl", "design", "hb", "kin", "scenes", "sim", "sweep", "foxglove_layout", "__version__"]


def foxglove_layout() -> pathlib.Path:
    """Path of the Foxglove layout shipped with the package (``ivt-layout.json``).

    Import it in Foxglove (Layouts → Import from file) and open a simulator
    run's ``out/*.mcap`` or a rig recording: plots of ω and ω_a, r, V_m, T_U and
    the stepper position, and the controller's fault state over time.
    """
    return pathlib.Path(__file__).resolve().with_name("foxglove") / "ivt-layout.json"


def __getattr__(name: str) -> Any:
    """``ivt.plot`` on first use (it needs matplotlib, an optional extra)."""
    if name == "plot":
        return importlib.import_module(".plot", __name__)
    raise AttributeError(f"module 'ivt' has no attribute {name!r}")
