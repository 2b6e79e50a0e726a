"""Kinematics of the SGIVT variant (thesis §2.3) and the plant of Eq. 151.

Every numeric argument may be a float or any array-like; arguments broadcast
like numpy ufuncs, and the result is a float for scalar input, else a float64
array. Non-finite inputs raise ``ValueError`` naming the argument.
"""

from typing import Any, Dict

from . import _ivt
from ._reexport import reexport


def _plant_from_params(params: Dict[str, Any]) -> Any:
    """Rebuild a pickled :class:`Plant` from ``Plant.params()``."""
    return Plant(**params)


__all__ = [
    "EQ42_PRINTED",
    "GIVT_MODULE_PERIOD",
    "NCG_AMPLITUDE",
    "R_AVG_SLOPE_PRINTED_PER_DEG",
    "Givt",
    "Plant",
    "Sgivt",
    "deg_to_rad",
    "direction",
    "fourier_coefficient_eq38",
    "inch_to_m",
    "m_to_inch",
    "ncg_ratio",
    "pitch_profile",
    "rad_s_to_rpm",
    "rad_to_deg",
    "rectified_shape",
    "rpm_to_rad_s",
    "driver_speeds",
    "f",
    "f_theta",
    "mean_f_squared",
    "output_speed",
    "output_to_motor_ratio",
    "ring_speeds",
]

reexport(globals(), _ivt.kin, __all__)
