"""ivt.hb against independent references: scipy time integration of the
ODE and of its variational equation (Floquet multipliers), closed-form linear
responses, the classic IHB, and the CLI's `ivt hb duffing --json`."""

import threading
import time

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import ivt
from ivt import hb


def duffing_rhs(xi: float, alpha: float, eps: float, force: float, w: float):  # type: ignore[no-untyped-def]
    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        u, v = y[0], y[1]
        # variational part: d/dt Φ = A(t) Φ with A = [[0, 1], [−α − 3εu², −2ξ]]
        phi = y[2:].reshape(2, 2)
        a = np.array([[0.0, 1.0], [-alpha - 3 * eps * u * u, -2 * xi]])
        du = [v, force * np.cos(w * t) - 2 * xi * v - alpha * u - eps * u**3]
        return np.concatenate([du, (a @ phi).ravel()])

    return rhs


def test_duffing_against_time_integration_and_floquet() -> None:
    xi, alpha, eps, force, w = 0.02, 1.0, 1.0, 0.1, 0.4
    res = hb.duffing(n=20, samples=64, xi=xi, alpha=alpha, eps=eps, force=force, omega_f=w)
    assert set(res) >= {"coeffs", "floquet", "stable", "iterations", "residual_norm", "solve_time_s"}
    q = res["coeffs"]
    assert isinstance(q, np.ndarray) and q.shape == (41,) and res["residual_norm"] < 1e-10
    u0 = hb.eval_series(q, 0.0)
    v0 = w * hb.eval_series(q, 0.0, order=1)
    period = 2 * np.pi / w
    sol = solve_ivp(
        duffing_rhs(xi, alpha, eps, force, w), (0, period),
        np.array([u0, v0, 1, 0, 0, 1.0]), method="DOP853", rtol=1e-12, atol=1e-13, dense_output=True,
    )
    t = np.linspace(0, period, 200)
    # HB with n = 20 vs a tight integration from the HB initial state, over one period:
    # truncation of the series is ~1e-12 here, the integration ~1e-11 (issue 3: ≤ 1e-8).
    np.testing.assert_allclose(sol.sol(t)[0], hb.eval_series(q, w * t), rtol=0, atol=1e-8)
    mono = sol.y[2:, -1].reshape(2, 2)
    mu_ref = np.sort_complex(np.linalg.eigvals(mono))
    mu = np.sort_complex(np.array([complex(a, b) for a, b in res["floquet"]]))
    # Hsu with Magnus-4 steps to a Richardson estimate ≤ 1e-6 (6.1e-8 here,
    # 42 steps): the error against the variational ODE is within 2× of it.
    np.testing.assert_allclose(mu, mu_ref, rtol=0, atol=1e-6)
    assert np.max(np.abs(mu - mu_ref)) <= 2 * res["multiplier_error"] + 1e-10
    assert res["stable"] == bool(np.all(np.abs(mu_ref) < 1))


def test_modified_and_classic_agree() -> None:
    a = hb.duffing(omega_f=1.2, method="modified")
    b = hb.duffing(omega_f=1.2, method="classic")
    np.testing.assert_allclose(a["coeffs"], b["coeffs"], rtol=0, atol=1e-9)


def test_duffing_matches_cli(cli) -> None:  # type: ignore[no-untyped-def]
    ref = cli("hb", "duffing", "--n", "20", "--samples", "64", "--omega-f", "0.4")
    got = hb.duffing(n=20, samples=64, omega_f=0.4)
    np.testing.assert_allclose(got["coeffs"], ref["coeffs"], rtol=0, atol=1e-12)
    assert got["stable"] == ref["stable"]
    np.testing.assert_allclose(got["floquet"], ref["floquet"], rtol=0, atol=1e-9)


def test_general_solver_reproduces_duffing_and_linear_2dof() -> None:
    eps, force = 1.0, 0.1
    ref = hb.duffing(omega_f=0.4, stability=False)
    got = hb.solve(
        1.0, 0.04, 1.0, lambda x, v, th: eps * x**3, 0.4,
        f=lambda th: force * np.cos(th), velocity_dependent=False, stability=False,
    )
    np.testing.assert_allclose(got["coeffs"], ref["coeffs"], rtol=0, atol=1e-10)
    assert ref["stable"] is None and ref["floquet"] == []
    # 2 DOF, linear: x = Re(X e^{iωt}) with (K − ω²M + iωC) X = F exactly.
    m = np.array([[1.0, 0.0], [0.0, 2.0]])
    c = np.array([[0.1, -0.05], [-0.05, 0.1]])
    k = np.array([[3.0, -1.0], [-1.0, 2.0]])
    w = 0.9
    res = hb.solve(m, c, k, lambda x, v, th: np.zeros(2), w, f=lambda th: [np.cos(th), 0.0], n=3, samples=8)
    x = np.linalg.solve(k - w * w * m + 1j * w * c, np.array([1.0, 0.0]))
    q = res["coeffs"].reshape(2, 7)  # [a0, a1..a3, b1..b3] per DOF
    np.testing.assert_allclose(q[:, 1], x.real, atol=1e-12)
    np.testing.assert_allclose(q[:, 4], -x.imag, atol=1e-12)
    np.testing.assert_allclose(q[:, [0, 2, 3, 5, 6]], 0, atol=1e-12)
    assert res["stable"] is True  # damped linear system: |μ| = e^{−…} < 1


def test_mathieu_duffing_orbit_and_multipliers_against_time_integration() -> None:
    # Eq. 81 with the thesis parameters (ξ̂ = 0.125, α̂ = 1, γ = 1, Ω = 2) at β = 2:
    # a period-1 orbit from a guess near the well u = −1. Checked as an orbit of the
    # ODE over one period, and its multipliers against the variational equation.
    beta, xi, om = 2.0, 0.125, 2.0
    guess = np.zeros(41)
    guess[0] = -2.0
    res = hb.mathieu_duffing(beta, guess=guess)
    q = res["coeffs"]
    assert abs(q[0]) > 0.1  # left the trivial solution u = 0

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        u, v, phi = y[0], y[1], y[2:].reshape(2, 2)
        k = 1 + beta * np.sin(om * t) - 3 * u * u
        a = np.array([[0.0, 1.0], [k, -2 * xi]])
        du = [v, -2 * xi * v + (1 + beta * np.sin(om * t)) * u - u**3]
        return np.concatenate([du, (a @ phi).ravel()])

    y0 = [hb.eval_series(q, 0.0), om * hb.eval_series(q, 0.0, order=1), 1, 0, 0, 1]
    period = 2 * np.pi / om
    sol = solve_ivp(rhs, (0, period), y0, method="DOP853", rtol=1e-12, atol=1e-13, dense_output=True)
    t = np.linspace(0, period, 50)
    np.testing.assert_allclose(sol.sol(t)[0], hb.eval_series(q, om * t), atol=1e-8)
    mu_ref = np.sort_complex(np.linalg.eigvals(sol.y[2:, -1].reshape(2, 2)))
    mu = np.sort_complex(np.array([complex(a, b) for a, b in res["floquet"]]))
    # The multipliers' error is relative to max(1, |μ|) (μ ≈ −6.58 here): within
    # 2× of the stated estimate, itself at most 1e-6.
    np.testing.assert_allclose(mu, mu_ref, rtol=1e-6, atol=1e-6)
    relative = np.max(np.abs(mu - mu_ref) / np.maximum(1.0, np.abs(mu_ref)))
    assert 0.0 < res["multiplier_error"] <= 1e-6
    assert relative <= 2 * res["multiplier_error"] + 1e-10, (relative, res["multiplier_error"])
    assert res["stable"] == bool(np.all(np.abs(mu_ref) < 1))


def test_frc_folds_and_flags() -> None:
    frc = hb.duffing_frc(0.2, 3.0)
    omega, amp, stable = frc["omega"], frc["amplitude"], frc["stable"]
    assert len(frc["points"]) == len(omega) and set(frc["points"][0]) >= {"omega", "amplitude", "stable"}
    # Hardening peak: the path turns twice (two folds), and the branch between
    # them is unstable (a multiplier crosses +1 at each fold).
    assert len(frc["folds"]) == 2
    # Located by the extended system: the shooting folds (ivt-hb tests/frc.rs).
    assert frc["folds"] == pytest.approx([1.6548121, 1.1687244], abs=1e-7)
    assert (~stable).sum() > 0 and stable[0] and stable[-1]
    # Far below resonance, two-term perturbation balance: (α − ω²)A1 + ¾εA1³ = F and
    # (α − 9ω²)A3 = −εA1³/4 (cos³ = ¾cos + ¼cos 3); peak A1 + A3. The neglected
    # coupling (¾εA1²A3 in the first-harmonic balance) is ~3e-4 of A: tolerance 5e-4.
    roots = np.roots([0.75, 0.0, 1 - 0.2**2, -0.1])
    a1 = float(roots[np.abs(roots.imag) < 1e-12].real.max())
    a3 = -(a1**3 / 4) / (1 - 9 * 0.2**2)
    assert amp[0] == pytest.approx(a1 + a3, rel=5e-4)
    assert omega.min() <= 0.2 + 1e-9 and omega.max() >= 3.0 - 1e-9


def test_errors() -> None:
    with pytest.raises(ValueError, match="`samples` = 20"):
        hb.duffing(n=20, samples=20)
    with pytest.raises(ValueError, match="`xi`"):
        hb.duffing(xi=float("nan"))
    # limits before allocation: a ValueError naming the argument, not SIGABRT
    with pytest.raises(ValueError, match="`n` = 100000"):
        hb.duffing(n=100000, samples=200002)
    with pytest.raises(ValueError, match="`samples` = 4294967296"):
        hb.duffing(samples=4294967296)
    with pytest.raises(ValueError, match="`tol`"):
        hb.duffing(tol=float("inf"))
    # a negative count names its argument (pyo3's usize gave a bare OverflowError)
    with pytest.raises(ValueError, match="`n` = -1 must be >= 0"):
        hb.duffing(n=-1)
    with pytest.raises(ValueError, match="`subharmonic` = -2"):
        hb.mathieu_duffing(0.5, subharmonic=-2)
    with pytest.raises(ValueError, match="`order` = -1"):
        hb.eval_series([0.0, 1.0, 0.0], 0.5, order=-1)
    with pytest.raises(ValueError, match="`method`"):
        hb.duffing(method="newton")  # type: ignore[arg-type]
    with pytest.raises(ValueError):
        hb.duffing(omega_f=-1.0)
    with pytest.raises(ZeroDivisionError):
        hb.solve(1.0, 0.1, 1.0, lambda x, v, th: 1 / 0, 1.0)
    with pytest.raises(ValueError, match="returned 2 values"):
        hb.solve(1.0, 0.1, 1.0, lambda x, v, th: [0.0, 0.0], 1.0)
    with pytest.raises(ValueError, match="`k` must be square"):
        hb.solve(np.eye(2), np.eye(2), np.ones((2, 3)), lambda x, v, th: x, 1.0)
    with pytest.raises(TypeError, match="`g`"):
        hb.solve(1.0, 0.1, 1.0, 3.0, 1.0)  # type: ignore[arg-type]
    with pytest.raises(hb.ConvergenceError) as info:
        hb.solve(1.0, 0.1, 1.0, lambda x, v, th: 1e300 * x**3, 1.0, f=lambda th: np.cos(th))
    assert isinstance(info.value.history, list)


def test_gil_released_during_a_solve() -> None:
    """While a worker thread is inside a long Rust call, the main thread runs
    Python code. Handshake, no sleep: the worker takes its timestamp and sets
    an event just before the native call; the main thread wakes on the event
    and needs the GIL to take its own timestamp. With the GIL released it runs
    as soon as the worker is inside Rust (scheduling latency, milliseconds);
    with the GIL held it can run only after the call returns, so its delay is
    at least the whole call (0.7 s on a loaded 2-core machine). Wall-clock
    ratios between one and two threads are a benchmark (benches/bench_gil.py),
    not a test."""
    entering = threading.Event()
    stamps: dict = {}  # type: ignore[type-arg]

    def worker() -> None:
        stamps["before"] = time.perf_counter()
        entering.set()
        hb.duffing_frc(0.2, 3.0, n=GIL_CALL_N, samples=GIL_CALL_SAMPLES)
        stamps["after"] = time.perf_counter()

    th = threading.Thread(target=worker)
    th.start()
    assert entering.wait(timeout=60)
    t_main = time.perf_counter()  # needs the GIL
    th.join()
    call = stamps["after"] - stamps["before"]
    waited = t_main - stamps["before"]
    assert waited < 0.5 * call, f"main thread ran {waited:.4f} s into a {call:.4f} s call"


# A Duffing FRC long enough (≫ the 5 ms GIL switch interval and the
# scheduling latency of a loaded machine) for the handshake above.
GIL_CALL_N = 30
GIL_CALL_SAMPLES = 128


def chain_2dof():  # type: ignore[no-untyped-def]
    """The 2-DOF cubic chain: M = I, K = [[2, −1], [−1, 2]], C = 0.02 I,
    g = [0.5 x1³, 0], f = [0.1 cos θ, 0]."""
    m = np.eye(2)
    c = 0.02 * np.eye(2)
    k = np.array([[2.0, -1.0], [-1.0, 2.0]])

    def g(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
        out = np.zeros_like(x)
        out[:, 0] = 0.5 * x[:, 0] ** 3
        return out

    def f(th: float) -> list:  # type: ignore[type-arg]
        return [0.1 * np.cos(th), 0.0]

    return m, c, k, g, f


def shooting_fold_2dof(y0: np.ndarray, w0: float) -> float:
    """ω_f of the fold of the 2-DOF chain by shooting on scipy's DOP853
    (rtol 1e-12): unknowns (x(0), v(0), ω_f), residual [y(T) − y(0),
    det(Φ(T) − I)] with Φ the variational matrix; Newton with central
    differences, started from `y0`, `w0`."""
    m, c, k, _, _ = chain_2dof()

    def rhs(t: float, y: np.ndarray, w: float) -> np.ndarray:
        x, v, phi = y[:2], y[2:4], y[4:].reshape(4, 4)
        gx = np.array([0.5 * x[0] ** 3, 0.0])
        acc = np.array([0.1 * np.cos(w * t), 0.0]) - c @ v - k @ x - gx
        dg = np.array([[1.5 * x[0] ** 2, 0.0], [0.0, 0.0]])
        a = np.block([[np.zeros((2, 2)), np.eye(2)], [-(k + dg), -c]])
        return np.concatenate([v, acc, (a @ phi).ravel()])

    def residual(z: np.ndarray) -> np.ndarray:
        w = z[4]
        sol = solve_ivp(
            rhs, (0.0, 2 * np.pi / w), np.concatenate([z[:4], np.eye(4).ravel()]),
            method="DOP853", rtol=1e-12, atol=1e-14, args=(w,),
        )
        yt = sol.y[:, -1]
        phi = yt[4:].reshape(4, 4)
        return np.concatenate([yt[:4] - z[:4], [np.linalg.det(phi - np.eye(4))]])

    z = np.concatenate([y0, [w0]])
    for _ in range(20):
        r = residual(z)
        jac = np.empty((5, 5))
        for j in range(5):
            h = 1e-6 * max(abs(z[j]), 1e-2)
            zp, zm = z.copy(), z.copy()
            zp[j] += h
            zm[j] -= h
            jac[:, j] = (residual(zp) - residual(zm)) / (2 * h)
        step = np.linalg.solve(jac, -r)
        z += step
        if np.abs(step).max() < 1e-11:
            return float(z[4])
    raise AssertionError(f"shooting fold did not converge: {z}")


def test_2dof_chain_frc_folds_match_shooting_with_vectorized_g() -> None:
    m, c, k, g, f = chain_2dof()
    calls = {"n": 0}

    # The sample grids g sees: 128 residual samples; 2S on a stability grid of
    # S Hsu steps (S = 32·2^k, doubled per point until the multipliers meet
    # 1e-6, at most 4096); 4096 for the multipliers at a located event (2048
    # steps); 1 per call of a one-sample ∂g. Differencing ∂g stacks the
    # 2·n_dof = 4 perturbed copies of a grid into one call.
    grids = {128, 4096, 1} | {2 * 32 * 2**k for k in range(8)}
    shapes = {(n, 2) for n in grids} | {(4 * n, 2) for n in grids}

    def g_counted(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
        calls["n"] += 1
        assert x.shape in shapes, x.shape
        assert th.shape == (x.shape[0],)
        return g(x, v, th)  # type: ignore[no-any-return]

    frc = hb.frc(m, c, k, g_counted, f, 0.5, 1.6, n=15, samples=64,
                 velocity_dependent=False, vectorized=True)
    folds = frc["folds"]
    assert len(folds) == 2, [fd["omega"] for fd in folds]
    assert all(fd["located"] for fd in folds)
    assert [b["kind"] for b in frc["bifurcations"]] == ["fold", "fold"]
    p0 = frc["points"][0]
    assert set(p0) >= {"omega", "coeffs", "amplitude", "multipliers", "stable"}
    assert len(p0["coeffs"]) == 2 * 31
    for fd in folds:
        q = fd["coeffs"]
        x0 = hb.eval_series(q, 0.0, n_dof=2)
        v0 = fd["omega"] * hb.eval_series(q, 0.0, order=1, n_dof=2)
        ref = shooting_fold_2dof(np.concatenate([x0, v0]), fd["omega"])
        assert abs(fd["omega"] - ref) < 1e-6, (fd["omega"], ref)
    # Stability flips exactly at the folds: each change of the flag is at one
    # of the two path points next to a fold's turn.
    stable = frc["stable"]
    switches = [i for i in range(1, len(stable)) if stable[i] != stable[i - 1]]
    assert len(switches) == 2, switches
    for s, fd in zip(switches, folds):
        assert s in (fd["index"], fd["index"] + 1), (s, fd["index"])


def test_scaled_duffing_same_orbit_and_verdict() -> None:
    """x = L·u maps Duffing Eq. 49 to ẍ + 0.04ẋ + x + x³/L² = 0.1·L cos θ: the
    orbit is L times the unit one and the multipliers are the same. The middle
    (saddle) branch at ω ≈ 1.4, in micrometres and 10 nm, then a 1e8 scale."""
    ref = hb.duffing_frc(from_=0.2, to=3.0)
    mid = min((p for p in ref["points"] if p["stability"] == "fold"), key=lambda p: abs(p["omega"] - 1.4))
    mu_ref = mid["multipliers"][0]
    assert mu_ref[0] > 1.0

    def solve(scale: float, omega: float, guess=None):  # type: ignore[no-untyped-def]
        def g(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
            return x**3 / scale**2  # type: ignore[no-any-return]

        return hb.solve(1.0, 0.04, 1.0, g, omega, f=lambda th: 0.1 * scale * np.cos(th), guess=guess,
                        velocity_dependent=False, vectorized=True)

    for scale in (1.0, 1e-6, 1e-8):
        got = solve(scale, mid["omega"], 1.001 * scale * np.asarray(mid["coeffs"]))
        dist = np.max(np.abs(got["coeffs"] / scale - mid["coeffs"])) / np.max(np.abs(mid["coeffs"]))
        assert dist < 1e-7, (scale, dist)  # both stop at ‖r‖ ≤ 1e-9·‖f̂‖
        assert got["stable"] is False and got["stability"] == "fold", (scale, got["stability"])
        np.testing.assert_allclose(got["floquet"][0], mu_ref, rtol=0, atol=1e-6)
    unit = hb.duffing(omega_f=0.4)
    for scale in (1e8, 1e-8):
        got = solve(scale, 0.4)  # from the linear solution
        np.testing.assert_allclose(got["coeffs"] / scale, unit["coeffs"], rtol=0, atol=1e-9 * np.max(np.abs(unit["coeffs"])))
        assert got["residual_norm"] <= 1e-9 * 0.1 * scale and got["stable"] is True
    # ‖r‖ ≤ tol + rtol·‖f̂‖: a loose rtol stops earlier; max_iter caps the iterations.
    assert solve(1.0, 0.4)["iterations"] > hb.solve(
        1.0, 0.04, 1.0, lambda x, v, th: x**3, 0.4, f=lambda th: 0.1 * np.cos(th), rtol=1e-4,
        velocity_dependent=False)["iterations"]
    with pytest.raises(hb.ConvergenceError):
        hb.solve(1.0, 0.04, 1.0, lambda x, v, th: x**3, 1.6, f=lambda th: 0.1 * np.cos(th), max_iter=1,
                 method="classic", velocity_dependent=False)
    with pytest.raises(ValueError, match="tolerances"):
        hb.solve(1.0, 0.04, 1.0, lambda x, v, th: x**3, 0.4, rtol=0.0, tol=0.0)
    with pytest.raises(ValueError, match="`max_iter`"):
        hb.solve(1.0, 0.04, 1.0, lambda x, v, th: x**3, 0.4, max_iter=0)


def test_van_der_pol_limit_cycle_period_against_time_integration() -> None:
    mu = 1.0

    def g(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
        return mu * x**2 * v  # type: ignore[no-any-return]

    lc = hb.limit_cycle(1.0, -mu, 1.0, g, 1.0, amplitude=2.0, n=30, samples=120, vectorized=True)

    # Period from time integration: successive upward zero crossings of x on the
    # attracting cycle (DOP853, rtol 1e-12, events located by scipy).
    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        return np.array([y[1], mu * (1 - y[0] ** 2) * y[1] - y[0]])

    def up(t: float, y: np.ndarray) -> float:
        return float(y[0])

    up.direction = 1  # type: ignore[attr-defined]
    sol = solve_ivp(rhs, (0.0, 200.0), [2.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14, events=up)
    crossings = sol.t_events[0]
    period = crossings[-1] - crossings[-2]
    assert lc["period"] == pytest.approx(period, rel=1e-8)
    assert lc["stable"] and lc["stability"] == "stable"
    mu0 = complex(*lc["multipliers"][0])
    assert abs(mu0 - 1) < 1e-6


def test_van_der_pol_written_with_the_damping_in_g_converges() -> None:
    """The same cycle with C = 0 and g = −μ(1 − x²)v: the guess at ω = 1
    makes the linear force L(ω)q₀ vanish (K = ω²M), so the tolerance's force
    scale falls back on the elastic force ‖K q₀‖; with S = 0 the default
    tolerance was 0 and the solve could not stop (‖r‖ reached 2.5e-17)."""
    for mu in (0.2, 1.0):
        a = hb.limit_cycle(1.0, 0.0, 1.0, lambda x, v, th: -mu * (1 - x**2) * v, 1.0, amplitude=2.0,
                           vectorized=True)
        b = hb.limit_cycle(1.0, -mu, 1.0, lambda x, v, th: mu * x**2 * v, 1.0, amplitude=2.0,
                           vectorized=True)
        assert a["period"] == pytest.approx(b["period"], rel=1e-10)


def test_eval_series_multi_dof_layout() -> None:
    # Two DOFs, n = 1: x0 = 1/2 + cos τ, x1 = −sin τ.
    q = np.array([1.0, 1.0, 0.0, 0.0, 0.0, -1.0])
    got = hb.eval_series(q, np.array([0.0, np.pi / 2]), n_dof=2)
    np.testing.assert_allclose(got, [[1.5, 0.0], [0.5, -1.0]], atol=1e-15)
    with pytest.raises(ValueError, match="n_dof"):
        hb.eval_series(q, 0.0, n_dof=4)


def test_mathieu_cascade_equals_cli(cli) -> None:  # type: ignore[no-untyped-def]
    """The period-doubling cascade (§3.2.5) is `ivt hb mathieu-duffing`: the
    same β values to 1e-12 (the same Rust function; the margin covers JSON
    float formatting only), within 1e-3 of the thesis's 4.825, 5.194, 5.253."""
    ref = cli("hb", "mathieu-duffing")
    got = hb.mathieu_cascade()
    assert got["periods"] == ref["periods"] == [1, 2, 4]
    np.testing.assert_allclose(got["period_doubling_beta"], ref["period_doubling_beta"], rtol=1e-12, atol=0)
    np.testing.assert_allclose(got["multipliers"], ref["multipliers"], rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(got["period_doubling_beta"], got["thesis"], atol=1e-3)
    with pytest.raises(ValueError, match="`n` = -1"):
        hb.mathieu_cascade(n=-1)
    with pytest.raises(ValueError, match="`omega`"):
        hb.mathieu_cascade(omega=0.0)
