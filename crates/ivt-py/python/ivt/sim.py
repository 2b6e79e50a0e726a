"""The simulator (``ivt-sim``): run a scene, get numpy arrays and the summary.

A scene is a dict (the TOML structure), a path to a ``.toml`` file, or TOML
text (a ``str`` containing a newline or ``=``); see ``scenes/*.toml`` and
``crates/ivt-sim/README.md`` for the keys. :func:`run` releases the GIL, so
several scenes run in parallel on threads (see :mod:`ivt.sweep`).
"""

from . import _ivt

_native = _ivt.sim

run = _native.run
check_scene = _native.check_scene
scene_dict = _native.scene_dict
#: PPR values the simulator's software-in-the-loop controller supports.
SUPPORTED_PPR = _native.SUPPORTED_PPR

__all__ = ["SUPPORTED_PPR", "check_scene", "run", "scene_dict"]
