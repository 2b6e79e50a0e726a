"""Large solids (issue 42): the steel plate of scikit-fem tetrahedra through
ivt.hb.frc, reduced once on a certified basis (reduction="krylov", the
"auto" choice for a solid of 1000 DOFs or more) against the exact condensed
path on the whole plate, Matrix Market input, and the refusals."""

import numpy as np
import pytest
import scipy.io
import scipy.sparse.linalg as spla

import ivt

pytest.importorskip("skfem")

ZETA = 0.005


def plate(nx):
    """The plate with C = 2ζω₁M, its ω₁ (scipy's shift-invert eigsh), the
    tip DOF and the unit load there."""
    m, k, tip = ivt.hb.models.plate(nx)
    w1 = float(np.sqrt(spla.eigsh(k.tocsc(), 1, m.tocsc(), sigma=0.0, which="LM")[0][0]))
    c = (2.0 * ZETA * w1) * m
    f = np.zeros(m.shape[0])
    f[tip] = 1.0
    return m, c, k, tip, f, w1


def cubic(k3, dof):
    """A cubic spring from model DOF `dof` to the ground."""
    return ivt.hb.elements.cubic_spring(k3, dof=dof)


def k3_for_two_folds(k, tip):
    """k3 = 1.5e-4·k_tip³ (F = 1 N): two folds inside 0.8–1.3 ω₁ on every
    mesh of the family (k_tip the static tip stiffness)."""
    e = np.zeros(k.shape[0])
    e[tip] = 1.0
    return 1.5e-4 / spla.spsolve(k.tocsc(), e)[tip] ** 3


def test_scikit_fem_plate_has_the_rust_plates_first_frequency():
    # The same mesh assembled by ivt-hb's models::plate (Rust,
    # tests/reduce.rs: ω₁ = 297.634767407434 from the dense eigenproblem).
    *_, w1 = plate(20)
    assert abs(w1 - 297.634767407434) < 1e-9 * w1


def test_reduced_curve_equals_the_exact_condensed_curve():
    m, c, k, tip, f, w1 = plate(10)  # 270 DOFs: the exact curve in seconds
    k3 = k3_for_two_folds(k, tip)
    args = (m, c, k, cubic(k3, tip), f, 0.8 * w1, 1.3 * w1)
    red = ivt.hb.frc(*args, nonlinear_dofs=[tip], reduction="krylov", record_dofs=[tip, 0])
    # The exact path's own stability basis does not converge on a solid (the
    # issue's 134 s at this size): the folds alone are compared.
    exact = ivt.hb.frc(*args, nonlinear_dofs=[tip], reduction="exact", stability=False)
    assert red["method"] == "reduced" and exact["method"] == "exact"
    assert exact["reduction"] is None
    r = red["reduction"]
    assert r["method"] == "krylov_static" and r["n_dof"] == m.shape[0]
    assert r["error_estimate"] <= 1e-8 and len(r["sampled"]) == 3
    assert all(s["error"] <= 1e-8 for s in r["sampled"])
    assert r["basis"] < m.shape[0] // 5
    assert [fd["located"] for fd in red["folds"]] == [True, True]
    for a, b in zip(red["folds"], exact["folds"]):
        assert abs(a["omega"] - b["omega"]) <= 1e-6 * b["omega"], (a["omega"], b["omega"])
    # The reduced curve's amplitude, interpolated at the exact curve's ω on
    # its first (lower) branch, before the first fold.
    end = exact["folds"][0]["index"]
    wr, ar = red["omega"][: red["folds"][0]["index"]], red["amplitude"][: red["folds"][0]["index"]]
    we, ae = exact["omega"][:end], exact["amplitude"][:end]
    inside = (we > wr[0]) & (we < wr[-1])
    # Linear interpolation between reduced points is the coarse part here;
    # the orbits themselves agree to 1e-10 (tests/reduce.rs).
    assert np.max(np.abs(np.interp(we[inside], wr, ar) - ae[inside]) / ae[inside]) < 5e-2
    # Recorded DOFs are DOFs of the whole plate: the tip's equals the orbit.
    p = red["points"][10]
    assert np.allclose(p["dof_coeffs"][tip], p["coeffs"], rtol=0, atol=1e-12 * np.abs(p["coeffs"]).max())
    assert np.abs(p["dof_coeffs"][0]).max() > 0.0
    # Stability decided at every point, unstable between the folds.
    kinds = [p["stability"] for p in red["points"]]
    assert "uncertain" not in kinds
    flips = sum(1 for a, b in zip(kinds, kinds[1:]) if a != b)
    assert flips == 2, kinds
    assert max(p["multiplier_error"] for p in red["points"]) < 1e-3


def test_auto_reduces_solids_and_keeps_beams_exact():
    m, c, k, tip = ivt.hb.models.cantilever(600)  # 1200 DOFs, banded
    f = np.zeros(m.shape[0])
    f[tip] = 0.005
    out = ivt.hb.frc(m, c, k, cubic(200.0, tip), f, 3.5, 3.52, nonlinear_dofs=[tip], stability=False)
    assert out["method"] == "exact"
    m, c, k, tip, f, w1 = plate(20)  # 900 DOFs: below the threshold
    out = ivt.hb.frc(m, c, k, cubic(1e12, tip), f, 0.8 * w1, 0.82 * w1, nonlinear_dofs=[tip], stability=False)
    assert out["method"] == "exact"


def test_matrix_market_files_give_the_same_curve(tmp_path):
    m, c, k, tip, f, w1 = plate(10)
    paths = []
    for name, a in (("m", m), ("c", c), ("k", k)):
        path = tmp_path / f"{name}.mtx"
        scipy.io.mmwrite(str(path), a, precision=17)
        paths.append(path)
    args = (cubic(1e12, tip), f, 0.9 * w1, 1.0 * w1)
    a = ivt.hb.frc(m, c, k, *args, nonlinear_dofs=[tip], reduction="krylov", stability=False)
    b = ivt.hb.frc(*paths, *args, nonlinear_dofs=[tip], reduction="krylov", stability=False)
    assert np.array_equal(a["omega"], b["omega"]) and np.array_equal(a["amplitude"], b["amplitude"])


def test_refusals_are_clean():
    m, c, k, tip, f, w1 = plate(10)
    with pytest.raises(ValueError, match="structural damping"):
        ivt.hb.frc(m, c, k * (1 + 0.01j), cubic(1e12, tip), f, 0.9 * w1, w1, nonlinear_dofs=[tip])
    with pytest.raises(ValueError, match="reduction"):
        ivt.hb.frc(m, c, k, cubic(1e12, tip), f, 0.9 * w1, w1, nonlinear_dofs=[tip], reduction="modal")
    with pytest.raises(ValueError, match="positive definite"):
        # No clamp: K is singular.
        import skfem

        mesh = skfem.MeshTet.init_tensor(*(np.linspace(0, s, 3) for s in (0.2, 0.1, 0.02)))
        mf, kf, _, _ = ivt.hb.models.solid(mesh, lambda x: np.zeros(x.shape[1], dtype=bool))
        ff = np.zeros(mf.shape[0])
        ff[-1] = 1.0
        ivt.hb.frc(mf, 0.0 * mf, kf, cubic(1.0, mf.shape[0] - 1), ff, 1e3, 2e3, nonlinear_dofs=[mf.shape[0] - 1],
                   reduction="krylov")
    with pytest.raises(ValueError, match="cannot read"):
        ivt.hb.frc("/nonexistent.mtx", c, k, cubic(1.0, tip), f, 1.0, 2.0, nonlinear_dofs=[tip])
