"""The rig controller (``ivt-ctrl``): the same f32 code the firmware runs.

:class:`Controller` takes ``ppr`` (one of :data:`SUPPORTED_PPR`) and keyword
overrides of ivt-ctrl's ``Config`` (SI units); feed it encoder timestamps
pulse by pulse (:meth:`Controller.on_pulse`) or as an array
(:meth:`Controller.on_pulses`, GIL released, keys of ``ivt ctrl replay --json``).
"""

from . import _ivt
from ._reexport import reexport


__all__ = [
    "FAULTS",
    "SUPPORTED_PPR",
    "Controller",
    "open_loop_eval",
    "open_loop_preset",
    "thesis_gains",
]

reexport(globals(), _ivt.ctrl, __all__)
