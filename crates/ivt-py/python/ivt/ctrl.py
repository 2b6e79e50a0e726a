"""The rig controller (``ivt-ctrl``): the same f32 code the firmware runs.

:class:`Controller` takes ``ppr`` (one of :data:`SUPPORTED_PPR`) and keyword
overrides of ivt-ctrl's ``Config`` (SI units); feed it encoder timestamps
pulse by pulse (:meth:`Controller.on_pulse`) or as an array
(:meth:`Controller.on_pulses`, GIL released, keys of ``ivt ctrl replay --json``).
"""

from . import _ivt

_native = _ivt.ctrl

Controller = _native.Controller
thesis_gains = _native.thesis_gains
open_loop_preset = _native.open_loop_preset
open_loop_eval = _native.open_loop_eval
#: PPR values with a compiled controller (Controller<PPR> is a const generic).
SUPPORTED_PPR = _native.SUPPORTED_PPR
#: Fault code → name (ivt-ctrl's ``Fault`` enum).
FAULTS = _native.FAULTS

__all__ = [
    "FAULTS",
    "SUPPORTED_PPR",
    "Controller",
    "open_loop_eval",
    "open_loop_preset",
    "thesis_gains",
]
