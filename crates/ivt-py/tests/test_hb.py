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
    # Hsu with 256 Magnus-4 steps: ~1e-7 against the variational ODE.
    np.testing.assert_allclose(mu, mu_ref, rtol=0, atol=1e-6)
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
    np.testing.assert_allclose(mu, mu_ref, atol=1e-6)
    assert res["stable"] == bool(np.all(np.abs(mu_ref) < 1))


def test_frc_folds_and_flags() -> None:
    frc = hb.duffing_frc(0.2, 3.0)
    omega, amp, stable = frc["omega"], frc["amplitude"], frc["stable"]
    assert len(frc["points"]) == len(omega) and set(frc["points"][0]) >= {"omega", "amplitude", "stable"}
    # Hardening peak: the path turns twice (two folds), and the branch between
    # them is unstable (a multiplier crosses +1 at each fold).
    assert len(frc["folds"]) == 2
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
