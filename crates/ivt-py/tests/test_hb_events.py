"""Neimark–Sacker and branch points of `ivt.hb.frc(events=True)` against
independent references: scipy shooting (DOP853, rtol 1e-12) of the orbit,
its monodromy matrix from the variational equations, and brentq (xtol 1e-13)
on the test function. Both events are located by ivt on their extended
systems, so they must agree to far better than the path's step; 1e-8 is
asserted (measured 3e-14 and 7e-11)."""

import math
from typing import Callable, Tuple

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from ivt import hb

Rhs = Callable[[float, np.ndarray, float], np.ndarray]


def periodic_orbit(rhs: Rhs, y0: np.ndarray, w: float, extra: int) -> Tuple[np.ndarray, np.ndarray]:
    """Shooting for the 2π/ω-periodic orbit of a 1-DOF system whose `rhs`
    integrates (x, v), its 2×2 monodromy and `extra` further 2×2 variational
    blocks; returns the initial state and the final value of every block."""

    def flow(y: np.ndarray) -> np.ndarray:
        eye = np.tile(np.eye(2).ravel(), 1 + extra)
        s = solve_ivp(rhs, (0.0, 2 * math.pi / w), np.concatenate([y, eye]), args=(w,),
                      method="DOP853", rtol=1e-12, atol=1e-13)
        return s.y[:, -1]  # type: ignore[no-any-return]

    y = y0
    for _ in range(30):
        end = flow(y)
        dy = np.linalg.solve(end[2:6].reshape(2, 2) - np.eye(2), -(end[:2] - y))
        y = y + dy
        if np.linalg.norm(dy) < 1e-13:
            break
    return y, flow(y)[2:]


def initial_state(coeffs: np.ndarray, n: int, omega: float, dof: int = 0) -> np.ndarray:
    """(x(0), ẋ(0)) of DOF `dof` from DOF-major coefficients [a0, a1..an, b1..bn]."""
    q = np.asarray(coeffs).reshape(-1, 2 * n + 1)[dof]
    return np.array([q[0] / 2 + q[1 : n + 1].sum(), omega * np.sum(np.arange(1, n + 1) * q[n + 1 :])])


def test_neimark_sacker_of_forced_van_der_pol_against_scipy() -> None:
    """x'' − μ(1 − x²)x' + x = F cos ωt (μ = F = 0.2): below the entrainment
    band the periodic orbit loses stability through a complex pair on the unit
    circle near ω = 0.9453 (a Neimark–Sacker point); reference: the ω in
    [0.945, 0.9454] where max |eig Φ| = 1."""
    mu, force, n = 0.2, 0.2, 12

    def g(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
        return -mu * (1 - x**2) * v  # type: ignore[no-any-return]

    r = hb.frc(1.0, 0.0, 1.0, g, lambda th: force * math.cos(th), 0.6, 1.6, n=n, samples=32,
               vectorized=True)
    ns = [b for b in r["bifurcations"] if b["kind"] == "neimark_sacker"]
    assert len(ns) == 1 and ns[0]["located"], r["bifurcations"]
    mus = [complex(*m) for m in ns[0]["multipliers"]]
    assert all(abs(abs(m) - 1) < 1e-8 and abs(m.imag) > 0.1 for m in mus), mus

    def rhs(t: float, y: np.ndarray, w: float) -> np.ndarray:
        x, v = y[0], y[1]
        a = np.array([[0.0, 1.0], [-1.0 - 2 * mu * x * v, mu * (1 - x * x)]])
        return np.concatenate([[v, mu * (1 - x * x) * v - x + force * math.cos(w * t)],
                               (a @ y[2:].reshape(2, 2)).ravel()])

    state = {"y": initial_state(ns[0]["coeffs"], n, ns[0]["omega"])}

    def indicator(w: float) -> float:
        state["y"], blocks = periodic_orbit(rhs, state["y"], w, 0)
        return float(np.max(np.abs(np.linalg.eigvals(blocks.reshape(2, 2)))) - 1)

    ref = brentq(indicator, 0.945, 0.9454, xtol=1e-13)
    assert abs(ns[0]["omega"] - ref) < 1e-8, (ns[0]["omega"], ref)


def test_symmetry_breaking_branch_point_against_scipy() -> None:
    """Two equal Duffing oscillators x_i'' + c x_i' + x_i + x_i³ + κ(x_i − x_j)
    = F cos ωt (c = 0.02, κ = 0.05, F = 0.1): on the symmetric orbit x₁ = x₂
    (a single Duffing) the antisymmetric perturbation obeys
    y'' + c y' + (1 + 2κ + 3x²) y = 0, and where its multiplier passes +1 an
    asymmetric branch bifurcates (a pitchfork: a branch point of the FRC, not
    a fold). Reference: the root of det(Φ_a − I) along the scipy orbit."""
    c, kappa, force, n = 0.02, 0.05, 0.1, 12
    m = np.eye(2)
    k = np.array([[1 + kappa, -kappa], [-kappa, 1 + kappa]])

    def g(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
        return x**3  # type: ignore[no-any-return]

    r = hb.frc(m, c * m, k, g, lambda th: [force * math.cos(th)] * 2, 0.5, 2.5, n=n, samples=32,
               vectorized=True, velocity_dependent=False)
    bps = [b for b in r["bifurcations"] if b["kind"] == "branch_point" and b["located"]]
    assert len(bps) >= 1, r["bifurcations"]
    bp = bps[0]
    q = np.asarray(bp["coeffs"]).reshape(2, 2 * n + 1)
    # On the symmetric orbit, to the locator's accuracy: its Newton stops once
    # the step is below 1e-8 relative (LocateOptions.noise_tol) and the
    # residual no longer falls; measured 1.0e-10.
    assert np.max(np.abs(q[0] - q[1])) < 1e-8 * np.max(np.abs(q))

    def rhs(t: float, y: np.ndarray, w: float) -> np.ndarray:
        x, v = y[0], y[1]
        sym = np.array([[0.0, 1.0], [-1.0 - 3 * x * x, -c]])
        anti = np.array([[0.0, 1.0], [-1.0 - 2 * kappa - 3 * x * x, -c]])
        return np.concatenate([[v, -c * v - x - x**3 + force * math.cos(w * t)],
                               (sym @ y[2:6].reshape(2, 2)).ravel(),
                               (anti @ y[6:].reshape(2, 2)).ravel()])

    state = {"y": initial_state(bp["coeffs"], n, bp["omega"])}

    def indicator(w: float) -> float:
        state["y"], blocks = periodic_orbit(rhs, state["y"], w, 1)
        return float(np.linalg.det(blocks[4:].reshape(2, 2) - np.eye(2)))

    ref = brentq(indicator, bp["omega"] - 2e-3, bp["omega"] + 2e-3, xtol=1e-13)
    assert abs(bp["omega"] - ref) < 1e-8, (bp["omega"], ref)
