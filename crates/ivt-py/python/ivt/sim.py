"""The simulator (``ivt-sim``): run a scene, get numpy arrays and the summary.

A scene is a dict (the TOML structure), a path to a ``.toml`` file, or TOML
text (a ``str`` containing a newline or ``=``); see ``scenes/*.toml`` and
``docs/guide/src/controller/scenes.md`` for the keys. :func:`run` releases the GIL, so
several scenes run in parallel on threads (see :mod:`ivt.sweep`).
"""

from . import _ivt
from ._reexport import reexport


__all__ = ["SUPPORTED_PPR", "check_scene", "run", "scene_dict"]

reexport(globals(), _ivt.sim, __all__)
