"""Kinematics of the SGIVT variant (thesis §2.3) and the plant of Eq. 151.

Every numeric argument may be a float or any array-like; arguments broadcast
like numpy ufuncs, and the result is a float for scalar input, else a float64
array. Non-finite inputs raise ``ValueError`` naming the argument.
"""

from typing import Any, Dict

from . import _ivt

_native = _ivt.kin

f = _native.f
f_theta = _native.f_theta
mean_f_squared = _native.mean_f_squared
ring_speeds = _native.ring_speeds
driver_speeds = _native.driver_speeds
output_speed = _native.output_speed
output_to_motor_ratio = _native.output_to_motor_ratio
Plant = _native.Plant
NCG_AMPLITUDE: float = _native.NCG_AMPLITUDE


def _plant_from_params(params: Dict[str, Any]) -> Any:
    """Rebuild a pickled :class:`Plant` from ``Plant.params()``."""
    return Plant(**params)


__all__ = [
    "NCG_AMPLITUDE",
    "Plant",
    "driver_speeds",
    "f",
    "f_theta",
    "mean_f_squared",
    "output_speed",
    "output_to_motor_ratio",
    "ring_speeds",
]
