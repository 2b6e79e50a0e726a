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

The numerics are the Rust crates of the workspace, reached through the private
native module ``ivt._ivt``; long calls release the GIL.
"""

from . import ctrl, design, hb, kin, scenes, sim, sweep
from ._ivt import __version__

__all__ = ["ctrl", "design", "hb", "kin", "scenes", "sim", "sweep", "__version__"]
