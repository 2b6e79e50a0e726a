"""Issue 27's analyses from Python: limit cycles from a state, every solution at
one frequency, damped nonlinear modes and the Jenkins element. References are
scipy time integrations (solve_ivp, rtol 1e-12) and closed forms, never HB."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.special import ellipk

from ivt import hb


def _period_by_integration(accel, y0=(2.0, 0.0), settle=200.0):
    """Period of the attracting cycle of x'' = accel(x, v): integrate `settle`
    time units, then the spacing of the last two maxima of x (events v = 0,
    v decreasing, located by the dense output)."""
    rhs = lambda t, y: [y[1], accel(y[0], y[1])]
    first = solve_ivp(rhs, (0, settle), y0, method="DOP853", rtol=1e-12, atol=1e-12)
    event = lambda t, y: y[1]
    event.direction = -1
    run = solve_ivp(rhs, (0, 60.0), first.y[:, -1], method="DOP853", rtol=1e-12,
                    atol=1e-12, events=event)
    t = run.t_events[0]
    return t[-1] - t[-2]


CYCLES = [  # (name, μ, harmonics)
    ("van_der_pol", 0.2, 15),
    ("van_der_pol", 1.0, 30),
    ("van_der_pol", 5.0, 120),
    ("rayleigh", 2.0, 60),
    ("rayleigh", 5.0, 120),
]


@pytest.mark.parametrize("name,mu,n", CYCLES)
def test_limit_cycle_from_the_default_start_and_from_x0(name, mu, n):
    if name == "van_der_pol":
        accel = lambda x, v: mu * (1 - x * x) * v - x
        g = lambda x, v, th: mu * x * x * v
    else:
        accel = lambda x, v: mu * (v - v ** 3 / 3) - x
        g = lambda x, v, th: mu * v ** 3 / 3
    period = _period_by_integration(accel)
    for kwargs in ({}, {"x0": [0.05, 0.0]}, {"x0": [3.0, -2.0]}):
        lc = hb.limit_cycle(1.0, -mu, 1.0, g, 1.0, n=n, samples=4 * n,
                            vectorized=True, **kwargs)
        assert abs(lc["period"] - period) < 1e-8 * period, (kwargs, lc["period"], period)
        assert lc["stable"]


def test_limit_cycle_start_errors():
    g = lambda x, v, th: x * x * v
    with pytest.raises(ValueError, match="not both"):
        hb.limit_cycle(1.0, -1.0, 1.0, g, 1.0, guess=np.zeros(41) + 0.1, x0=[1.0, 0.0], n=20)
    # μ < 0: the origin attracts; no cycle on valid input is "failed" (SPEC §6)
    with pytest.raises(hb.ConvergenceError, match="equilibrium"):
        hb.limit_cycle(1.0, 0.5, 1.0, lambda x, v, th: -0.5 * x * x * v, 1.0, x0=[0.5, 0.0])
    with pytest.raises(ValueError, match="x0"):
        hb.limit_cycle(1.0, -1.0, 1.0, g, 1.0, x0=[np.nan, 0.0])


def _duffing_period_map(omega, y):
    """RK (DOP853, rtol 1e-12) over one period of u'' + 0.04u' + u + u³ = 0.1 cos ωt."""
    rhs = lambda t, y: [y[1], 0.1 * np.cos(omega * t) - 0.04 * y[1] - y[0] - y[0] ** 3]
    return solve_ivp(rhs, (0, 2 * np.pi / omega), y, method="DOP853", rtol=1e-12,
                     atol=1e-12).y[:, -1]


def test_all_solutions_of_the_thesis_duffing_at_1_4():
    omega = 1.4
    found = hb.all_solutions(1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0),
                             lambda th: 0.1 * np.cos(th), omega, n=15)
    assert isinstance(found, hb.AllSolutions) and isinstance(found, list)
    assert len(found) == 3 and found.search["exhausted"]
    assert found.search["starts"] == 25 and found.search["max_amplitude"] == 10.0
    assert [s["stable"] for s in found] == [True, False, True]
    for s in found:
        # Each orbit's state at t = 0 is a fixed point of the period map.
        y = [hb.eval_series(s["coeffs"], 0.0), omega * hb.eval_series(s["coeffs"], 0.0, order=1)]
        assert np.max(np.abs(_duffing_period_map(omega, y) - y)) < 1e-8
        assert set(s) >= {"coeffs", "amplitude", "multipliers", "stable", "stability"}


def test_damped_modes_duffing_and_the_linear_limit():
    # One DOF: the EPMC damping cancels c exactly, so ω(A) is the free Duffing
    # frequency π√(1 + A²)/(2K(m)) and ζ = c/(2ω).
    c = 0.04
    dm = hb.damped_modes(1.0, c, 1.0, hb.elements.cubic_spring(1.0), 0.01, 1.0, n=21,
                         samples=84)
    assert dm["termination"] == "left_interval"
    for p in dm["points"]:
        a = float(hb.eval_series(p["coeffs"], 0.0))
        mk = a * a / (2 * (1 + a * a))
        exact = np.pi * np.sqrt(1 + a * a) / (2 * ellipk(mk))
        assert abs(p["omega"] - exact) < 1e-9 * exact
        assert abs(p["damping_ratio"] - c / (2 * p["omega"])) < 1e-9 * c
    # Two DOF, C = 0.05 M + 0.01 K: mode 1 (ω = √3) at a vanishing amplitude.
    m, k = np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]])
    lin = hb.damped_modes(m, 0.05 * m + 0.01 * k, k, hb.elements.cubic_spring(0.5),
                          1e-7, 1e-3, mode=1, n=7, samples=32)
    w = np.sqrt(3.0)
    first = lin["points"][0]
    assert abs(first["omega"] - w) < 1e-10 * w
    assert abs(first["damping_ratio"] - (0.05 + 0.01 * 3) / (2 * w)) < 1e-10


def test_jenkins_orbit_against_time_integration():
    # x'' + 0.1x' + x + F_J = 0.5 cos 1.2t, Jenkins k = 1, F_s = 0.3 (play
    # operator of half-width 0.3): RK with the slider advanced per step.
    k, fs, omega = 1.0, 0.3, 1.2
    period = 2 * np.pi / omega
    steps = 3200
    dt = period / steps
    x, v, z = 0.0, 0.0, 0.0
    def acc(t, x, v, z):
        zz = min(max(z, x - fs / k), x + fs / k)
        return 0.5 * np.cos(omega * t) - 0.1 * v - x - k * (x - zz)
    samples = []
    for i in range(120 * steps + steps):
        if i >= 120 * steps and (i - 120 * steps) % (steps // 32) == 0:
            samples.append(x)
        t = i * dt
        k1 = (v, acc(t, x, v, z))
        k2 = (v + 0.5 * dt * k1[1], acc(t + 0.5 * dt, x + 0.5 * dt * k1[0], v + 0.5 * dt * k1[1], z))
        k3 = (v + 0.5 * dt * k2[1], acc(t + 0.5 * dt, x + 0.5 * dt * k2[0], v + 0.5 * dt * k2[1], z))
        k4 = (v + dt * k3[1], acc(t + dt, x + dt * k3[0], v + dt * k3[1], z))
        x += dt / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v += dt / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
        z = min(max(z, x - fs / k), x + fs / k)
    sol = hb.solve(1.0, 0.1, 1.0, hb.elements.jenkins(k, fs), omega,
                   f=lambda th: 0.5 * np.cos(th), n=64, samples=2048, max_iter=400)
    taus = 2 * np.pi * np.arange(32) / 32
    assert np.max(np.abs(hb.eval_series(sol["coeffs"], taus) - samples)) < 1e-4


def test_jenkins_parameters_are_checked():
    with pytest.raises(ValueError, match="element 0"):
        hb.solve(1.0, 0.1, 1.0, hb.elements.jenkins(-1.0, 0.3), 1.0, f=lambda th: np.cos(th))


def test_continue_bifurcation_duffing_fold_curve_to_the_cusp():
    # The thesis Duffing family in F: from the F = 0.1 fold at the higher ω,
    # down to the cusp and up the other fold to F = 0.3, then up its own fold
    # to F = 0.3. Fold frequencies by shooting (tests/fold_curve.rs, 3.5e-13
    # there): 1.6548121230 and 1.1687243884 at F = 0.1, 1.2589591460 and
    # 2.2115927040 at 0.2, 1.3297591465 and 2.6572119678 at 0.3;
    # the cusp at F = 0.0120510724 (the extremum of F along the shooting curve).
    family = lambda F: (1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0),
                        lambda th: F * np.cos(th))
    frc = hb.frc(*family(0.1), 0.5, 2.5, n=15, events=True)
    folds = [b for b in frc["bifurcations"] if b["kind"] == "fold"]
    start = max(folds, key=lambda b: b["omega"])
    curve = hb.continue_bifurcation(family, start, 0.0, 0.3, at=[0.1, 0.2, 0.3],
                                    p_start=0.1, n=15)
    assert curve["kind"] == "fold" and curve["termination"] == "left_interval"
    got = sorted((round(a["p"], 12), a["omega"]) for a in curve["at"])
    want = [(0.1, 1.1687243884), (0.1, 1.6548121230), (0.2, 1.2589591460),
            (0.2, 2.2115927040), (0.3, 1.3297591465), (0.3, 2.6572119678)]
    assert len(got) == 6
    for (p, w), (pw, ww) in zip(got, want):
        assert p == pw and abs(w - ww) < 1e-7
    (cusp,) = curve["special"]
    assert cusp["kind"] == "cusp" and abs(cusp["p"] / 0.0120510724 - 1) < 1e-6
    assert set(curve["points"][0]) >= {"omega", "p", "amplitude", "coeffs"}
    assert curve["unlocated"] == []


def test_continue_bifurcation_reports_an_at_point_it_cannot_solve():
    # The forcing fails at F = 0.2 exactly (the path steps over it): the fold
    # curve passes F = 0.2 on both folds but cannot solve either there. Both
    # are reported in "unlocated" with the value, the reason and the path
    # point the solve started from; F = 0.25 is located on both folds.
    def family(F):
        def force(th):
            if F == 0.2:
                raise ValueError("no force at F = 0.2")
            return F * np.cos(th)
        return (1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0), force)

    frc = hb.frc(*family(0.1), 0.5, 2.5, n=15, events=True)
    start = max((b for b in frc["bifurcations"] if b["kind"] == "fold"), key=lambda b: b["omega"])
    curve = hb.continue_bifurcation(family, start, 0.0, 0.3, at=[0.2, 0.25], p_start=0.1, n=15)
    assert sorted(a["p"] for a in curve["at"]) == [0.25, 0.25]
    assert [(u["what"], u["value"]) for u in curve["unlocated"]] == [("at", 0.2)] * 2
    for u in curve["unlocated"]:
        assert abs(u["near"]["p"] - 0.2) < 0.05 and u["reason"], u


def test_continue_bifurcation_reraises_the_family_error():
    def family(F):
        if F < 0.09:
            raise RuntimeError("no model below 0.09")
        return (1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0), lambda th: F * np.cos(th))
    frc = hb.frc(*family(0.1), 0.5, 2.5, n=15, events=True)
    start = max((b for b in frc["bifurcations"] if b["kind"] == "fold"), key=lambda b: b["omega"])
    with pytest.raises(RuntimeError, match="no model below"):
        hb.continue_bifurcation(family, start, 0.0, 0.3, p_start=0.1, n=15)
    with pytest.raises(ValueError, match="p_start"):
        hb.continue_bifurcation(family, start, 0.0, 0.3, n=15)


def _newton(residual, u, steps=8):
    """Newton on residual(u) = 0 from u, central-difference Jacobian (step
    1e-5), until a step is below 1e-12."""
    for _ in range(steps):
        jac = np.column_stack([(residual(u + h) - residual(u - h)) / 2e-5
                               for h in 1e-5 * np.eye(len(u))])
        step = np.linalg.solve(jac, -residual(u))
        u = u + step
        if np.max(np.abs(step)) < 1e-12:
            break
    return u


def _unbalance_fold_by_shooting(omega0, y0):
    """The fold of u'' + 0.04u' + u + u³ = 0.03 ω² cos ωt near (ω0, y0) by
    shooting: Newton on [P(y) − y, det(∂P/∂y − I)] in (y, ω), the period map P
    by DOP853 (rtol 1e-12), every Jacobian by central differences."""
    def period_map(omega, y):
        rhs = lambda t, y: [y[1], 0.03 * omega ** 2 * np.cos(omega * t) - 0.04 * y[1]
                            - y[0] - y[0] ** 3]
        return solve_ivp(rhs, (0, 2 * np.pi / omega), y, method="DOP853", rtol=1e-12,
                         atol=1e-12).y[:, -1]

    def residual(u):
        y, omega = u[:2], u[2]
        h = 1e-6
        jac = np.column_stack([(period_map(omega, y + h * e) - period_map(omega, y - h * e))
                               / (2 * h) for e in np.eye(2)]) - np.eye(2)
        return np.r_[period_map(omega, y) - y, np.linalg.det(jac)]

    return _newton(residual, np.r_[y0, omega0])[2]


@pytest.mark.parametrize("vectorized", [False, True])
def test_frc_with_an_omega_dependent_force_matches_shooting(vectorized):
    # Rotating unbalance: f(θ, ω) = 0.03 ω² cos θ; ω is detected from the signature.
    g = lambda x, v, theta: x ** 3
    f = lambda theta, omega: 0.03 * omega ** 2 * np.cos(theta)
    curve = hb.frc(1.0, 0.04, 1.0, g, f, 0.5, 2.5, n=15, vectorized=vectorized,
                   velocity_dependent=False)
    folds = [b for b in curve["bifurcations"] if b["kind"] == "fold"]
    assert len(folds) == 2 and all(b["located"] for b in folds)
    for b in folds:
        y0 = [hb.eval_series(b["coeffs"], 0.0), b["omega"] * hb.eval_series(b["coeffs"], 0.0, order=1)]
        reference = _unbalance_fold_by_shooting(b["omega"], y0)
        assert abs(b["omega"] - reference) < 1e-7, (b["omega"], reference)


def test_omega_in_g_is_passed_and_refused_where_there_is_no_frequency():
    # g(x, v, θ, ω) = x³ + 0.04 ω x: solve at ω passes omega (the orbit
    # equals that of the fixed law at that ω), limit_cycle has none to pass.
    g = lambda x, v, theta, omega: x ** 3 + 0.04 * omega * x
    fixed = lambda x, v, theta: x ** 3 + 0.04 * 1.3 * x
    f = lambda theta: 0.1 * np.cos(theta)
    a = hb.solve(1.0, 0.04, 1.0, g, 1.3, f=f, n=9)
    b = hb.solve(1.0, 0.04, 1.0, fixed, 1.3, f=f, n=9)
    assert np.max(np.abs(np.asarray(a["coeffs"]) - b["coeffs"])) < 1e-10
    with pytest.raises(ValueError, match="omega"):
        hb.limit_cycle(1.0, -1.0, 1.0, lambda x, v, theta, omega: x * x * v, 1.0)
    with pytest.raises(TypeError, match="jac"):
        hb.frc(1.0, 0.04, 1.0, g, f, 0.5, 2.5, jac=lambda x, v, th: (3 * x * x, 0 * v))


def _hopf_family(mu):
    """x'' − (μ + x² − x⁴) x' + x = 0 as (m, c, k, g, f)."""
    return 1.0, -mu, 1.0, lambda x, v, th: -(x * x - x ** 4) * v, None


def _cycle_gap(mu, x0, period):
    """y(T) − (x0, 0) of x'' = (μ + x² − x⁴) x' − x from (x0, 0) (DOP853, rtol 1e-12)."""
    rhs = lambda t, y: [y[1], (mu + y[0] ** 2 - y[0] ** 4) * y[1] - y[0]]
    y = solve_ivp(rhs, (0, period), [x0, 0.0], method="DOP853", rtol=1e-12, atol=1e-12).y[:, -1]
    return np.array([y[0] - x0, y[1]])


def test_cycle_branch_hopf_fold_and_the_two_cycles_against_time_integration():
    out = hb.cycle_branch(_hopf_family, -0.2, 0.1, at=[-0.1], n=25, samples=128)
    assert out["unlocated"] == []
    [hopf] = out["hopf"]
    assert abs(hopf["p"]) < 1e-12 and abs(hopf["omega"] - 1.0) < 1e-12
    assert hopf["subcritical"] and hopf["lyapunov"] > 0
    [fold] = out["bifurcations"]
    # The fold by shooting: Newton on [y(T) − y0, det ∂(y(T) − y0)/∂(x0, T)] in (x0, T, μ).
    def residual(u):
        gap = _cycle_gap(u[2], u[0], u[1])
        j = np.column_stack([(_cycle_gap(u[2], *(u[:2] + h)) - _cycle_gap(u[2], *(u[:2] - h))) / 2e-6
                             for h in 1e-6 * np.eye(2)])
        return np.r_[gap, np.linalg.det(j)]
    x0 = max(hb.eval_series(fold["coeffs"], t) for t in np.linspace(0, 2 * np.pi, 4001))
    u = _newton(residual, np.array([x0, 2 * np.pi / fold["omega"], fold["p"]]))
    assert abs(fold["p"] - u[2]) < 1e-8, (fold["p"], u[2])
    # μ = −0.1: the large cycle attracts forward in time, the small one
    # backward (x'' = a(x, −x') in reversed time); periods to 1e-8.
    small, large = sorted(out["at"], key=lambda c: c["amplitude"])
    accel = lambda x, v: (-0.1 + x * x - x ** 4) * v - x
    assert large["stable"] and not small["stable"]
    t_large = _period_by_integration(accel, y0=(1.5, 0.0))
    t_small = _period_by_integration(lambda x, w: accel(x, -w), y0=(0.9, 0.0))
    assert abs(large["period"] - t_large) < 1e-8 * t_large, (large["period"], t_large)
    assert abs(small["period"] - t_small) < 1e-8 * t_small, (small["period"], t_small)


def test_neimark_sacker_points_of_forced_van_der_pol_against_shooting():
    # x'' − 0.2(1 − x²)x' + x = F cos ωt: the issue's point (0.94525643, 0.2).
    family = lambda F: (1.0, -0.2, 1.0, lambda x, v, th: 0.2 * x * x * v,
                        lambda th: F * np.cos(th))
    points = hb.neimark_sacker_points(family, [0.2], 0.5, 1.6, n=9, samples=32)
    [pt] = [p for p in points if abs(p["omega"] - 0.945) < 0.01]
    # Shooting: Newton on [P(y) − y, det ∂P/∂y − 1] in (y, ω) (DOP853, rtol 1e-12).
    def period_map(w, y):
        rhs = lambda t, y: [y[1], 0.2 * (1 - y[0] ** 2) * y[1] - y[0] + 0.2 * np.cos(w * t)]
        return solve_ivp(rhs, (0, 2 * np.pi / w), y, method="DOP853", rtol=1e-12,
                         atol=1e-12).y[:, -1]

    def residual(u):
        y, w = u[:2], u[2]
        jac = np.column_stack([(period_map(w, y + h) - period_map(w, y - h)) / 2e-6
                               for h in 1e-6 * np.eye(2)])
        return np.r_[period_map(w, y) - y, np.linalg.det(jac) - 1.0]

    c = pt["coeffs"]
    u = _newton(residual, np.array([hb.eval_series(c, 0.0),
                                    pt["omega"] * hb.eval_series(c, 0.0, order=1), pt["omega"]]))
    assert abs(pt["omega"] - u[2]) < 1e-7, (pt["omega"], u[2])
    assert abs(pt["omega"] - 0.94525643) < 1e-8
