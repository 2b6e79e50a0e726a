"""`ivt.hb.switch_branch` (issue 27 item 2) and the CLI commands of issue 27
(`ivt hb switch`, `cycle-branch`, `all-solutions`): the Python dict and
`ivt hb X --json` hold the same keys and values (one Rust job each), and the
switched branches are checked by RK4 integration (no HB): the period-2
branch of a forced Duffing oscillator in a well returns after 2T but not
after T; the symmetry-breaking branch of a symmetric 2-DOF chain is a
periodic orbit with x1 != x2."""

import math
from typing import Any, Callable, Dict, List

import numpy as np
import pytest

from ivt import hb
from test_hb_jobs import same


def well_g(x: Any, v: Any, th: Any) -> Any:
    """x^2 (3 + x): the twin-well Duffing about its well (x = u - 1); all
    samples at once (`vectorized`), each with the CLI's arithmetic."""
    return x * x * (3.0 + x)


def well_f(th: float) -> float:
    return 0.5 * math.cos(th)


WELL = dict(n=10, samples=32, velocity_dependent=False, vectorized=True)


def well_event(kind: str) -> Dict[str, Any]:
    curve = hb.frc(1.0, 0.1, 2.0, well_g, well_f, 3.6, 2.2, **WELL)  # type: ignore[arg-type]
    return next(e for e in curve["bifurcations"] if e["kind"] == kind)


def rk4(rhs: Callable[[float, List[float]], List[float]], y: List[float], t_end: float,
        steps: int) -> List[float]:
    """Classical RK4 from t = 0 (plain Python floats, no HB code)."""
    h = t_end / steps
    for i in range(steps):
        t = i * h
        k1 = rhs(t, y)
        k2 = rhs(t + h / 2, [a + h / 2 * b for a, b in zip(y, k1)])
        k3 = rhs(t + h / 2, [a + h / 2 * b for a, b in zip(y, k2)])
        k4 = rhs(t + h, [a + h * b for a, b in zip(y, k3)])
        y = [a + h / 6 * (p + 2 * q + 2 * r + s) for a, p, q, r, s in zip(y, k1, k2, k3, k4)]
    return y


def state(coeffs: Any, w: float) -> List[float]:
    """(x(0), x'(0)) of [a0, a1..an, b1..bn] at response frequency w."""
    c = np.asarray(coeffs)
    n = (len(c) - 1) // 2
    k = np.arange(1, n + 1)
    return [c[0] / 2 + c[1:n + 1].sum(), w * float((k * c[n + 1:]).sum())]


def test_switch_branch_equals_cli_and_is_period_two_by_rk4(
        cli: Callable[..., Dict[str, Any]]) -> None:
    pd = well_event("period_doubling")
    got = hb.switch_branch(1.0, 0.1, 2.0, well_g, well_f, at=pd, to=2.2,  # type: ignore[arg-type]
                           **WELL)
    ref = cli("hb", "switch", "--n", "10", "--samples", "32")
    same(got, ref)
    assert got["kind"] == "period_doubling" and got["subharmonic"] == 2
    assert got["start_omega"] == pd["omega"] and got["termination"] == "left_interval"
    # RK4 of x'' + 0.1x' + 2x + 3x^2 + x^3 = 0.5 cos wt from the HB state of a
    # point half-way: back after 2T (the HB orbit's truncation, n = 20 of w/2),
    # not after T.
    p = got["points"][len(got["points"]) // 2]
    w = p["omega"]

    def rhs(t: float, y: List[float]) -> List[float]:
        x, v = y
        return [v, 0.5 * math.cos(w * t) - 0.1 * v - 2 * x - 3 * x * x - x ** 3]

    y0 = state(p["coeffs"], w / 2)
    period = 2 * math.pi / w
    one = rk4(rhs, y0, period, 2000)
    two = rk4(rhs, y0, 2 * period, 4000)
    assert max(abs(a - b) for a, b in zip(two, y0)) < 1e-6, (two, y0)
    assert max(abs(a - b) for a, b in zip(one, y0)) > 1e-2, (one, y0)


def test_switch_branch_at_a_pitchfork_is_the_asymmetric_orbit_by_rk4() -> None:
    m, c = np.eye(2), 0.02 * np.eye(2)
    k = np.array([[1.1, 0.1], [0.1, 1.1]])

    def g(x: Any, v: Any, th: Any) -> Any:
        return x ** 3

    def f(th: float) -> List[float]:
        return [0.05 * math.cos(th), 0.05 * math.cos(th)]

    opts = dict(n=9, samples=32, velocity_dependent=False, vectorized=True)
    curve = hb.frc(m, c, k, g, f, 0.8, 1.1, **opts)  # type: ignore[arg-type]
    bp = next(e for e in curve["bifurcations"] if e["kind"] == "branch_point")
    with pytest.raises(ValueError, match="must lie on that side"):
        hb.switch_branch(m, c, k, g, f, at=bp, to=0.8, **opts)  # type: ignore[arg-type]
    new = hb.switch_branch(m, c, k, g, f, at=bp, to=1.1, **opts)  # type: ignore[arg-type]
    assert new["kind"] == "branch_point" and new["subharmonic"] == 1
    p = new["points"][-1]
    w, q = p["omega"], np.asarray(p["coeffs"])
    l = len(q) // 2
    assert np.abs(q[:l] - q[l:]).max() > 1e-2, "the new branch is the symmetric one"

    def rhs(t: float, y: List[float]) -> List[float]:
        x1, x2, v1, v2 = y
        fc = 0.05 * math.cos(w * t)
        return [v1, v2, fc - 0.02 * v1 - 1.1 * x1 - 0.1 * x2 - x1 ** 3,
                fc - 0.02 * v2 - 0.1 * x1 - 1.1 * x2 - x2 ** 3]

    (x1, v1), (x2, v2) = state(q[:l], w), state(q[l:], w)
    y0 = [x1, x2, v1, v2]
    back = rk4(rhs, y0, 2 * math.pi / w, 4000)
    assert max(abs(a - b) for a, b in zip(back, y0)) < 1e-6, (back, y0)


def test_switch_branch_refuses_folds_neimark_sacker_and_unlocated_events() -> None:
    fold = {"kind": "fold", "omega": 1.0, "coeffs": [0.0] * 21, "located": True}
    with pytest.raises(ValueError, match="fold"):
        hb.switch_branch(1.0, 0.1, 2.0, well_g, well_f, at=fold, to=2.2, **WELL)  # type: ignore[arg-type]
    ns = dict(fold, kind="neimark_sacker")
    with pytest.raises(ValueError, match="Neimark"):
        hb.switch_branch(1.0, 0.1, 2.0, well_g, well_f, at=ns, to=2.2, **WELL)  # type: ignore[arg-type]
    lost = dict(fold, kind="period_doubling", located=False, error="did not converge")
    with pytest.raises(ValueError, match="not located: did not converge"):
        hb.switch_branch(1.0, 0.1, 2.0, well_g, well_f, at=lost, to=2.2, **WELL)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="needs \"omega\""):
        hb.switch_branch(1.0, 0.1, 2.0, well_g, well_f, at={"kind": "branch_point"},  # type: ignore[arg-type]
                         to=2.2, **WELL)


def test_cycle_branch_equals_cli(cli: Callable[..., Dict[str, Any]]) -> None:
    """`ivt hb cycle-branch` builds M = 1, C = -mu, K = 1 and g with the
    arithmetic of this callback: the same problem, the same numbers."""
    def family(mu: float) -> Any:
        return (1.0, -mu, 1.0, lambda x, v, th: (x * x * (x * x) - x * x) * v, None)

    got = hb.cycle_branch(family, -0.2, 0.1, at=[-0.1])
    ref = cli("hb", "cycle-branch")
    same(got, ref)
    assert got["hopf"][0]["subcritical"] is True
    assert sorted(c["stable"] for c in got["at"]) == [False, True]


def test_all_solutions_equals_cli(cli: Callable[..., Dict[str, Any]]) -> None:
    """`ivt hb all-solutions` solves the thesis Duffing as this user system
    (M = 1, C = 2 xi, K = alpha, g = eps x^3, f = F cos) to its absolute
    `--tol` 1e-10."""
    got = hb.all_solutions(1.0, 0.04, 1.0, lambda x, v, th: 1.0 * x * x * x,
                           lambda th: 0.1 * math.cos(th), 1.4, velocity_dependent=False,
                           tol=1e-10, rtol=0.0)
    ref = cli("hb", "all-solutions")
    same(list(got), ref["solutions"], "solutions")
    same(got.search, ref["search"], "search")
    assert [s["stable"] for s in got] == [True, False, True]


def test_an_autonomous_family_may_return_four_items() -> None:
    """Issue 46: (m, c, k, g) is an unforced family, the same as (m, c, k, g, None)."""
    def g(x: Any, v: Any, th: float) -> Any:
        return (x * x * (x * x) - x * x) * v

    def timeless(d: Any) -> Any:
        if isinstance(d, dict):
            return {k: timeless(v) for k, v in d.items() if k not in ("time_s", "solve_time_s")}
        if isinstance(d, (list, tuple)):
            return [timeless(v) for v in d]
        return d

    five = hb.cycle_branch(lambda mu: (1.0, -mu, 1.0, g, None), -0.2, 0.1, at=[-0.1])
    four = hb.cycle_branch(lambda mu: (1.0, -mu, 1.0, g), -0.2, 0.1, at=[-0.1])
    # The same problem: bit for bit.
    np.testing.assert_equal(timeless(four), timeless(five))
    assert len(four["hopf"]) == 1 and len(four["at"]) == 2
    with pytest.raises(TypeError, match=r"\(m, c, k, g\)"):
        hb.cycle_branch(lambda mu: (1.0, -mu, 1.0), -0.2, 0.1)
