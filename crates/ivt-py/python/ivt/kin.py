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

# GIVT (§2.1), SGIVT (§2.2), noncircular gears, units
Givt = _native.Givt
Sgivt = _native.Sgivt
pitch_profile = _native.pitch_profile
fourier_coefficient_eq38 = _native.fourier_coefficient_eq38
ncg_ratio = _native.ncg_ratio
direction = _native.direction
rectified_shape = _native.rectified_shape
inch_to_m = _native.inch_to_m
m_to_inch = _native.m_to_inch
deg_to_rad = _native.deg_to_rad
rad_to_deg = _native.rad_to_deg
rpm_to_rad_s = _native.rpm_to_rad_s
rad_s_to_rpm = _native.rad_s_to_rpm
#: Coefficients a_1..a_4 of the smooth ratio Eq. 42 as printed.
EQ42_PRINTED = _native.EQ42_PRINTED
#: §4.4.2: R_avg ≈ 7/27492 per degree of θ_CT.
R_AVG_SLOPE_PRINTED_PER_DEG: float = _native.R_AVG_SLOPE_PRINTED_PER_DEG
#: Period of the GIVT module ratio in θ: π/2 (four crank-sliders 90° apart).
GIVT_MODULE_PERIOD: float = _native.GIVT_MODULE_PERIOD


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
