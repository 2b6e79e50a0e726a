"""Controller design from the model (thesis §4.2–4.3)."""

import os
from typing import Any, Dict, Literal, Optional, Tuple, Union

from .kin import Plant

# A preset name (Table 1, or Table 1 with k_t and k_e divided by 10), a plant
# file (`[plant]` table, e.g. from `ivt rig identify --out`) or a Plant.
PlantArg = Union[Literal["printed", "thesis-ch4"], str, "os.PathLike[str]", Plant]
# One axis of the (V_m, T_U) grid: (from, step, to), as in `ivt ol table`.
Axis = Tuple[float, float, float]

# The signatures are the runtime's, parameter for parameter (tests/test_stubs.py);
# a line holds one group: the operating point or grid, the law's or the
# loop's settings, the plant.
def ol_solve(
    v_m: float, t_u: float,
    omega0_rpm: float = 100.0, harmonics: int = 7,
    plant: Optional[PlantArg] = None, method: Literal["polish", "ihb"] = "polish",
) -> Dict[str, Any]: ...
def ol_table(
    v_m: Axis = (2.0, 0.4, 12.0), t_u: Axis = (1.5, 0.5, 9.0),
    omega0_rpm: float = 100.0, harmonics: int = 7,
    plant: Optional[PlantArg] = None,
) -> Dict[str, Any]: ...
def ol_fit(
    v_m: Axis = (2.0, 0.4, 12.0), t_u: Axis = (1.5, 0.5, 9.0),
    omega0_rpm: float = 100.0, harmonics: int = 7,
    plant: Optional[PlantArg] = None, full: bool = False,
) -> Dict[str, Any]: ...
def stability(
    v_m: float, t_u: float,
    k: float = 0.01, k2: float = 0.02, si: bool = False, n: int = 16, omega0_rpm: float = 100.0,
    plant: Optional[PlantArg] = None,
) -> Dict[str, Any]: ...
def stability_map(
    v_m: Axis = (2.0, 0.4, 12.0), t_u: Axis = (1.5, 0.5, 9.0),
    omega0_rpm: float = 100.0, k: float = 0.01, k2: float = 0.02, si: bool = False, n: int = 16,
    plant: Optional[PlantArg] = None, feasible_only: bool = False,
) -> Dict[str, Any]: ...
