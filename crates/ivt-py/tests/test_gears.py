"""GIVT/SGIVT/noncircular gears: the bindings against `ivt kin ... --json`
(same Rust code, so equality is exact through the JSON round trip) and
against closed forms."""

import math

import numpy as np
import pytest

from ivt import kin


def test_sgivt_against_cli(cli) -> None:  # type: ignore[no-untyped-def]
    ref = cli("kin", "sgivt-ratio", "--theta-ct", "1800", "--points", "8")
    s = kin.Sgivt()
    th = kin.deg_to_rad(1800.0)
    e = s.crank_length(th)
    assert e == ref["e"]
    assert s.average_ratio(e) == ref["r_avg"]
    assert s.average_ratio_from_stepper(th) == ref["r_avg"]
    theta_in = np.array([p["theta_in"] for p in ref["samples"]])
    np.testing.assert_array_equal(s.ratio(theta_in, e), [p["ratio"] for p in ref["samples"]])
    assert kin.m_to_inch(e) == pytest.approx(ref["e_inch"], rel=1e-15)
    # Eq. 185: e [in] = 7π/51840·θ_CT [deg]; §4.4.2: R_avg ≈ 7 θ_CT/27492.
    assert kin.m_to_inch(e) == pytest.approx(7 * math.pi / 51840 * 1800, rel=1e-12)
    assert kin.R_AVG_SLOPE_PRINTED_PER_DEG * 1800 == ref["r_avg_printed"]
    np.testing.assert_allclose(s.stepper_angle(s.crank_length([0.5, 10.0, 60.0])), [0.5, 10.0, 60.0], rtol=1e-12)


def test_givt_against_cli(cli) -> None:  # type: ignore[no-untyped-def]
    ref = cli("kin", "givt-ratio", "--r-mm", "5", "--points", "16")
    g = kin.Givt()
    theta = np.array([p["theta"] for p in ref["samples"]])
    np.testing.assert_array_equal(g.single_ratio(theta, 0.005), [p["r1"] for p in ref["samples"]])
    np.testing.assert_array_equal(g.module_ratio(theta, 0.005), [p["module_ratio"] for p in ref["samples"]])
    np.testing.assert_array_equal(g.final_ratio(theta, 0.005), [p["final_ratio"] for p in ref["samples"]])
    assert g.average_module_ratio(0.005) == ref["average_module_ratio"]
    assert g.module_corners(0.005) == ref["corners"]
    # Eq. 10: F = 3R when r_sun = 2 r_planet.
    assert g.crank_to_input == pytest.approx(3.0, rel=1e-15)
    np.testing.assert_allclose(g.final_ratio(theta, 0.005), 3 * g.module_ratio(theta, 0.005), rtol=1e-15)
    # The average of R over a period by an independent quadrature (numpy, 2^14 midpoints).
    n = 1 << 14
    grid = (np.arange(n) + 0.5) * kin.GIVT_MODULE_PERIOD / n
    assert np.mean(g.module_ratio(grid, 0.005)) == pytest.approx(ref["average_module_ratio"], rel=1e-7)


def test_pitch_profile_and_fourier_against_cli(cli) -> None:  # type: ignore[no-untyped-def]
    ref = cli("kin", "pitch-profile", "--design", "sgivt", "--points", "37")
    got = kin.pitch_profile("sgivt", 37)
    for key in ["closure_error", "max_centre_distance_error", "r_driven_min", "r_driven_max", "centre_distance"]:
        assert got[key] == ref[key], key
    np.testing.assert_array_equal(got["r_driving"], [p["r_driving"] for p in ref["points"]])
    # Eq. 15/39: the radii sum to the centre distance D = 5.25 in.
    np.testing.assert_allclose(got["r_driven"] + got["r_driving"], 5.25 * 0.0254, rtol=1e-14)
    fit = cli("kin", "fourier-fit")["coefficients"]
    for row in fit[1:]:
        k = row["k"]
        assert kin.fourier_coefficient_eq38(k) == row["exact"]
        assert row["exact"] == pytest.approx(2 * (-1) ** (k + 1) / (16 * k * k - 1), rel=1e-15)
    assert kin.EQ42_PRINTED == [r["printed"] for r in fit[1:5]]


def test_ncg_ratio_and_direction(cli) -> None:  # type: ignore[no-untyped-def]
    theta = np.linspace(0, 2 * np.pi, 101)
    np.testing.assert_array_equal(kin.ncg_ratio(theta), kin.f(theta))
    smooth = 1 + sum(a * np.cos(4 * (k + 1) * theta) for k, a in enumerate(kin.EQ42_PRINTED))
    np.testing.assert_allclose(kin.ncg_ratio(theta, smooth=True), smooth, rtol=1e-14)
    np.testing.assert_allclose(
        kin.rectified_shape(theta), np.maximum(abs(np.sin(theta)), abs(np.cos(theta))), rtol=1e-15
    )
    ref = cli("kin", "direction", "--r-sun", "2", "--r-planet", "1")
    got = kin.direction(2.0, 1.0)
    for key in ["forward_ratio", "reverse_ratio", "forward_ratio_printed", "reverse_ratio_printed"]:
        assert got[key] == ref[key], key


def test_units_round_trip() -> None:
    assert kin.inch_to_m(1.0) == 0.0254
    assert kin.rpm_to_rad_s(60.0) == pytest.approx(2 * math.pi)
    x = np.linspace(-3, 3, 7)
    np.testing.assert_allclose(kin.rad_to_deg(kin.deg_to_rad(x)), x, rtol=1e-15)
    np.testing.assert_allclose(kin.rad_s_to_rpm(kin.rpm_to_rad_s(x)), x, rtol=1e-15)


def test_gear_errors() -> None:
    with pytest.raises(ValueError, match="theta_ct"):
        kin.Sgivt().crank_length([0.0, -1.0])
    with pytest.raises(ValueError, match="flat index 1"):
        kin.Sgivt().crank_length([0.0, 1e9])
    with pytest.raises(ValueError, match="`r`"):
        kin.Givt().module_ratio(0.1, 0.06)  # r ≥ l1 = 0.05
    with pytest.raises(ValueError, match="`l1`"):
        kin.Givt(l1=-1.0)
    with pytest.raises(TypeError, match="unknown GIVT parameter"):
        kin.Givt(l2=1.0)
    with pytest.raises(ValueError, match="`r_og`"):
        kin.Sgivt(r_og=0.0)
    with pytest.raises(ValueError, match="`design`"):
        kin.pitch_profile("round")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="`points`"):
        kin.pitch_profile("sgivt", 1)
    assert "l1=0.06" in repr(kin.Givt(l1=0.06))
