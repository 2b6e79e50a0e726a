"""The optional user Jacobian `jac` of ivt.hb user systems against the
central differences of `g` it replaces: the same orbits, multipliers, folds
and periods (to the differences' own error), fewer calls of `g`, and the
errors of a bad `jac`."""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import pytest

from ivt import hb
from test_hb import chain_2dof

Pair = Tuple[np.ndarray, Optional[np.ndarray]]


def chain_jac(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> Pair:
    """∂g/∂x of the chain's g = [0.5 x1³, 0] for (N, 2) samples; g ignores v."""
    dg_dx = np.zeros(x.shape + (2,))
    dg_dx[:, 0, 0] = 1.5 * x[:, 0] ** 2
    return dg_dx, None


def chain_jac_per_sample(x: np.ndarray, v: np.ndarray, th: float) -> Pair:
    return np.array([[1.5 * x[0] ** 2, 0.0], [0.0, 0.0]]), np.zeros((2, 2))


def chain_g_per_sample(x: np.ndarray, v: np.ndarray, th: float) -> np.ndarray:
    return np.array([0.5 * x[0] ** 3, 0.0])


def test_chain_orbit_and_multipliers_equal_the_differenced_ones() -> None:
    """Both solves converge to ‖r‖ ≤ 1e-13·‖f̂‖ on the upper branch near the
    resonance (ω = 1.1, between the folds), so the orbits agree to ~1e-12 and
    1e-9 is a margin; the stability matrix is built from ∂g itself, and the
    differences err by ~1e-10 relative (step 1e-6 of the orbit's scale:
    O(h²) truncation, O(ε/h) rounding), so 1e-7 bounds the multipliers'
    difference after amplification by the eigenproblem's condition."""
    m, c, k, g, f = chain_2dof()
    common: Dict[str, Any] = dict(n=15, rtol=1e-13, velocity_dependent=False)
    guess = hb.solve(m, c, k, g, 1.0, f=f, vectorized=True, **common)["coeffs"]
    ref = hb.solve(m, c, k, g, 1.1, f=f, vectorized=True, guess=guess, **common)
    runs = [
        hb.solve(m, c, k, g, 1.1, f=f, vectorized=True, guess=guess, jac=chain_jac, **common),
        hb.solve(m, c, k, chain_g_per_sample, 1.1, f=f, guess=guess, jac=chain_jac_per_sample,
                 **common),
    ]
    scale = np.max(np.abs(ref["coeffs"]))
    for got in runs:
        assert np.max(np.abs(got["coeffs"] - ref["coeffs"])) <= 1e-9 * scale
        np.testing.assert_allclose(got["floquet"], ref["floquet"], rtol=0, atol=1e-7)
        assert got["stability"] == ref["stability"]


@pytest.mark.parametrize("events", [True, False])
def test_chain_frc_folds_equal_and_g_is_called_less(events: bool) -> None:
    """The located folds with `jac` equal the differenced ones to 1e-8 in ω (the
    extended systems are solved to ~1e-10; ∂g differs by ~1e-10 relative). With
    `jac` no Jacobian assembly differences `g` (one call on the 2·n_dof = 4
    stacked perturbed copies of a grid each), so `g` runs on the residual's
    2N = 128 samples only. Measured calls of `g` per point: 5.9 → 3.4 with
    events=True and with events=False; the rest are the continuation's residual
    evaluations, which `jac` does not replace (asserted: fewer, and none off
    the residual grid)."""
    m, c, k, g, f = chain_2dof()
    per_point = []
    folds = []
    grids = []
    for jac in (None, chain_jac):
        sizes: List[int] = []

        def g_counted(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
            sizes.append(x.shape[0])
            return g(x, v, th)  # type: ignore[no-any-return]

        frc = hb.frc(m, c, k, g_counted, f, 0.5, 1.6, n=15, events=events, vectorized=True,
                     velocity_dependent=False, jac=jac)
        folds.append([fd["omega"] for fd in frc["folds"]])
        per_point.append(len(sizes) / len(frc["points"]))
        grids.append(set(sizes))
    assert len(folds[0]) == 2 and all(fd["located"] for fd in frc["folds"])
    np.testing.assert_allclose(folds[1], folds[0], rtol=0, atol=1e-8)
    assert 4 * 128 in grids[0] and grids[1] == {128}, grids
    assert per_point[1] < per_point[0], per_point


def test_van_der_pol_period_with_jac_equals_without() -> None:
    """x'' − μ(1 − x²)x' + x = 0 (μ = 1) as C = −μ, g = μx²v with ∂g/∂x = 2μxv,
    ∂g/∂v = μx² (the form of docs/guide/src/model/limit-cycles.md: with C = 0
    and g = μ(x² − 1)v the unforced system's force scale, that of the
    start's linear force, is 0 at ω = 1). Newton converges quadratically either way (‖r‖ ≈ 2e-15 after 5
    iterations, measured), so the periods agree to rounding; 1e-12 relative
    is asserted."""
    mu = 1.0

    def g(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
        return mu * x**2 * v  # type: ignore[no-any-return]

    def jac(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> Pair:
        # (N, 1) in: (N, 1) out is accepted for the expected (N, 1, 1).
        return 2 * mu * x * v, mu * x**2

    common: Dict[str, Any] = dict(amplitude=2.0, n=30, samples=120)
    ref = hb.limit_cycle(1.0, -mu, 1.0, g, 1.0, vectorized=True, **common)
    for got in (
        hb.limit_cycle(1.0, -mu, 1.0, g, 1.0, vectorized=True, jac=jac, **common),
        hb.limit_cycle(1.0, -mu, 1.0, g, 1.0, jac=jac, **common),  # per sample: (1,) arrays
    ):
        assert got["period"] == pytest.approx(ref["period"], rel=1e-12)
        assert got["stable"] and ref["stable"]


def test_jac_errors() -> None:
    m, c, k, g, f = chain_2dof()
    # solve's first Jacobian assembly is Hsu's, on 64 samples (its first
    # level: max(2(n + 1), 32) = 32 steps).
    kw: Dict[str, Any] = dict(f=f, n=8, samples=32, vectorized=True, velocity_dependent=False)
    with pytest.raises(TypeError, match="`jac` must be None when `g` is ivt.hb.elements"):
        hb.solve(1.0, 0.1, 1.0, hb.elements.cubic_spring(1.0), 1.0, jac=lambda x, v, th: (x, None))
    with pytest.raises(TypeError, match="argument `jac` must be callable"):
        hb.frc(m, c, k, g, f, 0.5, 0.6, jac=3.0)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=r"`jac` returned dg_dx of shape \[64, 2\], expected \[64, 2, 2\]"):
        hb.solve(m, c, k, g, 0.9, jac=lambda x, v, th: (x, None), **kw)
    with pytest.raises(ValueError, match=r"`jac` returned dg_dv of shape \[2, 2\], expected \[64, 2, 2\]"):
        hb.solve(m, c, k, g, 0.9, jac=lambda x, v, th: (chain_jac(x, v, th)[0], np.eye(2)), **kw)
    with pytest.raises(ValueError, match=r"`jac` returned a non-finite dg_dx entry \(NaN\) at flat index 0"):
        hb.solve(m, c, k, g, 0.9, jac=lambda x, v, th: (np.nan * chain_jac(x, v, th)[0], None), **kw)
    with pytest.raises(TypeError, match="`jac` must return a pair"):
        hb.limit_cycle(1.0, -1.0, 1.0, lambda x, v, th: x**2 * v, 1.0, jac=lambda x, v, th: 1.0)
    with pytest.raises(ZeroDivisionError):  # the first exception, re-raised after the run
        hb.frc(m, c, k, g, f, 0.5, 0.6, n=8, samples=32, vectorized=True, jac=lambda x, v, th: 1 / 0)


def test_callback_arrays_are_never_changed_by_the_solver() -> None:
    """The arrays a vectorized `g` or `jac` receives are its own: `x` and `v`
    keep the values they had at the call after the run goes on, and the phase
    array (shared by the calls on one sample grid) is read-only."""
    m, c, k, g, f = chain_2dof()
    kept = []

    def g_keeping(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
        kept.append((x, x.copy(), v, v.copy(), th, th.copy()))
        with pytest.raises(ValueError, match="read-only"):
            th[0] = 1.0
        return g(x, v, th)  # type: ignore[no-any-return]

    def jac_keeping(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> Pair:
        kept.append((x, x.copy(), v, v.copy(), th, th.copy()))
        return chain_jac(x, v, th)

    hb.frc(m, c, k, g_keeping, f, 0.9, 1.0, n=8, samples=32, vectorized=True, jac=jac_keeping)
    assert len(kept) > 20 and len({id(t[4]) for t in kept}) < len(kept)
    for arrays in kept:
        for seen, copy in zip(arrays[::2], arrays[1::2]):
            np.testing.assert_array_equal(seen, copy)


def test_backbone_with_jac_is_the_elliptic_closed_form_with_fewer_calls() -> None:
    """The backbone of u'' + u + u³ = 0 followed on the exact Jacobian of
    {q, ω, κ}: with `jac` as without it every point's ω is the closed form
    π √(1 + A²) / (2 K(m)), m = A² / (2(1 + A²)), to 1e-9 relative (the HB
    truncation at n = 20 is ~1e-12), and `g` is called less (no differences
    of it)."""
    from scipy.special import ellipk

    counts = []
    for jac in (None, lambda x, v, th: (3.0 * x[:, :, None] ** 2, None)):
        calls = {"n": 0}

        def g(x: np.ndarray, v: np.ndarray, th: np.ndarray) -> np.ndarray:
            calls["n"] += 1
            return x**3  # type: ignore[no-any-return]

        bb = hb.backbone(1.0, 0.0, 1.0, g, 1.0, [1.0], 0.01, 2.0, velocity_dependent=False,
                         vectorized=True, jac=jac)
        assert bb["termination"] == "left_interval" and bb["amplitude"][-1] >= 2.0
        for p in bb["points"]:
            a = float(hb.eval_series(p["coeffs"], 0.0))
            mm = a * a / (2 * (1 + a * a))
            exact = np.pi * np.sqrt(1 + a * a) / (2 * ellipk(mm))
            assert p["omega"] == pytest.approx(exact, rel=1e-9), a
        counts.append(calls["n"] / len(bb["points"]))
    assert counts[1] < counts[0], counts
