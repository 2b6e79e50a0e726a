"""ivt.design against `ivt ol solve`, `ivt ol table`, `ivt stability` and
`ivt stability-map` (same Rust code: equal numbers), and against SPEC §5's averaged power
balance for the feasible band."""

import math

import numpy as np
import pytest

from ivt import design, kin


def test_ol_solve_equals_cli_and_band(cli) -> None:  # type: ignore[no-untyped-def]
    ref = cli("ol", "solve", "--vm", "8.6", "--tu", "6", "--method", "ihb")  # the n = 7 IHB
    got = design.ol_solve(8.6, 6.0, method="ihb")
    for key in ["r", "feasible", "verdict", "omega_min", "omega_max", "iterations", "residual_norm",
                "r_max", "omega0", "method", "r_ihb", "error_estimate", "thesis_choice"]:
        assert got[key] == ref[key], key
    np.testing.assert_array_equal(got["q"], ref["q"])
    # SPEC §5 averaged balance: V_m = (c ω0 + b T_U r̄)/a, so r̄ ≈ (a V_m − c ω0)/(b T_U)
    # with a = k_t/R_a, b = 2√2/(π r_u), c = (k_t k_e/R_a)·⟨f²⟩; the full IHB differs
    # from this averaged estimate by a few per cent (band edge 7.869 vs 7.93 V).
    p = kin.Plant()
    w0 = 100 * 2 * math.pi / 60
    r_avg = (p.motor_gain * 8.6 - p.motor_damping * kin.mean_f_squared() * w0) / (p.load_gain * 6.0)
    assert got["r"] == pytest.approx(r_avg, rel=0.15)
    assert got["verdict"] == "feasible"
    assert design.ol_solve(6.0, 6.0)["verdict"] == "under-drive"  # below the band (SPEC §5)


def test_ol_solve_is_accurate_by_default_like_cli(cli) -> None:  # type: ignore[no-untyped-def]
    """The default polishes the n = 7 IHB by θ-shooting, as `ivt ol solve`:
    the same r̄ as the CLI's JSON to 1e-12 (the same Rust function; the
    margin covers nothing but float formatting), an error estimate ≤ 1e-6
    relative (the issue's acceptance bound), and r̄ ≈ 0.0068038 m at
    (8 V, 1.5 N·m), where the n = 7 IHB alone gives 0.0065958 m (3.1 % off)."""
    ref = cli("ol", "solve", "--vm", "8", "--tu", "1.5")
    got = design.ol_solve(8.0, 1.5)
    assert got["method"] == ref["method"] == "ihb+shooting"
    assert got["r"] == pytest.approx(ref["r"], rel=1e-12, abs=0)
    assert got["r_ihb"] == pytest.approx(ref["r_ihb"], rel=1e-12, abs=0)
    est = got["error_estimate"]
    assert est["r_abs"] == pytest.approx(ref["error_estimate"]["r_abs"], rel=1e-6, abs=1e-15)
    assert est["r_rel"] <= 1e-6 and est["how"] == ref["error_estimate"]["how"]
    assert got["r"] == pytest.approx(0.0068038, abs=5e-8)
    assert got["r_ihb"] == pytest.approx(0.0065958, abs=5e-8)
    assert got["thesis_choice"] is False
    ihb = design.ol_solve(8.0, 1.5, method="ihb")
    assert ihb["thesis_choice"] is True and ihb["r"] == got["r_ihb"]
    # Its estimate |r̄(7) − r̄(15)| is of the size of the true 3 % error.
    assert 0.3 < ihb["error_estimate"]["r_abs"] / abs(got["r"] - ihb["r"]) < 3.0
    with pytest.raises(ValueError, match="`method`"):
        design.ol_solve(8.0, 1.5, method="newton")  # type: ignore[arg-type]


def test_ol_table_equals_cli(cli) -> None:  # type: ignore[no-untyped-def]
    args = ["--vm-from", "7.6", "--vm-step", "0.4", "--vm-to", "8.8",
            "--tu-from", "2", "--tu-step", "2", "--tu-to", "6", "--quiet"]
    ref = cli("ol", "table", *args)
    got = design.ol_table(v_m=(7.6, 0.4, 8.8), t_u=(2.0, 2.0, 6.0))
    assert got["v_m"] == ref["v_m"] and got["t_u"] == ref["t_u"]
    assert got["r"].shape == (len(ref["t_u"]), len(ref["v_m"]))
    for a, b in zip(got["points"], ref["points"]):
        assert a.get("r") == b.get("r") and a.get("verdict") == b.get("verdict")
    # r̄ grows with V_m along each row (more drive needs more load share).
    assert np.all(np.diff(got["r"], axis=1) > 0)


def test_stability_equals_cli(cli) -> None:  # type: ignore[no-untyped-def]
    ref = cli("stability", "--vm", "8.6", "--tu", "6", "--k", "2", "--k2", "1")
    got = design.stability(8.6, 6.0, k=2.0, k2=1.0)
    for key in ["max_abs_multiplier", "r_bar", "k_si", "k2_si", "stable", "chebyshev_order"]:
        assert got[key] == ref[key], key
    assert got["k_si"] == pytest.approx(2e-3)  # mm·rad⁻¹ → m·s/rad² (ivt-ctrl units)


def test_stability_map_equals_cli(cli) -> None:  # type: ignore[no-untyped-def]
    """Same points, values, worst case and keys as `ivt stability-map --json`
    (one Rust function behind both, so equal to the last bit); each point
    equals `design.stability` there, and the array holds the points row by
    row in T_U."""
    args = ["--vm", "8", "0.4", "8.8", "--tu", "4", "2", "6", "--k", "2", "--k2", "1"]
    ref = cli("stability-map", *args)
    got = design.stability_map(v_m=(8.0, 0.4, 8.8), t_u=(4.0, 2.0, 6.0), k=2.0, k2=1.0)
    for key in ["worst", "failed", "k_si", "k2_si", "plant"]:
        assert got[key] == ref[key], key
    assert set(ref) <= set(got)
    assert got["points"] == ref["points"]
    assert got["failed"] == 0 and len(got["points"]) == 3 * 2
    values = got["max_abs_multiplier"]
    assert values.shape == (len(got["t_u"]), len(got["v_m"])) == (2, 3)
    np.testing.assert_array_equal(values.ravel(), [p["max_abs_multiplier"] for p in got["points"]])
    assert got["worst"] == values.max()
    p = got["points"][4]  # second row (T_U = 6), second column (V_m = 8.4)
    assert (p["vm"], p["tu"]) == (8.4, 6.0)
    assert p["max_abs_multiplier"] == design.stability(8.4, 6.0, k=2.0, k2=1.0)["max_abs_multiplier"]


def test_stability_map_feasible_only_and_failures(cli) -> None:  # type: ignore[no-untyped-def]
    """feasible_only skips the under-drive points (NaN in the array) like
    `--feasible-only`; a map where every point fails is a RuntimeError (the
    CLI's `failed`), never a worst case of 0; a step that would allocate
    without bound is refused by name before allocation."""
    args = ["--vm", "6", "1", "9", "--tu", "6", "1", "6", "--feasible-only"]
    ref = cli("stability-map", *args)
    got = design.stability_map(v_m=(6.0, 1.0, 9.0), t_u=(6.0, 1.0, 6.0), feasible_only=True)
    assert got["points"] == ref["points"] and got["worst"] == ref["worst"]
    skipped = np.isnan(got["max_abs_multiplier"]).sum()
    assert skipped == 4 - len(got["points"]) and skipped >= 1  # 6 V is under-drive (SPEC §5)
    with pytest.raises(RuntimeError, match="every one of the 2 points failed"):
        design.stability_map(v_m=(8.0, 1.0, 9.0), t_u=(1.5, 1.0, 1.5), k=1e6)
    with pytest.raises(ValueError, match="`v_m`"):
        design.stability_map(v_m=(2.0, 1e-300, 12.0))
    with pytest.raises(ValueError, match="`t_u`"):
        design.stability_map(t_u=(9.0, 0.5, 1.5))
    with pytest.raises(ValueError, match="`k2`"):
        design.stability_map(k2=float("nan"))
    with pytest.raises(ValueError, match="`v_m`"):
        design.ol_table(v_m=(2.0, 1e-300, 12.0))


# 7 × 9 points around the feasible band at 100 rpm (≥ the 15 terms of `full`).
_FIT_GRID = dict(v_m=(7.6, 0.2, 8.8), t_u=(2.0, 0.5, 6.0))
_FIT_ARGS = ["--vm-from", "7.6", "--vm-step", "0.2", "--vm-to", "8.8",
             "--tu-from", "2", "--tu-step", "0.5", "--tu-to", "6", "--quiet"]


def test_ol_fit_equals_cli(cli) -> None:  # type: ignore[no-untyped-def]
    """`ol_fit` is `ivt ol fit --json` as a dict (one Rust function behind
    both, so equal to the last bit), with and without `full`."""
    assert design.ol_fit(**_FIT_GRID) == cli("ol", "fit", *_FIT_ARGS)
    got = design.ol_fit(**_FIT_GRID, full=True, plant="printed")
    assert got == cli("ol", "fit", "--full", *_FIT_ARGS)
    assert got["form"] == "full" and got["emitted"] is None


def test_ol_fit_boundaries() -> None:
    """Checks from outside the fit: at r̄ = 0 the brake torque does not reach
    the motor (Eq. 151: the load term is b T_U r), so the under-drive boundary
    has slope 0; on the over-drive line V_m = α T_U + β an independent IHB
    solve (n = 7, as the fit) gives r̄ = r_max."""
    got = design.ol_fit(**_FIT_GRID)
    assert abs(got["underdrive_boundary"]["alpha"]) < 1e-9  # V/(N·m); Newton tol ~1e-12
    _, alpha_neg, beta_neg = got["boundary"]
    assert got["boundary_max_dev_v"] < 1e-9
    for t_u in [2.5, 5.5]:  # between the grid's T_U values
        r = design.ol_solve(-alpha_neg * t_u - beta_neg, t_u, method="ihb")["r"]
        # the line is exact to 1e-9 V here, ∂r̄/∂V_m ~ 0.03 m/V: 1e-9 m is ample
        assert r == pytest.approx(got["r_max"], abs=1e-9), t_u
    # The law refitted on this plant holds ω0 better than the printed one.
    assert got["omega_a_error_rpm"]["max_abs"] < got["thesis_omega_a_error_rpm"]["max_abs"]


def test_ol_fit_errors() -> None:
    with pytest.raises(ValueError, match="`v_m`"):
        design.ol_fit(v_m=(2.0, 0.0, 12.0))
    with pytest.raises(ValueError, match="omega0_rpm"):
        design.ol_fit(omega0_rpm=float("nan"))
    with pytest.raises(ValueError, match="`harmonics` = -1"):
        design.ol_fit(harmonics=-1)
    with pytest.raises(ValueError, match="`plant`"):
        design.ol_fit(plant="nope")
    # 2 × 2 points cannot determine the ten Eq. 158 terms (CLI: kind "input").
    with pytest.raises(ValueError, match="fewer feasible points than polynomial terms"):
        design.ol_fit(v_m=(7.6, 0.4, 8.0), t_u=(2.0, 2.0, 4.0))


def test_design_errors() -> None:
    with pytest.raises(ValueError, match="omega0_rpm"):
        design.ol_solve(8.0, 6.0, omega0_rpm=-1.0)
    with pytest.raises(ValueError):
        design.ol_solve(float("nan"), 6.0)
    with pytest.raises(ValueError, match="`k`"):
        design.stability(8.6, 6.0, k=float("inf"))
    # Counts: a negative value names the argument (not pyo3's bare OverflowError),
    # the Chebyshev order is checked by DelayOptions::validate before any solve.
    with pytest.raises(ValueError, match="`harmonics` = -1"):
        design.ol_solve(8.0, 6.0, harmonics=-1)
    with pytest.raises(ValueError, match="`n` = -1"):
        design.stability(8.6, 6.0, n=-1)
    for n in [0, 3, 66]:
        with pytest.raises(ValueError, match="chebyshev_order"):
            design.stability(8.6, 6.0, n=n)


def test_plant_presets_equal_cli(cli) -> None:  # type: ignore[no-untyped-def]
    """plant="thesis-ch4" is `--plant thesis-ch4` (k_t, k_e ÷ 10); a Plant with
    the printed constants is named "printed"; an unknown name is a ValueError."""
    ref = cli("ol", "solve", "--plant", "thesis-ch4", "--vm", "6", "--tu", "6", "--method", "ihb")
    got = design.ol_solve(6.0, 6.0, plant="thesis-ch4", method="ihb")
    assert got["plant"] == "thesis-ch4" and got["r"] == ref["r"]
    assert abs(got["r"] - 0.0067775) < 1e-6  # the thesis's Fig. 39 orbit (0.0067)
    st = design.stability(8.0, 8.0, plant="thesis-ch4")
    assert st["plant"] == "thesis-ch4"
    assert st["max_abs_multiplier"] == cli("stability", "--plant", "thesis-ch4", "--vm", "8", "--tu", "8")["max_abs_multiplier"]
    assert design.ol_solve(8.6, 6.0, plant=kin.Plant())["plant"] == "printed"
    assert design.ol_table(v_m=(6.0, 1.0, 6.0), t_u=(6.0, 1.0, 6.0), plant="thesis-ch4")["plant"] == "thesis-ch4"
    with pytest.raises(ValueError):
        design.ol_solve(8.0, 6.0, plant="roller")
