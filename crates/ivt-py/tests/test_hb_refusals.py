"""Issue 41, items 3–4 from Python: complex inputs, keywords the large-model path
does not read, forced families and failing members are refused with a message
naming the cause; the searches report what exists. References are closed
forms (linear responses, the eigenvalues μ/2 ± √(μ²/4 − 1)), never HB."""

import numpy as np
import pytest
import scipy.sparse as sp

from ivt import hb

F = lambda th: 0.1 * np.cos(th)
CUBIC = lambda x, v, th: 0.5 * x**3


@pytest.mark.parametrize("name", ["m", "c", "k"])
@pytest.mark.parametrize("value", [np.array([[1.0 + 0.5j]]), [[1.0 + 0.0j]], 1.0 + 0.1j])
def test_complex_matrices_are_refused_naming_the_argument(name, value):
    args = {"m": [[1.0]], "c": [[0.02]], "k": [[1.0]]}
    args[name] = value
    with pytest.raises(ValueError, match=f"argument `{name}` is complex"):
        hb.solve(args["m"], args["c"], args["k"], CUBIC, 1.2, F)
    with pytest.raises(ValueError, match=f"argument `{name}` is complex"):
        hb.frc(args["m"], args["c"], args["k"], CUBIC, F, 0.5, 1.5)


@pytest.mark.parametrize("vectorized", [False, True])
def test_complex_callback_values_are_refused_not_truncated(vectorized):
    with pytest.raises(ValueError, match="value of (vectorized )?`g` is complex"):
        hb.solve([[1.0]], [[0.02]], [[1.0]], lambda x, v, th: 0.5 * x**3 + 0.1j, 1.2, F,
                 vectorized=vectorized)
    with pytest.raises(ValueError, match="value of `f` is complex"):
        hb.solve([[1.0]], [[0.02]], [[1.0]], CUBIC, 1.2, lambda th: 0.1 * np.cos(th) + 0j)
    with pytest.raises(ValueError, match="value of `g` is complex"):
        hb.limit_cycle(1.0, 0.0, 1.0, lambda x, v, th: -(1 - x**2) * v + 0j, 1.0)


def _chain():
    k = sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))
    return sp.identity(2, format="csr"), 0.02 * k, k


def test_the_large_model_path_refuses_keywords_it_does_not_read():
    m, c, k = _chain()
    g = hb.elements.cubic_spring(0.5, dof=0)
    load = np.array([0.1, 0.0])
    base = hb.solve(m, c, k, g, 1.2, load)
    assert base["amplitude"] > 0
    for kw in [dict(subharmonic=2), dict(guess=np.zeros(30)), dict(method="classic"),
               dict(max_iter=0), dict(tol=1e-3)]:
        with pytest.raises(ValueError, match="do\\(es\\) not apply to a large model"):
            hb.solve(m, c, k, g, 1.2, load, **kw)
    with pytest.raises(TypeError, match="'smaples'"):
        hb.solve(m, c, k, g, 1.2, load, smaples=40)
    with pytest.raises(ValueError, match="do\\(es\\) not apply"):
        hb.frc(m, c, k, g, load, 0.5, 1.5, events=False)
    with pytest.raises(TypeError, match="'ds_mx'"):
        hb.frc(m, c, k, g, load, 0.5, 1.5, ds_mx=0.1)
    with pytest.raises(ValueError, match="argument `k` is complex"):
        hb.solve(m, c, k * (1 + 0.5j), g, 1.2, load)
    with pytest.raises(ValueError, match="argument `f` is complex"):
        hb.solve(m, c, k, g, 1.2, load * (1 + 1j))


def _vdp(mu):
    """x'' − μx' + x + x²x' = 0: the pair μ/2 ± √(μ²/4 − 1) crosses at μ = 0
    (ω = 1) and turns real at μ = ±2."""
    return ([[1.0]], [[-mu]], [[1.0]], lambda x, v, th: x * x * v)


@pytest.mark.parametrize("interval", [(-0.2, 2.5), (-5.0, 5.0), (-1000.0, 1000.0)])
def test_cycle_branch_reports_only_the_hopf_point_where_the_pair_crosses(interval):
    # The branch itself is cut at 40 points (the Hopf search covers the range).
    out = hb.cycle_branch(_vdp, *interval, max_points=40, n=10, samples=32)
    assert [round(h["p"], 12) for h in out["hopf"]] == [0.0]
    assert abs(out["hopf"][0]["omega"] - 1.0) < 1e-12
    assert out["hopf_undecided"] == []
    assert out["termination"] in ("left_interval", "max_points") and out["points"]


def test_cycle_branch_refuses_a_forced_family_and_names_a_failing_member():
    forced = lambda mu: (*_vdp(mu), lambda th: [0.1 * np.cos(th)])
    with pytest.raises(ValueError, match="excitation f"):
        hb.cycle_branch(forced, -0.2, 0.1)
    parametric = lambda mu: ([[1.0]], [[-mu]], [[1.0]], lambda x, v, th: x * x * v + 0.2 * np.cos(th) * x)
    with pytest.raises(ValueError, match="depends on θ"):
        hb.cycle_branch(parametric, -0.2, 0.1)
    with pytest.raises(ValueError, match="depends on θ"):
        hb.limit_cycle(1.0, -1.0, 1.0, lambda x, v, th: x * x * v + 0.2 * np.cos(th), 1.0)
    nan_late = lambda mu: ([[1.0]], [[-mu]], [[1.0]],
                           (lambda x, v, th: x * x * v) if mu < 0.05 else (lambda x, v, th: x * np.nan))
    with pytest.raises(ValueError, match="g returned NaN"):
        hb.cycle_branch(nan_late, -0.2, 0.1)
    resized = lambda mu: _vdp(mu) if mu < 0.05 else (np.eye(2), -mu * np.eye(2), np.eye(2),
                                                      lambda x, v, th: x * x * v)
    with pytest.raises(ValueError, match="changes size"):
        hb.cycle_branch(resized, -0.2, 0.1)


def test_all_solutions_finds_what_exists_once_and_refuses_a_resonance():
    xi, force = 0.02, 0.1
    for omega in (1e3, 1e6):
        found = hb.all_solutions(1.0, 2 * xi, 1.0, CUBIC, lambda th: force * np.cos(th), omega)
        assert len(found) == 1 and found.search["exhausted"]
        d = (1 - omega**2) ** 2 + (2 * xi * omega) ** 2
        a1 = force * (1 - omega**2) / d
        assert abs(found[0]["coeffs"][1] - a1) <= 1e-9 * abs(a1)
        assert "1 failed run per start" in found.search["bound"]
    linear = lambda x, v, th: 0.0 * x
    found = hb.all_solutions(1.0, 0.0, 1.0, linear, lambda th: force * np.cos(th), 0.7)
    assert len(found) == 1 and abs(found[0]["coeffs"][1] - force / (1 - 0.49)) < 1e-10
    with pytest.raises(ValueError, match="singular at harmonic 1 "):
        hb.all_solutions(1.0, 0.0, 1.0, linear, lambda th: force * np.cos(th), 1.0)
    free = hb.all_solutions(1.0, 0.0, 1.0, lambda x, v, th: x**3, None, 1.4)
    assert len(free) == 3 and free.search["copies_merged"] >= 2
