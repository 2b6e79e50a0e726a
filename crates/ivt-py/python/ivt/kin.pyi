"""Kinematics of the SGIVT variant (thesis §2.3) and the plant of Eq. 151."""

from typing import Any, Dict, Literal, Tuple, Union, overload

from ._types import ArrayLike, FloatArray

NCG_AMPLITUDE: float

@overload
def f(theta: float) -> float: ...  # type: ignore[overload-overlap]
@overload
def f(theta: ArrayLike) -> FloatArray: ...
@overload
def f_theta(theta: float) -> float: ...  # type: ignore[overload-overlap]
@overload
def f_theta(theta: ArrayLike) -> FloatArray: ...
def mean_f_squared() -> float: ...
@overload
def ring_speeds(  # type: ignore[overload-overlap]
    omega: float, omega_c: float, d_s: float = 1.0, d_p: float = 1.0
) -> Tuple[float, float]: ...
@overload
def ring_speeds(
    omega: ArrayLike, omega_c: ArrayLike, d_s: float = 1.0, d_p: float = 1.0
) -> Tuple[FloatArray, FloatArray]: ...
@overload
def driver_speeds(  # type: ignore[overload-overlap]
    theta: float, omega: float, r: float
) -> Tuple[float, float]: ...
@overload
def driver_speeds(
    theta: ArrayLike, omega: ArrayLike, r: ArrayLike
) -> Tuple[FloatArray, FloatArray]: ...
@overload
def output_speed(  # type: ignore[overload-overlap]
    theta: float, omega: float, r: float, r_u: float = 0.0222
) -> float: ...
@overload
def output_speed(
    theta: ArrayLike, omega: ArrayLike, r: ArrayLike, r_u: float = 0.0222
) -> FloatArray: ...
@overload
def output_to_motor_ratio(r: float, r_u: float = 0.0222) -> float: ...  # type: ignore[overload-overlap]
@overload
def output_to_motor_ratio(r: ArrayLike, r_u: float = 0.0222) -> FloatArray: ...

Gravity = Literal["printed", "roller_mass"]

class Plant:
    """The IVT plant of Eq. 151 with the Table 1 parameters (SI units)."""

    def __init__(self, **overrides: Union[float, Gravity]) -> None: ...
    def replace(self, **overrides: Union[float, Gravity]) -> "Plant": ...
    def params(self) -> Dict[str, Any]: ...
    def summary(self) -> Dict[str, float]: ...
    @property
    def j_a(self) -> float: ...
    @property
    def j_b(self) -> float: ...
    @property
    def j_c(self) -> float: ...
    @property
    def j_d(self) -> float: ...
    @property
    def motor_damping(self) -> float: ...
    @property
    def motor_gain(self) -> float: ...
    @property
    def load_gain(self) -> float: ...
    @property
    def gravity_gain(self) -> float: ...
    @property
    def r_max(self) -> float: ...
    @overload
    def terms(  # type: ignore[overload-overlap]
        self, theta: float, r: float, v_m: float, t_u: float
    ) -> Dict[str, float]: ...
    @overload
    def terms(
        self, theta: ArrayLike, r: ArrayLike, v_m: ArrayLike, t_u: ArrayLike
    ) -> Dict[str, FloatArray]: ...
    @overload
    def acceleration(  # type: ignore[overload-overlap]
        self, theta: float, omega: float, r: float, v_m: float, t_u: float
    ) -> float: ...
    @overload
    def acceleration(
        self,
        theta: ArrayLike,
        omega: ArrayLike,
        r: ArrayLike,
        v_m: ArrayLike,
        t_u: ArrayLike,
    ) -> FloatArray: ...
