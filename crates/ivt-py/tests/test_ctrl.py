"""ivt.ctrl.Controller against an independent float64 reference of the
thesis equations: angle-sampled averaging (§4.3), Eq. 158–160 and Eq. 180."""

import math

import numpy as np
import pytest

from ivt import ctrl

F_TIMER = 1.0e6


def pulse_ticks(ppr: int, n: int, omega0: float, depth: float) -> np.ndarray:
    """Timer counts of n encoder pulses for ω(θ) = ω0/(1 + depth·cos θ), whose
    time is t(θ) = (θ + depth·sin θ)/ω0 in closed form, rounded to ticks."""
    theta = np.arange(n) * 2 * np.pi / ppr
    t = 0.01 + (theta + depth * np.sin(theta)) / omega0
    return np.round(t * F_TIMER).astype(np.int64)


def r_ol_ref(preset: str, v_m: float, t_u: float) -> float:
    """Eq. 158–160 in float64 on a preset's coefficients, no clamping of inputs
    (test points lie inside 2 ≤ V_m ≤ 12, 1.5 ≤ T_U ≤ 9)."""
    c = ctrl.open_loop_preset(preset)
    poly = np.array(c["poly"], dtype=np.float64)
    r_f = sum(poly[i, j] * v_m**i * t_u**j for i in range(poly.shape[0]) for j in range(poly.shape[1]))
    b = c["boundary"]
    f_b = b[0] * v_m + b[1] * t_u + b[2]
    if f_b > 0 or r_f > 0.012:
        return 0.012
    return max(r_f, 0.0)


def test_open_loop_eval_matches_eq158_160() -> None:
    # f32 evaluation of a polynomial with terms up to ~0.1: abs error ~1e-8 m.
    for v_m, t_u in [(8.0, 8.0), (6.0, 6.0), (4.0, 2.0), (11.0, 3.0), (3.0, 9.0)]:
        got = ctrl.open_loop_eval(v_m, t_u, "thesis")
        assert got["r_ol"] == pytest.approx(r_ol_ref("thesis", v_m, t_u), abs=2e-8), (v_m, t_u)
        assert got["f_b"] == pytest.approx(v_m - 1.579 * t_u - 0.632, abs=1e-5)
    assert ctrl.open_loop_eval(11.0, 3.0, "thesis")["ol_region"] == "over_drive"
    assert ctrl.open_loop_eval(20.0, 3.0)["inputs_clamped"] is True


def test_refit_is_the_default_open_loop_law() -> None:
    # REFIT's terms reach ~1 and cancel to ~1e-2 (ivt-ctrl's rounding-bound
    # test: f32 error < 1e-6 m over the grid); inside the band at 100 rpm
    # (V_m ∈ [7.87, 7.87 + 0.154·T_U]) the law is between 0 and r_max.
    for v_m, t_u in [(8.0, 2.0), (8.4, 6.0), (8.9, 8.0), (8.6, 7.0)]:
        got = ctrl.open_loop_eval(v_m, t_u)
        assert got["r_ol"] == pytest.approx(r_ol_ref("refit", v_m, t_u), abs=1e-6), (v_m, t_u)
        assert got["ol_region"] == "normal" and 0.0 < got["r_ol"] < 0.012
    assert ctrl.Controller(100).config()["open_loop"] == ctrl.open_loop_preset("refit")
    with pytest.raises(ValueError, match="'refit'"):
        ctrl.open_loop_eval(8.0, 6.0, "printed")


@pytest.mark.parametrize("ppr", [100, 1200])
def test_delay_law_against_float64_reference(ppr: int) -> None:
    omega0 = 100 * 2 * np.pi / 60
    k, k2 = ctrl.thesis_gains(0.06, 0.12)
    c = ctrl.Controller(ppr, f_timer_hz=F_TIMER, omega0=omega0, k=k, k2=k2, law="delay")
    n = 6 * ppr
    ticks = pulse_ticks(ppr, n, omega0 * 0.97, 0.1)
    out = c.on_pulses(ticks)
    assert set(out) >= {"omega", "omega_a", "omega_T", "r_ol", "r_d", "r", "fault"}

    t = ticks.astype(np.float64)
    dth = 2 * np.pi / ppr
    ready = np.arange(n) >= ppr + 1
    idx = np.nonzero(ready)[0]
    omega = dth * F_TIMER / (t[idx] - t[idx - 1])
    omega_a = 2 * np.pi * F_TIMER / (t[idx] - t[idx - ppr])
    omega_t = dth * F_TIMER / (t[idx - ppr] - t[idx - ppr - 1])
    # f32 speeds from integer tick differences: relative error ≤ a few ulp (1e-7).
    np.testing.assert_allclose(out["omega"][idx], omega, rtol=1e-6)
    np.testing.assert_allclose(out["omega_a"][idx], omega_a, rtol=1e-6)
    np.testing.assert_allclose(out["omega_T"][idx], omega_t, rtol=1e-6)
    assert np.all(out["omega_a"][~ready][: ppr] == 0.0)

    # Eq. 180 integrated per pulse with the anti-windup clamp of ivt-ctrl's docs.
    r_ol = ctrl.open_loop_eval(8.0, 8.0)["r_ol"]  # default law at Config.initial_inputs
    r_d, ref = 0.0, []
    for w, wa, wt in zip(omega, omega_a, omega_t):
        r_d += (k * (wa - omega0) + k2 * (w - wt)) * dth
        r_d = min(max(r_d, -r_ol), 0.012 - r_ol)
        ref.append(r_d)
    # f32 state over ≤ 7200 Kahan-compensated increments vs f64: the increments
    # themselves carry the f32 speed error (1e-6 relative) → 1e-6·|r_d| + 1e-9 m.
    np.testing.assert_allclose(out["r_d"][idx], ref, rtol=2e-5, atol=1e-9)
    np.testing.assert_allclose(out["r"][idx], np.clip(r_ol + np.array(ref), 0, 0.012), atol=1e-8)
    assert np.all(out["fault"] == 0)


def test_pulse_by_pulse_equals_batch_and_step_tick() -> None:
    ticks = pulse_ticks(100, 400, 10.0, 0.05)
    a, b = ctrl.Controller(100), ctrl.Controller(100)
    # (8.4 V, 6 N·m) lies inside the band at 100 rpm: the default (REFIT)
    # u_ol is 6.85 mm there (7 V would be under-drive: u_ol = 0, no move).
    batch = b.on_pulses(ticks, v_m=np.full(400, 8.4), t_u=np.full(400, 6.0))
    for i, tk in enumerate(ticks):
        a.update_inputs(8.4, 6.0)
        o = a.on_pulse(int(tk))
        assert o["r"] == batch["r"][i] and o["omega_a"] == batch["omega_a"][i]
    st = a.step_tick(int(ticks[-1]) + 10)
    assert set(st) == {"step", "forward", "position", "next_step_at", "moving", "fault", "fault_name"}
    assert st["moving"] and st["forward"]  # stepper heads from 0 towards r > 0


def test_faults_stall_short_interval_invalid_input() -> None:
    c = ctrl.Controller(100, stall_timeout_s=0.5)
    c.on_pulse(0)
    c.on_pulse(10_000)
    assert c.on_pulse(10_000)["fault_name"] == "interval_too_short"
    assert c.update_inputs(float("nan"), 5.0)["fault"] == 3
    assert c.step_tick(10_000 + 600_000)["fault_name"] == "stall"
    assert c.output()["r"] == 0.0  # safe_r
    assert ctrl.FAULTS[1] == "stall"


def test_config_errors_name_the_keyword() -> None:
    with pytest.raises(ValueError, match="`ppr` = 7"):
        ctrl.Controller(7)
    with pytest.raises(ValueError, match="`f_timer_hz`"):
        ctrl.Controller(100, f_timer_hz=-1.0)
    with pytest.raises(ValueError, match="`omega_max`"):
        ctrl.Controller(100, omega_max=float("nan"), k=1e-5)
    with pytest.raises(ValueError, match="`law`"):
        ctrl.Controller(100, law="pid")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="`open_loop`"):
        ctrl.Controller(100, open_loop={"r_max": -1.0})
    with pytest.raises(TypeError, match="unknown open_loop key"):
        ctrl.Controller(100, open_loop={"rmax": 0.01})
    with pytest.raises(ValueError, match=r"`ticks`\[0\] = 0.5 is not a whole timer count"):
        ctrl.Controller(100).on_pulses(np.array([0.5, 1.5]))
    with pytest.raises(TypeError, match="`ticks`"):
        ctrl.Controller(100).on_pulses(np.array(["a", "b"]))
    with pytest.raises(ValueError, match=r"`ticks`\[1\] = -3"):
        ctrl.Controller(100).on_pulses([0, -3])
    with pytest.raises(ValueError, match="`v_m` has 1 entries"):
        ctrl.Controller(100).on_pulses([0, 1], v_m=[1.0], t_u=[1.0])
    # Counts out of range are ValueErrors naming the argument (not pyo3's
    # unnamed OverflowError).
    with pytest.raises(ValueError, match="`ticks` = 4294967296"):
        ctrl.Controller(100).on_pulse(2**32)
    with pytest.raises(ValueError, match="`ppr` = -1"):
        ctrl.Controller(-1)
    with pytest.raises(ValueError, match="`decimation` = -1"):
        ctrl.Controller(100, decimation=-1)
    with pytest.raises(ValueError, match="`now` = -1"):
        ctrl.Controller(100).step_tick(-1)


def test_on_pulses_takes_float_inputs_and_whole_float_ticks() -> None:
    """`v_m`/`t_u` as floats are held for every pulse (the stub's ArrayLike);
    ticks as a float array of whole counts (numpy.loadtxt) are the same
    counts: both equal the integer/array call exactly."""
    ticks = pulse_ticks(100, 200, 10.0, 0.05)
    ref = ctrl.Controller(100).on_pulses(ticks, v_m=np.full(200, 8.4), t_u=np.full(200, 6.0))
    got = ctrl.Controller(100).on_pulses(ticks.astype(np.float64), v_m=8.4, t_u=6.0)
    for key in ref:
        np.testing.assert_array_equal(got[key], ref[key], err_msg=key)


def test_config_roundtrip_and_presets() -> None:
    c = ctrl.Controller(1200, omega0_rpm=90.0, law="nodelay", decimation=2)
    cfg = c.config()
    assert cfg["omega0"] == pytest.approx(90 * 2 * np.pi / 60, rel=1e-6)
    assert cfg["law"] == "nodelay" and cfg["decimation"] == 2 and c.ppr == 1200
    assert c.r_max == pytest.approx(0.012)
    assert ctrl.thesis_gains(0.01, 0.02) == pytest.approx((1e-5, 2e-5))
    assert 1200 in ctrl.SUPPORTED_PPR
    assert "nodelay" in repr(c)
