"""Harmonic balance (``ivt-hb``): periodic solutions, Floquet stability and
frequency-response curves, for Duffing, Mathieu–Duffing and user systems."""

from typing import Any, Callable, Dict, List, Literal, Optional, Sequence, Union, overload

import numpy as np
import numpy.typing as npt

from ._types import ArrayLike, FloatArray

Method = Literal["modified", "classic"]
Matrix = Union[float, npt.ArrayLike]
Callback = Callable[[FloatArray, FloatArray, float], Union[float, Sequence[float], FloatArray]]
VectorizedCallback = Callable[[FloatArray, FloatArray, FloatArray], npt.ArrayLike]
Forcing = Callable[[float], Union[float, Sequence[float], FloatArray]]

class ConvergenceError(RuntimeError):
    """A solve that did not converge."""

    history: List[float]

def duffing(
    n: int = 20,
    samples: int = 64,
    xi: float = 0.02,
    alpha: float = 1.0,
    eps: float = 1.0,
    force: float = 0.1,
    omega_f: float = 0.4,
    method: Method = "modified",
    guess: Optional[ArrayLike] = None,
    tol: float = 1e-10,
    stability: bool = True,
) -> Dict[str, Any]: ...
def mathieu_duffing(
    beta: float,
    n: int = 20,
    samples: int = 64,
    xi: float = 0.125,
    alpha: float = 1.0,
    gamma: float = 1.0,
    omega: float = 2.0,
    subharmonic: int = 1,
    guess: Optional[ArrayLike] = None,
    tol: float = 1e-10,
    stability: bool = True,
) -> Dict[str, Any]: ...
def mathieu_cascade(
    xi: float = 0.125, alpha: float = 1.0, omega: float = 2.0, gamma: float = 1.0, n: int = 12
) -> Dict[str, Any]: ...
def duffing_frc(
    from_: float = 0.2,
    to: float = 3.0,
    n: int = 20,
    samples: int = 64,
    xi: float = 0.02,
    alpha: float = 1.0,
    eps: float = 1.0,
    force: float = 0.1,
) -> Dict[str, Any]: ...
def solve(
    m: Matrix,
    c: Matrix,
    k: Matrix,
    g: Callback,
    omega_f: float,
    f: Optional[Forcing] = None,
    n: int = 20,
    samples: int = 64,
    subharmonic: int = 1,
    method: Method = "modified",
    guess: Optional[ArrayLike] = None,
    tol: float = 0.0,
    stability: bool = True,
    velocity_dependent: bool = True,
    vectorized: bool = False,
    rtol: float = 1e-9,
    max_iter: int = 100,
) -> Dict[str, Any]: ...
def frc(
    m: Matrix,
    c: Matrix,
    k: Matrix,
    g: Union[Callback, VectorizedCallback],
    f: Optional[Forcing],
    omega_from: float,
    omega_to: float,
    n: int = 20,
    samples: int = 64,
    tol: float = 0.0,
    velocity_dependent: bool = True,
    vectorized: bool = False,
    rtol: float = 1e-9,
    max_iter: int = 100,
) -> Dict[str, Any]: ...
def limit_cycle(
    m: Matrix,
    c: Matrix,
    k: Matrix,
    g: Union[Callback, VectorizedCallback],
    omega_guess: float,
    amplitude: float = 1.0,
    guess: Optional[ArrayLike] = None,
    n: int = 20,
    samples: int = 64,
    tol: float = 0.0,
    velocity_dependent: bool = True,
    vectorized: bool = False,
    rtol: float = 1e-9,
    max_iter: int = 100,
) -> Dict[str, Any]: ...
@overload
def eval_series(coeffs: ArrayLike, tau: float, order: int = 0, n_dof: Literal[1] = 1) -> float: ...
@overload
def eval_series(coeffs: ArrayLike, tau: ArrayLike, order: int = 0, n_dof: int = 1) -> FloatArray: ...
