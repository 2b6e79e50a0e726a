"""ivt.hb's engine surface against independent references: the Rust element
library against the same system written as a Python g, the Duffing backbone
against its closed form (Jacobi elliptic period), period doublings of a
parametrically excited oscillator against scipy's monodromy matrix, and the
STHB string against `ivt hb string --json`."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import brentq
from scipy.special import ellipk

from ivt import hb

M = np.eye(2)
C = 0.02 * np.eye(2)
K = np.array([[2.0, -1.0], [-1.0, 2.0]])


def forcing(th: float) -> list:  # type: ignore[type-arg]
    return [0.1 * np.cos(th), 0.0]


def test_elements_equal_the_same_system_as_a_python_g() -> None:
    """Cubic spring on DOF 0, quadratic damper on DOF 1 and tanh friction
    between the DOFs, as Rust elements and as a vectorized Python g: the same
    orbit (both stop at ‖r‖ ≤ 1e-9·‖f̂‖; the orbits then differ by about that
    times the conditioning, 1e-7 allows 100) and multipliers."""
    el = (hb.elements.cubic_spring(0.5, dof=0) + hb.elements.quadratic_damper(0.05, dof=1)
          + hb.elements.coulomb(0.02, 0.05, dof=0, to=1))
    assert len(el) == 3

    def g(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
        fr = 0.02 * np.tanh((v[:, 0] - v[:, 1]) / 0.05)
        out = np.zeros_like(x)
        out[:, 0] = 0.5 * x[:, 0] ** 3 + fr
        out[:, 1] = 0.05 * v[:, 1] * np.abs(v[:, 1]) - fr
        return out

    for w in (0.6, 1.1, 1.8):
        a = hb.solve(M, C, K, el, w, f=forcing, n=15)
        b = hb.solve(M, C, K, g, w, f=forcing, n=15, vectorized=True)
        scale = np.max(np.abs(b["coeffs"]))
        assert np.max(np.abs(a["coeffs"] - b["coeffs"])) < 1e-7 * scale, w
        np.testing.assert_allclose(a["floquet"], b["floquet"], rtol=0, atol=1e-6)


def test_elements_chain_frc_folds_equal_the_python_g_folds() -> None:
    """The 2-DOF cubic chain FRC with g = cubic_spring(0.5) and with the
    vectorized Python g: the same two located folds (each converged on the
    extended system to a relative step of 1e-11; 1e-9 allows the rounding
    difference of the two evaluations of g)."""

    def g(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
        out = np.zeros_like(x)
        out[:, 0] = 0.5 * x[:, 0] ** 3
        return out

    a = hb.frc(M, C, K, hb.elements.cubic_spring(0.5), forcing, 0.5, 1.6, n=15)
    b = hb.frc(M, C, K, g, forcing, 0.5, 1.6, n=15, vectorized=True, velocity_dependent=False)
    wa = [fd["omega"] for fd in a["folds"]]
    wb = [fd["omega"] for fd in b["folds"]]
    assert len(wa) == 2 and all(fd["located"] for fd in a["folds"])
    np.testing.assert_allclose(wa, wb, rtol=0, atol=1e-9)
    # events=False: the fast path (folds only), the same folds.
    fast = hb.frc(M, C, K, hb.elements.cubic_spring(0.5), forcing, 0.5, 1.6, n=15, events=False)
    np.testing.assert_allclose([fd["omega"] for fd in fast["folds"]], wa, rtol=0, atol=1e-9)
    assert [e["kind"] for e in fast["bifurcations"]] == ["fold", "fold"]


def test_duffing_backbone_against_the_elliptic_closed_form() -> None:
    """u'' + u + ε u³ = 0 oscillates with ω(A) = π √(1 + εA²) / (2 K(m)),
    m = εA² / (2(1 + εA²)), A = u(0) the peak (b1 = 0 puts it at τ = 0). With
    n = 20 harmonics the HB frequency is exact to ~1e-12 up to εA² = 4; 1e-9
    relative. The unfolding damping κ is zero on a conservative system."""
    eps = 1.0
    # The cubic spring as a Rust element, then as a Python g.
    for g in (hb.elements.cubic_spring(eps), lambda x, v, th: eps * x**3):
        bb = hb.backbone(1.0, 0.0, 1.0, g, 1.0, [1.0], 0.01, 2.0, velocity_dependent=False)
        assert bb["termination"] == "left_interval"
        assert bb["amplitude"][0] == pytest.approx(0.01, abs=1e-12) and bb["amplitude"][-1] >= 2.0
        assert len(bb["points"]) > 10
        for p in bb["points"]:
            a = float(hb.eval_series(p["coeffs"], 0.0))
            mm = eps * a * a / (2 * (1 + eps * a * a))
            exact = np.pi * np.sqrt(1 + eps * a * a) / (2 * ellipk(mm))
            assert p["omega"] == pytest.approx(exact, rel=1e-9), a
        assert np.max(np.abs(bb["kappa"])) < 1e-8
    with pytest.raises(ValueError, match="undamped"):
        hb.backbone(1.0, 0.1, 1.0, hb.elements.cubic_spring(eps), 1.0, [1.0])
    with pytest.raises(ValueError, match="mode"):
        hb.backbone(1.0, 0.0, 1.0, hb.elements.cubic_spring(eps), 1.0, [1.0, 0.0])


def mathieu_pd_reference(c: float, beta: float, lo: float, hi: float) -> float:
    """ω where a Floquet multiplier of x'' + c x' + (1 + β cos ωt) x = 0 is −1:
    the root of det(Φ(2π/ω) + I) in [lo, hi], Φ integrated by DOP853 (rtol
    1e-12), the root by brentq (xtol 1e-13)."""

    def indicator(w: float) -> float:
        def rhs(t: float, y: np.ndarray) -> np.ndarray:
            phi = y.reshape(2, 2)
            a = np.array([[0.0, 1.0], [-(1 + beta * np.cos(w * t)), -c]])
            return (a @ phi).ravel()

        sol = solve_ivp(rhs, (0.0, 2 * np.pi / w), np.eye(2).ravel(), method="DOP853",
                        rtol=1e-12, atol=1e-14)
        return float(np.linalg.det(sol.y[:, -1].reshape(2, 2) + np.eye(2)))

    return float(brentq(indicator, lo, hi, xtol=1e-13))


def test_frc_locates_period_doublings_against_scipy_monodromy() -> None:
    """The trivial orbit of x'' + 0.05x' + (1 + 0.4 cos θ)x + x³ = 0 loses and
    regains stability at the edges of the principal parametric resonance
    (ω ≈ 2), a multiplier through −1. `frc` lists both as located period
    doublings within 1e-8 of the scipy reference, with μ = −1 to 1e-8."""
    c, beta = 0.05, 0.4

    def g(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
        return beta * np.cos(th)[:, None] * x + x**3  # type: ignore[no-any-return]

    r = hb.frc(1.0, c, 1.0, g, None, 1.6, 2.4, n=10, samples=32, vectorized=True,
               velocity_dependent=False, tol=1e-12)
    pds = [b for b in r["bifurcations"] if b["kind"] == "period_doubling"]
    assert len(pds) == 2 and all(b["located"] for b in pds), r["bifurcations"]
    refs = [mathieu_pd_reference(c, beta, 1.7, 1.9), mathieu_pd_reference(c, beta, 2.1, 2.3)]
    for b, ref in zip(pds, refs):
        assert abs(b["omega"] - ref) < 1e-8, (b["omega"], ref)
        assert min(abs(complex(*mu) + 1) for mu in b["multipliers"]) < 1e-8
    stable = [p["stable"] for p in r["points"]]
    assert stable[0] and stable[-1] and not all(stable)


def test_string_equals_cli(cli) -> None:  # type: ignore[no-untyped-def]
    """`ivt.hb.string` is `ivt hb string --json` (the same Rust function): the
    same points to 1e-12 (JSON float formatting only) and the same counts."""
    args = dict(modes=3, harmonics=7, ns=32, ms=64, from_=1.0, to=3.0)
    got = hb.string(**args)  # type: ignore[arg-type]
    ref = cli("hb", "string", "--modes", "3", "--harmonics", "7", "--ns", "32", "--ms", "64",
              "--from", "1", "--to", "3")
    assert set(got) == set(ref) - {"boundary_note"}
    assert (got["jacobians"], got["hill_calls"], got["stop"]) == (ref["jacobians"], ref["hill_calls"], ref["stop"])
    assert len(got["points"]) == len(ref["points"]) > 10
    for p, q in zip(got["points"], ref["points"]):
        assert (p["stable"], p["kind"], p["method"]) == (q["stable"], q["kind"], q["method"])
        np.testing.assert_allclose([p["omega"], p["norm"], p["max_multiplier"]],
                                   [q["omega"], q["norm"], q["max_multiplier"]], rtol=1e-12)
    with pytest.raises(ValueError, match="`boundary`"):
        hb.string(boundary="free")
    with pytest.raises(ValueError, match="`from_`"):
        hb.string(from_=3.0, to=1.0)
    with pytest.raises(ValueError, match="`kd`"):
        hb.string(kd=float(2**63))
    with pytest.raises(hb.ConvergenceError):  # accepted, but Hill's method fails on the way
        hb.string(kd=1e8)


def test_bad_elements_are_named() -> None:
    with pytest.raises(ValueError, match="element 0"):
        hb.solve(1.0, 0.1, 1.0, hb.elements.coulomb(0.1, 0.0), 1.0, f=lambda th: np.cos(th))
    with pytest.raises(ValueError, match="element 1"):
        hb.solve(M, C, K, hb.elements.cubic_spring(1.0) + hb.elements.cubic_spring(1.0, dof=2), 1.0,
                 f=forcing)
    with pytest.raises(ValueError, match="`dof`"):
        hb.elements.clearance(0.1, 10.0, dof=-1)
    with pytest.raises(TypeError, match="`g`"):
        hb.solve(1.0, 0.1, 1.0, 3.0, 1.0)  # type: ignore[arg-type]
