"""Every Python function that follows a path takes the same continuation
keywords, `ds`, `ds_min`, `ds_max` and `max_points`, each None by default
(the path's own steps, stated in its docstring), and the accuracy keywords
`n` and `samples` (`samples=None` derives N from n; the string's STHB
discretization is `harmonics`, `ms`). Each keyword reaches its path:
`max_points` cuts every path short (termination "max_points"), `ds_max`
changes the number of points, and a bad step is refused by name before any
work (issue 40, Options)."""

import inspect

import numpy as np
import pytest
import scipy.sparse as sp

from ivt import hb

STEPS = ("ds", "ds_min", "ds_max", "max_points")
PATHS = ["frc", "duffing_frc", "duffing_folds", "continue_bifurcation", "cycle_branch",
         "cycle_fold_curve", "neimark_sacker_points", "backbone", "damped_modes",
         "torus_branch", "diagram", "switch_branch", "string", "mathieu_cascade"]

DUFFING = (1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0), lambda th: 0.1 * np.cos(th))
UNDAMPED = (1.0, 0.0, 1.0, hb.elements.cubic_spring(1.0))


def _vdp(mu):
    return ([[1.0]], [[-mu]], [[1.0]], lambda x, v, th: x * x * v)


def _forced_vdp(force):
    return (1.0, -0.2, 1.0, lambda x, v, th: 0.2 * x * x * v, lambda th: force * np.cos(th))


def _cycle_family(mu, nu):
    return (1.0, -mu, 1.0, lambda x, v, th: -(nu * x * x - x**4) * v, None)


def _duffing_family(force):
    return (1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0), lambda th: force * np.cos(th))


def _fold_start():
    frc = hb.frc(*_duffing_family(0.1), 0.5, 2.5, n=9)
    return max(frc["folds"], key=lambda b: b["omega"])


def _chain():
    k = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    return sp.identity(2, format="csr"), 0.02 * k, k


@pytest.mark.parametrize("name", PATHS)
def test_every_path_function_has_the_same_continuation_and_accuracy_keywords(name):
    params = inspect.signature(getattr(hb, name)).parameters
    for key in STEPS:
        assert key in params and params[key].default is None, (name, key)
    assert "step_max" not in params
    if name != "string":
        # The cascade keeps §3.2.5's n = 12 (its orbits double it with each period).
        n = 12 if name == "mathieu_cascade" else 20
        assert params["n"].default == n and params["samples"].default is None, name


def test_event_sensitivity_is_no_path_and_takes_no_steps():
    params = inspect.signature(hb.event_sensitivity).parameters
    assert not set(STEPS) & set(params)


# Each path with a few points' budget. Curves of two legs (the codim-2 ones,
# and the cycle branch when it turns back past its start) spend it per leg.
CUT = {
    "frc": lambda k: hb.frc(*DUFFING, 0.2, 3.0, n=8, max_points=k),
    "frc (condensed)": lambda k: hb.frc(*_chain(), lambda x, v, th: 0.5 * x**3,
                                        np.array([0.1, 0.0]), 0.5, 1.5, nonlinear_dofs=[0],
                                        stability=False, truncation_estimate=False, max_points=k),
    "duffing_frc": lambda k: hb.duffing_frc(n=8, max_points=k),
    "duffing_folds": lambda k: hb.duffing_folds(n=9, max_points=k),
    "continue_bifurcation": lambda k: hb.continue_bifurcation(
        _duffing_family, _fold_start(), 0.0, 0.3, p_start=0.1, n=9, max_points=k),
    "cycle_branch": lambda k: hb.cycle_branch(_vdp, -0.2, 2.5, n=10, samples=32, max_points=k),
    "backbone": lambda k: hb.backbone(*UNDAMPED, 1.0, [1.0], n=8, max_points=k),
    "damped_modes": lambda k: hb.damped_modes(1.0, 0.02, 1.0, hb.elements.cubic_spring(1.0),
                                              0.01, 1.0, n=8, max_points=k),
    "diagram": lambda k: hb.diagram(*DUFFING, 0.5, 2.5, n=8, depth=0, tori=False,
                                    fold_scale=None, deflation_omegas=0, max_points=k),
    "string": lambda k: hb.string(max_points=k),
}


@pytest.mark.parametrize("name", CUT)
def test_max_points_cuts_every_path_short(name):
    out = CUT[name](6)
    points = out["branches"][0]["points"] if name == "diagram" else out["points"]
    end = out["branches"][0]["termination"] if name == "diagram" else out.get(
        "termination", out.get("stop"))
    assert end == "max_points", (name, end)
    legs = 2 if name in ("duffing_folds", "continue_bifurcation", "cycle_branch") else 1
    assert 2 <= len(points) <= 6 * legs, (name, len(points))


def test_max_points_reaches_the_curves_of_ns_points_switching_tori_and_cycle_folds():
    # The forced Van der Pol's Neimark–Sacker point lies at ω_f ≈ 0.945: five
    # points from 0.5 do not reach it. (g takes arrays: a scalar g costs the
    # multipliers of every point ~30 k Python calls, 35 s here, and the
    # keywords under test do not depend on it.)
    keys = dict(n=9, samples=32, vectorized=True)
    assert len(hb.neimark_sacker_points(_forced_vdp, [0.2], 0.5, 1.6, **keys)) == 1
    assert hb.neimark_sacker_points(_forced_vdp, [0.2], 0.5, 1.6, max_points=5, **keys) == []
    keys = dict(n=12, samples=32, vectorized=True)
    frc = hb.frc(*_forced_vdp(0.2), 0.6, 1.6, events=True, **keys)
    [ns] = [b for b in frc["bifurcations"] if b["kind"] == "neimark_sacker"]
    tor = hb.torus_branch(*_forced_vdp(0.2), ns, 0.89, max_points=4, **keys)
    assert tor["termination"] == "max_points" and len(tor["points"]) <= 4
    curve = hb.cycle_fold_curve(_cycle_family, 1.0, 0.45, -0.2, 0.1, n=25, samples=128,
                                vectorized=True, max_points=3)
    assert curve["termination"] == "max_points" and len(curve["points"]) <= 6


def test_the_cascade_takes_samples_and_steps_per_leg():
    # A leg cut short cannot reach its doubling: the error says how it ended.
    with pytest.raises(ValueError, match="period-1 branch never reached μ = −1: it ended "
                                         "with `max_points` after 4 points"):
        hb.mathieu_cascade(max_points=4)
    with pytest.raises(ValueError, match="`samples` = 12 must exceed `n` = 12"):
        hb.mathieu_cascade(samples=12)
    with pytest.raises(ValueError, match="`ds` = -1.0 must be finite and > 0"):
        hb.mathieu_cascade(ds=-1.0)
    # Twice the default samples and smaller steps: the same doublings (each
    # located on its extended system; 1e-14 apart, measured), and §3.2.5's
    # β1, β2, β4 printed to three decimals: within 1e-3 (as tests/mathieu.rs).
    base = hb.mathieu_cascade()
    fine = hb.mathieu_cascade(samples=96, ds_max=0.02)
    assert np.allclose(base["period_doubling_beta"], fine["period_doubling_beta"], atol=1e-10)
    assert np.allclose(fine["period_doubling_beta"], [4.825, 5.194, 5.253], atol=1e-3)
    # N = n + 1 aliases the cubic term (exact from N = 2n): the samples reach the AFT.
    aliased = hb.mathieu_cascade(samples=13)["period_doubling_beta"]
    assert 1e-9 < abs(aliased[0] - base["period_doubling_beta"][0]) < 1e-6, aliased


def test_max_points_reaches_the_switched_branch():
    # The twin-well Duffing of tests/test_hb_switch.py about its well.
    well = (1.0, 0.1, 2.0, lambda x, v, th: x * x * (3.0 + x), lambda th: 0.5 * np.cos(th))
    keys = dict(n=10, samples=32, velocity_dependent=False, vectorized=True)
    frc = hb.frc(*well, 3.6, 2.2, **keys)
    pd = next(e for e in frc["bifurcations"] if e["kind"] == "period_doubling")
    full = hb.switch_branch(*well, at=pd, to=2.2, **keys)
    cut = hb.switch_branch(*well, at=pd, to=2.2, max_points=4, **keys)
    assert full["termination"] == "left_interval" and len(full["points"]) > 4
    assert cut["termination"] == "max_points" and len(cut["points"]) <= 4


def test_ds_max_sets_the_step_and_ds_the_first_one():
    base = hb.duffing_frc(n=8)
    fine = hb.duffing_frc(n=8, ds_max=0.02)
    assert base["termination"] == fine["termination"] == "left_interval"
    assert len(fine["points"]) > 3 * len(base["points"]), (len(base["points"]), len(fine["points"]))
    # The same folds either way (each located on its extended system).
    assert np.allclose(base["folds"], fine["folds"], atol=1e-9)
    # A first step of 1e-3 in (q, ω_f) against the path's 0.05.
    assert np.diff(hb.duffing_frc(n=8, ds=1e-3, max_points=2)["omega"])[0] <= 1e-3
    assert np.diff(base["omega"])[0] > 1e-2


@pytest.mark.parametrize("call", [
    lambda **kw: hb.frc(*DUFFING, 0.2, 3.0, n=8, **kw),
    lambda **kw: hb.duffing_frc(n=8, **kw),
    lambda **kw: hb.backbone(*UNDAMPED, 1.0, [1.0], n=8, **kw),
    lambda **kw: hb.cycle_branch(_vdp, -0.2, 2.5, n=10, samples=32, **kw),
    lambda **kw: hb.duffing_folds(n=9, **kw),
    lambda **kw: hb.string(**kw),
], ids=["frc", "duffing_frc", "backbone", "cycle_branch", "duffing_folds", "string"])
def test_bad_steps_are_refused_by_name(call):
    with pytest.raises(ValueError, match=r"`ds` = -1\.0 must be finite and > 0"):
        call(ds=-1.0)
    with pytest.raises(ValueError, match=r"`ds_max` = nan must be finite and > 0|`ds_max` = NaN"):
        call(ds_max=float("nan"))
    with pytest.raises(ValueError, match="`ds_min` = 0.5 exceeds"):
        call(ds_min=0.5, ds=0.01)
    with pytest.raises(ValueError, match="`max_points` must be ≥ 1"):
        call(max_points=0)
    with pytest.raises(ValueError, match="max_points"):
        call(max_points=-3)
