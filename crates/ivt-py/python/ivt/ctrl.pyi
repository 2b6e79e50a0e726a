"""The rig controller (``ivt-ctrl``): the same f32 code the firmware runs."""

from typing import Any, Dict, List, Literal, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from ._types import ArrayLike

SUPPORTED_PPR: List[int]
FAULTS: Dict[int, str]

Law = Literal["delay", "nodelay", "prop", "open"]
OpenLoop = Union[Literal["refit", "thesis"], Dict[str, Any]]

class Controller:
    """The rig controller of ivt-ctrl for ``ppr`` samples per revolution."""

    def __init__(
        self,
        ppr: int = 1200,
        *,
        f_timer_hz: Optional[float] = None,
        omega0: Optional[float] = None,
        omega0_rpm: Optional[float] = None,
        decimation: Optional[int] = None,
        law: Optional[Law] = None,
        k: Optional[float] = None,
        k2: Optional[float] = None,
        k_prop: Optional[float] = None,
        prop_period_s: Optional[float] = None,
        open_loop: Optional[OpenLoop] = None,
        feedforward: Optional[bool] = None,
        steps_per_metre: Optional[float] = None,
        offset_steps: Optional[int] = None,
        stepper_max_speed: Optional[float] = None,
        stepper_accel: Optional[float] = None,
        stall_timeout_s: Optional[float] = None,
        omega_max: Optional[float] = None,
        safe_r: Optional[float] = None,
        v_m_valid: Optional[Tuple[float, float]] = None,
        t_u_valid: Optional[Tuple[float, float]] = None,
        initial_inputs: Optional[Tuple[float, float]] = None,
    ) -> None: ...
    @property
    def ppr(self) -> int: ...
    @property
    def r_max(self) -> float: ...
    def config(self) -> Dict[str, Any]: ...
    def on_pulse(self, ticks: int) -> Dict[str, Any]: ...
    def update_inputs(self, v_m: float, t_u: float) -> Dict[str, Any]: ...
    def step_tick(self, now: int) -> Dict[str, Any]: ...
    def output(self) -> Dict[str, Any]: ...
    def on_pulses(
        self,
        ticks: Union[npt.NDArray[np.integer[Any]], Sequence[int]],
        v_m: Optional[ArrayLike] = None,
        t_u: Optional[ArrayLike] = None,
    ) -> Dict[str, npt.NDArray[Any]]: ...

def thesis_gains(k: float, k2: float) -> Tuple[float, float]: ...
def open_loop_preset(name: Literal["refit", "thesis"]) -> Dict[str, Any]: ...
def open_loop_eval(
    v_m: float, t_u: float, open_loop: Optional[OpenLoop] = None
) -> Dict[str, Any]: ...
