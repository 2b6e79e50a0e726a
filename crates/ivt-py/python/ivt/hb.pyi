"""Harmonic balance (``ivt-hb``): periodic solutions, Floquet stability,
frequency-response curves with located bifurcations, limit cycles and backbone
curves, for Duffing, Mathieu–Duffing, the STHB string and user systems."""

# Forward references in class bodies: pdoc executes the stubs as Python.
from __future__ import annotations

from typing import Any, Callable, Dict, List, Literal, Optional, Sequence, Tuple, Union, overload

import os

import numpy as np
import numpy.typing as npt

from ._types import ArrayLike, FloatArray

Method = Literal["modified", "classic"]
Matrix = Union[float, npt.ArrayLike]
# ``g`` and ``f`` may also take the excitation frequency as a parameter named
# ``omega`` (passed by ``frc`` and ``solve``): ``g(x, v, theta, omega)``,
# ``f(theta, omega)``.
Callback = Union[
    Callable[[FloatArray, FloatArray, float], Union[float, Sequence[float], FloatArray]],
    Callable[[FloatArray, FloatArray, float, float], Union[float, Sequence[float], FloatArray]],
]
VectorizedCallback = Union[
    Callable[[FloatArray, FloatArray, FloatArray], npt.ArrayLike],
    Callable[[FloatArray, FloatArray, FloatArray, float], npt.ArrayLike],
]
Forcing = Union[
    Callable[[float], Union[float, Sequence[float], FloatArray]],
    Callable[[float, float], Union[float, Sequence[float], FloatArray]],
]
# Large models (issue 28): scipy.sparse matrices (untyped here) and load
# vectors F (F cos θ) or (F_cos, F_sin).
SparseMatrix = Any
Loads = Union[npt.ArrayLike, Tuple[npt.ArrayLike, npt.ArrayLike]]
# ``jac(x, v, theta) -> (dg_dx, dg_dv)``: per sample two (n, n) arrays, with
# ``vectorized=True`` two (N, n, n) arrays; ``dg_dv`` may be None (zero).
Jacobian = Callable[[FloatArray, FloatArray, Any], Sequence[Optional[npt.ArrayLike]]]

class Elements:
    """A sum of Rust nonlinear elements, passed as ``g`` (no Python in the loop)."""

    def __add__(self, other: Elements) -> Elements: ...
    def __len__(self) -> int: ...
    @property
    def dofs(self) -> List[int]: ...
    def restricted(self, dofs: Sequence[int]) -> Elements: ...

class elements:
    """``ivt.hb.elements``: element constructors; ``+`` composes them. Each acts on
    δ = x[dof] − x[to] (x[to] = 0 for ``to=None``, the ground)."""

    @staticmethod
    def cubic_spring(k3: float, dof: int = 0, to: Optional[int] = None) -> Elements: ...
    @staticmethod
    def quadratic_damper(c2: float, dof: int = 0, to: Optional[int] = None) -> Elements: ...
    @staticmethod
    def cubic_damper(c3: float, dof: int = 0, to: Optional[int] = None) -> Elements: ...
    @staticmethod
    def coulomb(force: float, v_reg: float, dof: int = 0, to: Optional[int] = None) -> Elements: ...
    @staticmethod
    def clearance(gap: float, k: float, dof: int = 0, to: Optional[int] = None) -> Elements: ...
    @staticmethod
    def unilateral(gap: float, k: float, dof: int = 0, to: Optional[int] = None) -> Elements: ...
    @staticmethod
    def jenkins(k: float, slip_force: float, dof: int = 0, to: Optional[int] = None) -> Elements: ...

class ConvergenceError(RuntimeError):
    """A solve that did not converge."""

    history: List[float]

# A model's matrix: dense (``Matrix``) or, for large models, scipy.sparse or
# the path of a Matrix Market (.mtx) file.
Operator = Union[Matrix, SparseMatrix, str, "os.PathLike[str]"]
# ``g``: a Python callback (per sample or vectorized) or a sum of Rust elements.
Nonlinearity = Union[Callback, VectorizedCallback, Elements]
# ``family(p) -> (m, c, k, g, f)`` or, unforced, ``(m, c, k, g)``: the system at p.
Family = Callable[[float], Sequence[Any]]
# Large models, keyword only: DOF indices (``nonlinear_dofs``: where ``g``
# acts; ``record_dofs``: whose coefficients the result holds).
Dofs = Optional[Sequence[int]]
# Large models: the exact condensed path, the reduced one, or the choice by
# size and bandwidth (``None`` = "auto").
Reduction = Literal["auto", "exact", "krylov"]

# The signatures below are the runtime's, parameter for parameter
# (tests/test_stubs.py pins each name, kind, order and default), so the options
# that many solvers share are spelled in each; a line holds one group of them:
# the model, the excitation, the discretization, the solver's own options, and
# the Newton options (``tol``, ``velocity_dependent``, ``vectorized``, ``rtol``,
# ``max_iter``, ``jac``).
def duffing(
    n: int = 20, samples: Optional[int] = None,
    xi: float = 0.02, alpha: float = 1.0, eps: float = 1.0, force: float = 0.1, omega_f: float = 0.4,
    method: Method = "modified", guess: Optional[ArrayLike] = None, tol: float = 1e-10, stability: bool = True,
) -> Dict[str, Any]: ...
def mathieu_duffing(
    beta: float,
    n: int = 20, samples: Optional[int] = None,
    xi: float = 0.125, alpha: float = 1.0, gamma: float = 1.0, omega: float = 2.0, subharmonic: int = 1,
    guess: Optional[ArrayLike] = None, tol: float = 1e-10, stability: bool = True,
) -> Dict[str, Any]: ...
def mathieu_cascade(
    xi: float = 0.125, alpha: float = 1.0, omega: float = 2.0, gamma: float = 1.0, n: int = 12,
    samples: Optional[int] = None,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
) -> Dict[str, Any]: ...
def duffing_frc(
    from_: float = 0.2, to: float = 3.0,
    n: int = 20, samples: Optional[int] = None,
    xi: float = 0.02, alpha: float = 1.0, eps: float = 1.0, force: float = 0.1,
    events: bool = False,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
) -> Dict[str, Any]: ...
def duffing_folds(
    force: float = 0.1, force_from: float = 0.0, force_to: float = 0.3, at: Sequence[float] = ...,
    from_: float = 0.5, to: float = 2.5,
    n: int = 20, samples: Optional[int] = None,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
) -> Dict[str, Any]: ...
def solve(
    m: Operator, c: Operator, k: Operator, g: Nonlinearity,
    omega_f: float, f: Optional[Union[Forcing, Loads]] = None,
    n: int = 20, samples: Optional[int] = None, subharmonic: int = 1,
    method: Method = "modified", guess: Optional[ArrayLike] = None, tol: float = 0.0, stability: bool = True,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
    jac: Optional[Jacobian] = None,
    *,
    nonlinear_dofs: Dofs = None, amplitude_dof: Optional[int] = None, record_dofs: Dofs = None,
    reduction: Optional[Reduction] = None, reduction_tol: Optional[float] = None,
    reduction_samples: Optional[int] = None,
) -> Dict[str, Any]: ...
def frc(
    m: Operator, c: Operator, k: Operator, g: Nonlinearity,
    f: Optional[Union[Forcing, Loads]], omega_from: float, omega_to: float,
    n: int = 20, samples: Optional[int] = None, tol: float = 0.0, events: bool = True,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
    jac: Optional[Jacobian] = None,
    *,
    nonlinear_dofs: Dofs = None, amplitude_dof: Optional[int] = None, record_dofs: Dofs = None,
    reduction: Optional[Reduction] = None, reduction_tol: Optional[float] = None,
    reduction_samples: Optional[int] = None,
) -> Dict[str, Any]: ...
def continue_bifurcation(
    family: Family, start: Dict[str, Any],
    p_from: float, p_to: float, at: Sequence[float] = ..., p_start: Optional[float] = None,
    n: int = 20, samples: Optional[int] = None,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
) -> Dict[str, Any]: ...
def cycle_branch(
    family: Family,
    p_from: float, p_to: float, at: Sequence[float] = ...,
    n: int = 20, samples: Optional[int] = None,
    velocity_dependent: bool = True, vectorized: bool = False, grid: int = 100, rtol: float = 1e-9, max_iter: int = 100,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None, offset: float = 1e-2,
) -> Dict[str, Any]: ...
def neimark_sacker_points(
    family: Family, ps: Sequence[float],
    omega_from: float, omega_to: float,
    n: int = 20, samples: Optional[int] = None, rtol: float = 1e-9, max_iter: int = 100,
    velocity_dependent: bool = True, vectorized: bool = False,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
) -> List[Dict[str, Any]]: ...
def limit_cycle(
    m: Matrix, c: Matrix, k: Matrix, g: Nonlinearity,
    omega_guess: float, amplitude: float = 1.0, guess: Optional[ArrayLike] = None,
    n: int = 20, samples: Optional[int] = None, tol: float = 1e-8, x0: Optional[Sequence[float]] = None,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
    jac: Optional[Jacobian] = None,
) -> Dict[str, Any]: ...
def backbone(
    m: Matrix, c: Matrix, k: Matrix, g: Nonlinearity,
    omega0: float, mode: Sequence[float], amplitude_from: float = 0.01, amplitude_to: float = 1.0,
    n: int = 20, samples: Optional[int] = None, dof: int = 0, tol: float = 0.0,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
    jac: Optional[Jacobian] = None,
) -> Dict[str, Any]: ...
class AllSolutions(List[Dict[str, Any]]):
    """The orbits of :func:`all_solutions`; ``search`` holds the search's bounds
    and whether it was exhausted."""

    search: Dict[str, Any]
    def __init__(self, solutions: List[Dict[str, Any]], search: Dict[str, Any]) -> None: ...

def all_solutions(
    m: Matrix, c: Matrix, k: Matrix, g: Nonlinearity,
    f: Optional[Forcing], omega: float,
    n: int = 20, samples: Optional[int] = None, max_amplitude: float = 10.0, amplitudes: int = 6, newton_steps: int = 60,
    tol: float = 0.0,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
    jac: Optional[Jacobian] = None,
) -> AllSolutions: ...
def damped_modes(
    m: Matrix, c: Matrix, k: Matrix, g: Nonlinearity,
    amplitude_from: float, amplitude_to: float,
    n: int = 20, samples: Optional[int] = None, mode: int = 0, dof: int = 0, tol: float = 0.0,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
    jac: Optional[Jacobian] = None,
) -> Dict[str, Any]: ...
def string(
    kd: float = 10.0, modes: int = 5, harmonics: int = 19,
    from_: float = 1.0, to: float = 6.0,
    cd: float = 0.8, y0: float = 0.5, ns: int = 64, ms: int = 128,
    boundary: Literal["fixed", "spring"] = "fixed", k0: float = 10.0,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
) -> Dict[str, Any]: ...
@overload
def eval_series(coeffs: ArrayLike, tau: float, order: int = 0, n_dof: Literal[1] = 1) -> float: ...
@overload
def eval_series(coeffs: ArrayLike, tau: ArrayLike, order: int = 0, n_dof: int = 1) -> FloatArray: ...

class models:
    """``ivt.hb.models``: structural test models (issue 28)."""

    @staticmethod
    def cantilever(
        n_elements: int,
        length: float = 1.0,
        ei: float = 1.0,
        rho_a: float = 1.0,
        alpha: float = 0.07,
        beta: float = 2e-4,
    ) -> Tuple[SparseMatrix, SparseMatrix, SparseMatrix, int]: ...
    @staticmethod
    def solid(
        mesh: Any,
        clamped: Callable[[FloatArray], Any],
        young: float = 210e9,
        poisson: float = 0.3,
        density: float = 7800.0,
    ) -> Tuple[SparseMatrix, SparseMatrix, FloatArray, Callable[[int, int], int]]: ...
    @staticmethod
    def plate(
        nx: int,
        ny: Optional[int] = None,
        nz: int = 2,
        size: Tuple[float, float, float] = (1.0, 0.2, 0.02),
        young: float = 210e9,
        poisson: float = 0.3,
        density: float = 7800.0,
    ) -> Tuple[SparseMatrix, SparseMatrix, int]: ...
    @staticmethod
    def bladed_disk(
        blade_stiffness: Optional[npt.ArrayLike] = None,
    ) -> Tuple[SparseMatrix, SparseMatrix, SparseMatrix, int]: ...

# Branch switching (issue 27 item 2, crates/ivt-py/src/hb_switch.rs).
def torus_branch(
    m: Matrix, c: Matrix, k: Matrix, g: Nonlinearity,
    f: Optional[Forcing], start: Dict[str, Any], omega_to: float, at: Sequence[float] = ...,
    n: int = 20, samples: Optional[int] = None,
    truncation: Optional[Union[int, Tuple[int, int]]] = None, step: float = 0.02,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
    estimate_tol: float = 1e-7, max_unknowns: int = 3000, amplitude_dof: int = 0,
    estimate_points: bool = False, section_points: int = 200, tol: float = 0.0,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
    jac: Optional[Jacobian] = None,
) -> Dict[str, Any]: ...
def diagram(
    m: Matrix, c: Matrix, k: Matrix, g: Nonlinearity,
    f: Optional[Forcing], omega_from: float, omega_to: float, at: Sequence[float] = ...,
    n: int = 20, samples: Optional[int] = None,
    depth: int = 2, max_branches: int = 24,
    tori: bool = True, torus: Optional[Union[int, Tuple[int, int]]] = None, torus_points: int = 60,
    fold_scale: Optional[Tuple[float, float]] = ...,
    deflation_omegas: int = 6, max_amplitude: float = 10.0, amplitudes: int = 6,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
    step: float = 0.05, tol: float = 0.0,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
    jac: Optional[Jacobian] = None,
) -> Dict[str, Any]: ...
def event_sensitivity(
    family: Family, event: Dict[str, Any], p: float, amplitude_dof: int = 0,
    n: int = 20, samples: Optional[int] = None,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
) -> Dict[str, Any]: ...
def switch_branch(
    m: Matrix,
    c: Matrix,
    k: Matrix,
    g: Union[Callback, VectorizedCallback, Elements],
    f: Optional[Forcing],
    at: Dict[str, Any],
    to: float,
    n: int = 20,
    samples: Optional[int] = None,
    step: float = 0.05,
    ds: Optional[float] = None,
    ds_min: Optional[float] = None,
    ds_max: Optional[float] = None,
    max_points: Optional[int] = None,
    tol: float = 0.0,
    velocity_dependent: bool = True,
    vectorized: bool = False,
    rtol: float = 1e-9,
    max_iter: int = 100,
    jac: Optional[Jacobian] = None,
) -> Dict[str, Any]: ...

# Folds of limit cycles in two parameters (issue 27 item 1, crates/ivt-py/src/hb_cycle_fold.rs).
def cycle_fold_curve(
    family: Callable[[float, float], Any],
    nu_from: float, nu_to: float, mu_from: float, mu_to: float, at: Sequence[float] = ...,
    n: int = 20, samples: Optional[int] = None,
    velocity_dependent: bool = True, vectorized: bool = False, rtol: float = 1e-9, max_iter: int = 100,
    ds: Optional[float] = None, ds_min: Optional[float] = None, ds_max: Optional[float] = None, max_points: Optional[int] = None,
) -> Dict[str, Any]: ...
