"""IVT toolkit from Python: kinematics, harmonic balance, controller and
simulator of the infinitely variable transmission of Wang (2017).

Submodules (each mirrors a command group of the ``ivt`` command line, with the
same names and dict keys as its ``--json`` output, SPEC §6):

- :mod:`ivt.kin`   kinematics and plant coefficients (numpy-vectorized)

The numerics are the Rust crates of the workspace, reached through the private
native module ``ivt._ivt``; long calls release the GIL.
"""

from . import _ivt, kin

__version__: str = _ivt.__version__

__all__ = ["kin", "__version__"]
