"""Issue 45 from Python: the torus branch of the forced Van der Pol oscillator
(`ivt.hb.torus_branch`), the automatic bifurcation diagram of the 2-DOF cubic
chain (`ivt.hb.diagram`) and the sensitivities of located features
(`ivt.hb.event_sensitivity`), each against scipy (time integration, shooting)
or differences of located points, never against ivt's own answer."""

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

from ivt import hb

MU = F = 0.2

# The reference of the acceptance at ω = 0.93 and 0.90: rotation
# number, mean |x| and max |x| of a 1500-period integration's Poincaré map
# (weighted Birkhoff averages; crates/ivt-hb/tests/torus.rs computes it in
# CI with RK6, bench/qp_references.py with scipy's DOP853 at rtol 1e-12;
# the two agree to 1e-9, 2e-8 and 2e-7).
REFERENCE = {
    0.93: (0.0452570374, 1.1783649695, 2.3789481906),
    0.90: (0.0928371997, 1.2042105492, 2.3696325980),
}


def vdp_g(x, v, th):
    return MU * x**2 * v


def vdp_f(th):
    return F * np.cos(th)


def vdp_start():
    frc = hb.frc(1.0, -MU, 1.0, vdp_g, vdp_f, 0.6, 1.6, n=12, samples=32, vectorized=True)
    [ns] = [b for b in frc["bifurcations"] if b["kind"] == "neimark_sacker"]
    return frc, ns


def torus_series(point, harmonics, theta1, theta2):
    """X(θ₁, θ₂) of DOF 0 of a torus point (its coefficients over
    `harmonics`)."""
    c = np.asarray(point["coeffs"])
    h = len(harmonics)
    k = np.asarray(harmonics, dtype=float)
    phase = np.multiply.outer(theta1, k[:, 0]) + np.multiply.outer(theta2, k[:, 1])
    return 0.5 * c[0] + np.cos(phase) @ c[1:h + 1] + np.sin(phase) @ c[h + 1:2 * h + 1]


def test_van_der_pol_torus_is_invariant_and_matches_the_poincare_map():
    _, ns = vdp_start()
    tor = hb.torus_branch(1.0, -MU, 1.0, vdp_g, vdp_f, ns, 0.89, at=[0.93, 0.90], n=12, samples=32,
                          vectorized=True, truncation=(5, 12))
    assert tor["termination"] == "left_interval"
    assert abs(tor["points"][0]["omega"] - ns["omega"]) < 1e-3
    for omega in (0.93, 0.90):
        [p] = [a for a in tor["at"] if a["omega"] == omega]
        rho, mean, top = REFERENCE[omega]
        assert abs(p["rotation_number"] - rho) < 1e-5
        assert abs(p["amplitude_mean"] - mean) < 1e-5
        assert abs(p["amplitude_max"] - top) < 1e-5
        assert p["error_estimate"] < 1e-5 and p["stable"]
        # A trajectory started on the torus (θ₁ = θ₂ = 0) stays on it with
        # θ₁ = ωt, θ₂ = Ωt: scipy over ten forcing periods.
        x0, v0 = p["section"]["x"][0], p["section"]["v"][0]
        period = 2 * math.pi / omega
        t = np.linspace(0.0, 10 * period, 400)
        run = solve_ivp(lambda t, y: [y[1], MU * (1 - y[0] ** 2) * y[1] - y[0] + F * math.cos(omega * t)],
                        (0.0, t[-1]), [x0, v0], method="DOP853", rtol=1e-12, atol=1e-12, t_eval=t)
        on_torus = torus_series(p, p["harmonics"], omega * t, p["second_frequency"] * t)
        assert np.max(np.abs(run.y[0] - on_torus)) < 1e-6


def test_torus_branch_refuses_what_it_cannot_follow():
    frc, ns = vdp_start()
    fold = {"kind": "fold", "omega": 1.0, "coeffs": ns["coeffs"], "multipliers": ns["multipliers"]}
    with pytest.raises(ValueError, match="neimark_sacker"):
        hb.torus_branch(1.0, -MU, 1.0, vdp_g, vdp_f, fold, 0.9, n=12, samples=32, vectorized=True)
    with pytest.raises(ValueError, match="must lie on that side"):
        hb.torus_branch(1.0, -MU, 1.0, vdp_g, vdp_f, ns, 1.2, n=12, samples=32, vectorized=True,
                        truncation=(3, 6))
    with pytest.raises(TypeError, match="truncation"):
        hb.torus_branch(1.0, -MU, 1.0, vdp_g, vdp_f, ns, 0.9, n=12, samples=32, vectorized=True,
                        truncation="wide")
    jenkins = hb.elements.jenkins(1.0, 0.1) + hb.elements.cubic_damper(MU / 3)
    with pytest.raises(ValueError, match="hysteretic"):
        hb.torus_branch(1.0, -MU, 1.0, jenkins, vdp_f, ns, 0.9, n=12, samples=32)


# The 2-DOF chain of the issue, forced on DOF 1.
M, C, K = np.eye(2), 0.02 * np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]])


def chain_g(x, v, th):
    return 0.5 * x**3


def chain_jac(x, v, th):
    d = np.zeros((len(x), 2, 2))
    d[:, 0, 0] = 1.5 * x[:, 0] ** 2
    d[:, 1, 1] = 1.5 * x[:, 1] ** 2
    return d, None


def chain_f(th):
    return [0.1 * np.cos(th), 0.0]


def period_map(y, omega, monodromy=False):
    """The state after one forcing period (scipy DOP853), and its Jacobian
    from the variational equation when asked."""

    def rhs(t, z):
        x, v = z[:2], z[2:4]
        acc = np.array([0.1 * math.cos(omega * t), 0.0]) - C @ v - K @ x - 0.5 * x**3
        out = [*v, *acc]
        if monodromy:
            phi = z[4:].reshape(4, 4)
            a = np.zeros((4, 4))
            a[:2, 2:] = np.eye(2)
            a[2:, :2] = -K - np.diag(1.5 * x**2)
            a[2:, 2:] = -C
            out += list((a @ phi).ravel())
        return out

    z0 = list(y) + (list(np.eye(4).ravel()) if monodromy else [])
    run = solve_ivp(rhs, (0.0, 2 * math.pi / omega), z0, method="DOP853", rtol=1e-11, atol=1e-12)
    end = run.y[:, -1]
    return end[:4], (end[4:].reshape(4, 4) if monodromy else None)


def test_diagram_holds_every_orbit_that_scipy_shooting_finds():
    omega = 1.15
    d = hb.diagram(M, C, K, chain_g, chain_f, 0.5, 2.5, at=[omega], n=15, vectorized=True,
                   velocity_dependent=False, jac=chain_jac, deflation_omegas=2)
    assert d["branches"][0]["kind"] == "primary" and d["search"]["interval"] == [0.5, 2.5]
    orbits = []
    for b in d["branches"]:
        if b["subharmonic"] != 1 or b["torus_harmonics"]:
            continue
        for p in b["points"]:
            if p["at"]:
                q = np.asarray(p["coeffs"]).reshape(2, -1)
                state = [hb.eval_series(qd, 0.0) for qd in q] + [omega * hb.eval_series(qd, 0.0, 1) for qd in q]
                orbits.append((np.array(state, dtype=float), p["stable"]))
    assert len(orbits) == 3
    # Each is a fixed point of scipy's period map, with scipy's stability.
    for y, stable in orbits:
        end, phi = period_map(y, omega, monodromy=True)
        assert np.max(np.abs(end - y)) < 1e-7
        assert (np.max(np.abs(np.linalg.eigvals(phi))) < 1) == stable
    # Shooting from states spread over the box finds no orbit the diagram lacks.
    rng = np.random.default_rng(45)
    found = 0
    for start in rng.uniform(-1.2, 1.2, size=(8, 4)):
        y, info, ok, _ = fsolve(lambda y: period_map(y, omega)[0] - y, start, full_output=True, xtol=1e-12)
        if ok != 1 or np.max(np.abs(period_map(y, omega)[0] - y)) > 1e-9:
            continue
        found += 1
        assert min(np.max(np.abs(y - o)) for o, _ in orbits) < 1e-6
    assert found >= 2


def duffing(force):
    return 1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0), lambda th: force * np.cos(th)


def test_fold_sensitivities_of_the_thesis_duffing_match_shooting_and_differences():
    # dω_fold/dF at F = 0.1 by Richardson differences of shooting folds
    # (crates/ivt-hb/tests/sensitivity.rs, RK4 shooting): 6.427494543615
    # (upper fold) and 1.066903537492 (lower).
    frc = hb.frc(*duffing(0.1), 0.5, 2.5, n=20)
    shooting = [6.427494543615, 1.066903537492]
    for fold, reference in zip(frc["folds"], shooting):
        s = hb.event_sensitivity(duffing, fold, 0.1, n=20)
        assert s["kind"] == "fold" and abs(s["omega"] - fold["omega"]) < 1e-9
        assert abs(s["d_omega_dp"] / reference - 1) < 1e-6
        # dA/dF (A = max |x| of the orbit) against the folds located at F ± h.
        h = 1e-4
        near = [hb.event_sensitivity(duffing, fold, 0.1 + dh, n=20) for dh in (h, -h)]
        assert abs(s["d_amplitude_dp"] - (near[0]["amplitude"] - near[1]["amplitude"]) / (2 * h)) < 1e-6 * abs(
            s["d_amplitude_dp"])


def test_peak_sensitivity_and_refused_events():
    # Below its folds (F = 0.01) the Duffing resonance has a plain peak.
    frc = hb.frc(*duffing(0.01), 0.5, 2.5, n=9, samples=32)
    assert not frc["folds"]
    top = max(frc["points"], key=lambda p: p["amplitude"])
    s = hb.event_sensitivity(duffing, {"kind": "peak", "omega": top["omega"], "coeffs": top["coeffs"]}, 0.01,
                             n=9, samples=32)
    h = 1e-6
    moved = [hb.event_sensitivity(duffing, {"kind": "peak", "omega": s["omega"], "coeffs": s["coeffs"]},
                                  0.01 + dh, n=9, samples=32) for dh in (h, -h)]
    assert abs(s["d_omega_dp"] - (moved[0]["omega"] - moved[1]["omega"]) / (2 * h)) < 1e-5 * abs(s["d_omega_dp"])
    assert abs(s["d_amplitude_dp"] - (moved[0]["amplitude"] - moved[1]["amplitude"]) / (2 * h)) < 1e-5 * abs(
        s["d_amplitude_dp"])
    with pytest.raises(ValueError, match="unknown feature"):
        hb.event_sensitivity(duffing, {"kind": "cusp", "omega": top["omega"], "coeffs": top["coeffs"]}, 0.01,
                             n=9, samples=32)
    with pytest.raises(ValueError, match="coefficients"):
        hb.event_sensitivity(duffing, {"omega": 1.0, "coeffs": [0.0, 1.0]}, 0.01, n=9, samples=32)
