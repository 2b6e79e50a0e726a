"""Large structures (issue 28): ivt.hb.frc/solve on scipy.sparse matrices
condensed onto the nonlinear DOFs, load-vector forcing, amplitude_dof and
record_dofs, and ivt.hb.models.cantilever."""

import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla

import ivt

W1 = 3.516015268066119  # (1.8751041)², the clamped–free beam
K3, F0 = 200.0, 0.005


def spring(x, v, t):
    return K3 * x**3


def spring_jac(x, v, t):
    return np.array([[3.0 * K3 * x[0] ** 2]]), np.zeros((1, 1))


def test_cantilever_is_sparse_symmetric_with_the_static_tip_stiffness():
    m, c, k, tip = ivt.hb.models.cantilever(20)
    assert all(sp.issparse(a) for a in (m, c, k))
    assert m.shape == (40, 40) and tip == 38
    for a in (m, c, k):
        assert abs(a - a.T).max() == 0.0
    # K⁻¹ e_tip at the tip is 1/(3EI/L³) exactly for Hermite cubics (scipy's
    # plain sparse LU already loses 1.3e-12 of it at N = 20: κ(K) ~ N⁴).
    e = np.zeros(40)
    e[tip] = 1.0
    assert abs(spla.spsolve(k.tocsc(), e)[tip] - 1.0 / 3.0) < 1e-10
    # C = 0.07 M + 2e-4 K.
    assert abs(c - (0.07 * m + 2e-4 * k)).max() < 1e-12 * abs(k).max()


def test_condensed_curve_with_located_folds_and_recovered_dofs():
    m, c, k, tip = ivt.hb.models.cantilever(20)
    f = np.zeros(m.shape[0])
    f[tip] = F0
    out = ivt.hb.frc(m, c, k, spring, f, 0.7 * W1, 1.3 * W1, jac=spring_jac,
                     nonlinear_dofs=[tip], record_dofs=[0, tip])
    assert out["termination"] == "left_interval"
    assert [fold["located"] for fold in out["folds"]] == [True, True]
    # The folds of the Rust tests (tests/condense.rs checks them on the full
    # extended system to 1e-10).
    assert abs(out["folds"][0]["omega"] - 3.906984060533) < 1e-9
    assert abs(out["folds"][1]["omega"] - 3.672391045809) < 1e-9
    n = 7
    for p in out["points"]:
        assert set(p["dof_coeffs"]) == {0, tip}
        assert p["dof_coeffs"][0].shape == (2 * n + 1,)
        # The recovered tip is the condensed unknown itself (to the corrector's
        # tolerance, 1e-12 of the start's linear response ≈ 4e-15).
        assert np.allclose(p["dof_coeffs"][tip], p["coeffs"], rtol=0, atol=1e-13)
        assert 0 < p["error_estimate"] < 1e-7
        # Floquet multipliers of the whole beam from the reduced basis
        # (tests/condense_stability.rs: within their estimate of the full
        # 80-state Hsu at N = 20).
        assert p["multiplier_error"] < 1e-4
        assert len(p["multipliers"]) == 2 * p["stability_basis"]
    # Stable outside the folds, unstable (a real multiplier > 1) between.
    first, second = (fold["index"] for fold in out["folds"])
    stable = [p["stable"] for p in out["points"]]
    assert all(stable[: first - 1]) and all(stable[second + 2 :])
    assert not any(stable[first + 2 : second - 1])
    assert all(p["stability"] == "fold" for p in out["points"][first + 2 : second - 1])
    assert np.array_equal(out["omega"], [p["omega"] for p in out["points"]])


def test_a_curve_without_the_truncation_estimate_has_the_same_points_and_no_estimate():
    # truncation_estimate=False skips only the estimate: the same path, the
    # same orbits, truncation_error and error_estimate None (not the orbit
    # error alone); with it both are numbers and error_estimate is their sum.
    m, c, k, tip = ivt.hb.models.cantilever(8)
    f = np.zeros(m.shape[0])
    f[tip] = F0
    args = (m, c, k, ivt.hb.elements.cubic_spring(K3, dof=tip), f, 0.9 * W1, 1.1 * W1)
    kw = dict(n=5, samples=16, nonlinear_dofs=[tip], stability=False)
    full = ivt.hb.frc(*args, **kw)
    bare = ivt.hb.frc(*args, truncation_estimate=False, **kw)
    assert len(bare["points"]) == len(full["points"]) > 10
    np.testing.assert_array_equal(bare["omega"], full["omega"])
    np.testing.assert_array_equal(bare["amplitude"], full["amplitude"])
    for p, q in zip(bare["points"], full["points"]):
        assert p["truncation_error"] is None and p["error_estimate"] is None
        assert p["orbit_error"] == q["orbit_error"]
        assert q["error_estimate"] == q["orbit_error"] + q["truncation_error"]


def test_condensed_curve_with_a_rust_element_equals_the_python_g():
    # The same tip spring as a Rust element on the condensed unknown (its
    # local index 0) and as the Python g with its Jacobian: the same points
    # and folds (both correct to 1e-12 of the linear response; the folds are
    # located on the extended system to 1e-11).
    m, c, k, tip = ivt.hb.models.cantilever(20)
    f = np.zeros(m.shape[0])
    f[tip] = F0
    args = (0.7 * W1, 1.3 * W1)
    py = ivt.hb.frc(m, c, k, spring, f, *args, jac=spring_jac, nonlinear_dofs=[tip])
    el = ivt.hb.frc(m, c, k, ivt.hb.elements.cubic_spring(K3, dof=tip), f, *args, nonlinear_dofs=[tip])
    assert len(el["points"]) == len(py["points"])
    np.testing.assert_allclose(el["amplitude"], py["amplitude"], rtol=1e-9, atol=0)
    assert [fd["located"] for fd in el["folds"]] == [True, True]
    np.testing.assert_allclose([fd["omega"] for fd in el["folds"]],
                               [fd["omega"] for fd in py["folds"]], rtol=1e-10, atol=0)


def test_condensed_solve_equals_the_dense_uncondensed_solve():
    # N = 8: the dense solve (classic Newton on all 16 DOFs) from its own
    # linear guess reaches the same orbit.
    m, c, k, tip = ivt.hb.models.cantilever(8)
    nd = m.shape[0]
    f = np.zeros(nd)
    f[tip] = F0
    large = ivt.hb.solve(m, c, k, spring, 3.0, f, nonlinear_dofs=[tip], record_dofs=list(range(nd)))

    def g_full(x, v, t):
        out = np.zeros(nd)
        out[tip] = K3 * x[tip] ** 3
        return out

    dense = ivt.hb.solve(m.toarray(), c.toarray(), k.toarray(), g_full, 3.0,
                         lambda t: f * np.cos(t), n=7, samples=32, method="classic",
                         velocity_dependent=False, rtol=1e-11)
    full = np.concatenate([large["dof_coeffs"][j] for j in range(nd)])
    assert np.max(np.abs(full - np.asarray(dense["coeffs"]))) < 1e-10 * np.max(np.abs(full))


def test_sine_load_is_the_cosine_orbit_shifted():
    m, c, k, tip = ivt.hb.models.cantilever(10)
    f = np.zeros(m.shape[0])
    f[tip] = F0
    cos = ivt.hb.solve(m, c, k, spring, 3.0, f, nonlinear_dofs=[tip])
    sin = ivt.hb.solve(m, c, k, spring, 3.0, (np.zeros_like(f), f), nonlinear_dofs=[tip])
    assert abs(cos["amplitude"] - sin["amplitude"]) < 1e-13
    n = 7
    a, b = cos["coeffs"][1 : n + 1], cos["coeffs"][n + 1 :]
    a2, b2 = sin["coeffs"][1 : n + 1], sin["coeffs"][n + 1 :]
    # x(τ − π/2): harmonic 1 turns (a, b) → (−b, a).
    assert abs(a2[0] + b[0]) < 1e-13 and abs(b2[0] - a[0]) < 1e-13


def test_amplitude_dof_and_record_dofs_on_a_dense_model():
    m = np.eye(2)
    k = np.array([[2.0, -1.0], [-1.0, 2.0]])
    c = 0.02 * np.eye(2)

    def g(x, v, t):
        return np.array([0.5 * x[0] ** 3, 0.0])

    out = ivt.hb.solve(m, c, k, g, 0.8, lambda t: np.array([0.1 * np.cos(t), 0.0]),
                       n=9, samples=32, amplitude_dof=1, record_dofs=[1])
    block = np.asarray(out["coeffs"]).reshape(2, -1)[1]
    assert np.array_equal(out["dof_coeffs"][1], block)
    tau = np.linspace(0, 2 * np.pi, 20001)
    assert abs(out["amplitude"] - np.abs(ivt.hb.eval_series(block, tau)).max()) < 1e-8


def test_bad_large_inputs_raise_value_errors():
    m, c, k, tip = ivt.hb.models.cantilever(4)
    f = np.zeros(m.shape[0])
    f[tip] = F0
    with pytest.raises(ValueError, match="nonlinear_dofs"):
        ivt.hb.frc(m, c, k, spring, f, 2.0, 3.0)
    with pytest.raises(ValueError):
        ivt.hb.frc(m, c, k, spring, f, 2.0, 3.0, nonlinear_dofs=[99])
    with pytest.raises(ValueError):
        ivt.hb.solve(m, c, k, spring, 2.0, f[:3], nonlinear_dofs=[tip])
    with pytest.raises(ValueError):
        ivt.hb.models.cantilever(0)


def test_stability_false_skips_the_multipliers_and_keeps_the_folds():
    m, c, k, tip = ivt.hb.models.cantilever(20)
    f = np.zeros(m.shape[0])
    f[tip] = F0
    out = ivt.hb.frc(m, c, k, spring, f, 0.7 * W1, 1.3 * W1, jac=spring_jac,
                     nonlinear_dofs=[tip], stability=False)
    assert all(p["multipliers"] is None and p["stable"] is None for p in out["points"])
    assert abs(out["folds"][0]["omega"] - 3.906984060533) < 1e-9
    assert abs(out["folds"][1]["omega"] - 3.672391045809) < 1e-9
    one = ivt.hb.solve(m, c, k, spring, 3.0, f, nonlinear_dofs=[tip])
    assert one["stable"] is True and np.hypot(*one["multipliers"][0]) < 1.0


def test_an_element_names_one_model_dof_on_the_dense_and_the_sparse_form():
    """Issue 46: `cubic_spring(K3, dof=tip)` means the tip on every path. The
    sparse cantilever (condensed path, its nonlinear DOFs taken from the
    element, no `nonlinear_dofs`) and its dense form (the full HB system of
    all 8 DOFs) give the same orbits at every DOF to 1e-10, and the same
    folds."""
    m, c, k, tip = ivt.hb.models.cantilever(4)
    nd = m.shape[0]
    f = np.zeros(nd)
    f[tip] = F0
    tip_spring = ivt.hb.elements.cubic_spring(K3, dof=tip)
    assert tip_spring.dofs == [tip] and len(tip_spring.restricted([tip])) == 1
    md, cd, kd = (a.toarray() for a in (m, c, k))

    def load(th):
        return f * np.cos(th)

    everywhere = list(range(nd))
    for w in (0.9 * W1, 0.98 * W1, 1.3 * W1):
        large = ivt.hb.solve(m, c, k, tip_spring, w, f, n=7, samples=32, record_dofs=everywhere)
        dense = ivt.hb.solve(md, cd, kd, tip_spring, w, load, n=7, samples=32, rtol=1e-12,
                             record_dofs=everywhere)
        scale = max(np.abs(dense["dof_coeffs"][j]).max() for j in everywhere)
        for j in everywhere:
            err = np.abs(np.asarray(large["dof_coeffs"][j]) - dense["dof_coeffs"][j]).max()
            assert err <= 1e-10 * scale, (w, j, err / scale)
        # The spring acts: the tip's response differs from the linear one by
        # far more than the two forms differ (2.8e-4 of the scale at 0.9 ω₁).
        linear = ivt.hb.solve(md, cd, kd, ivt.hb.elements.cubic_spring(0.0, dof=tip), w, load, n=7,
                              samples=32, rtol=1e-12, record_dofs=[tip])
        assert np.abs(linear["dof_coeffs"][tip] - dense["dof_coeffs"][tip]).max() > 1e-4 * scale
    kw = dict(n=7, samples=32, amplitude_dof=tip, stability=False)
    large = ivt.hb.frc(m, c, k, tip_spring, f, 0.9 * W1, 1.3 * W1, **kw)
    dense = ivt.hb.frc(md, cd, kd, tip_spring, load, 0.9 * W1, 1.3 * W1, rtol=1e-12, events=False,
                       **{key: v for key, v in kw.items() if key != "stability"})
    assert len(large["folds"]) == len(dense["folds"]) == 2
    for a, b in zip(large["folds"], dense["folds"]):
        assert abs(a["omega"] - b["omega"]) <= 1e-10 * W1, (a["omega"], b["omega"])
    # Old meaning refused, never silently remapped: an element off the
    # condensed DOFs names the element and the DOF.
    with pytest.raises(ValueError, match="model DOF 0"):
        ivt.hb.solve(m, c, k, ivt.hb.elements.cubic_spring(K3, dof=0), W1, f, nonlinear_dofs=[tip])
