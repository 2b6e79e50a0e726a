"""ivt.kin against closed forms (numpy) and the CLI's `ivt kin plant --json`."""

import math
import pickle

import numpy as np
import pytest

import ivt
from ivt import kin

A = math.pi / (2 * math.sqrt(2))  # Eq. 43 amplitude


def f_closed(theta: np.ndarray) -> np.ndarray:
    return A * np.maximum(np.abs(np.sin(theta)), np.abs(np.cos(theta)))


def test_f_matches_eq43_closed_form() -> None:
    theta = np.linspace(-7.0, 7.0, 2001)
    np.testing.assert_allclose(kin.f(theta), f_closed(theta), rtol=0, atol=1e-15)
    assert kin.NCG_AMPLITUDE == pytest.approx(A, rel=1e-16)


def test_f_theta_is_derivative_of_f() -> None:
    # Central differences away from the corners θ = π/4 + kπ/2 (Eq. 139 jumps there);
    # h = 1e-6 gives truncation ~h²·f''' ≈ 1e-12 and rounding ~1e-16/h = 1e-10.
    theta = np.linspace(0.0, 2 * np.pi, 997)
    phase = np.mod(theta + np.pi / 4, np.pi / 2)
    theta = theta[(phase > 1e-3) & (phase < np.pi / 2 - 1e-3)]
    h = 1e-6
    fd = (f_closed(theta + h) - f_closed(theta - h)) / (2 * h)
    np.testing.assert_allclose(kin.f_theta(theta), fd, rtol=0, atol=1e-8)


def test_means_over_a_period() -> None:
    # ⟨f⟩ = 1 (the gears keep the mean ratio) and ⟨f²⟩ = π²/8 (1/2 + 1/π), SPEC §5;
    # the midpoint rule on 2^16 points of a piecewise-smooth periodic function is
    # accurate to ~1e-9.
    n = 1 << 16
    theta = (np.arange(n) + 0.5) * 2 * np.pi / n
    assert np.mean(kin.f(theta)) == pytest.approx(1.0, abs=1e-9)
    assert np.mean(kin.f(theta) ** 2) == pytest.approx(kin.mean_f_squared(), abs=1e-9)
    assert kin.mean_f_squared() == pytest.approx(np.pi**2 / 8 * (0.5 + 1 / np.pi), rel=1e-15)


def test_scalar_in_float_out_and_broadcasting() -> None:
    assert isinstance(kin.f(0.3), float)
    assert isinstance(kin.f(1), float)  # ints convert
    out = kin.output_speed(np.zeros((3, 1)), np.ones(4), 0.005)
    assert out.shape == (3, 4) and out.dtype == np.float64
    assert kin.f([[0.1, 0.2]]).shape == (1, 2)
    assert kin.f(np.array([], dtype=np.float32)).shape == (0,)


def test_speed_chain_eq44_to_eq47() -> None:
    rng = np.random.default_rng(7)
    theta, omega, r = rng.uniform(0, 7, 50), rng.uniform(1, 20, 50), rng.uniform(0, 0.012, 50)
    w, wc = rng.uniform(-5, 5, 50), rng.uniform(-5, 5, 50)
    r1, r2 = kin.ring_speeds(w, wc, d_s=1.0, d_p=2.0)
    np.testing.assert_allclose(r1, (2 * 3 * w + wc) / 5, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(r2, (2 * 3 * w - wc) / 5, rtol=1e-15, atol=1e-15)
    v1, v2 = kin.driver_speeds(theta, omega, r)
    np.testing.assert_allclose(v1, omega * r * np.sin(theta), rtol=1e-15)
    np.testing.assert_allclose(v2, omega * r * np.cos(theta), rtol=1e-15)
    # Eq. 47: ω_U/ω_m is the constant 2√2 r/(π r_u) at every θ, with ω_m = f(θ)ω.
    w_u = kin.output_speed(theta, omega, r, r_u=0.0222)
    ratio = w_u / (kin.f(theta) * omega)
    np.testing.assert_allclose(ratio, kin.output_to_motor_ratio(r, 0.0222), rtol=1e-13)
    np.testing.assert_allclose(
        kin.output_to_motor_ratio(r), 2 * np.sqrt(2) * r / (np.pi * 0.0222), rtol=1e-15
    )


def test_plant_summary_equals_cli(cli) -> None:  # type: ignore[no-untyped-def]
    ref = cli("kin", "plant")
    got = kin.Plant().summary()
    for key, value in ref.items():
        assert got[key] == value, key  # same f64 through JSON round trip: exact


def test_plant_thesis_constants_section_4_1() -> None:
    p = kin.Plant()
    # §4.1 prints J_a = 0.0237, J_b = 2.1264, J_c = 0.3388 (half a unit in the last place)
    assert p.j_a == pytest.approx(0.0237, abs=0.5e-4)
    assert p.j_b == pytest.approx(2.1264, abs=0.5e-4)
    assert p.j_c == pytest.approx(0.3388, abs=0.5e-4)
    assert p.load_gain == pytest.approx(40.5548, abs=0.5e-4)
    assert p.r_max == 0.012


def test_plant_terms_and_acceleration_eq151() -> None:
    p = kin.Plant()
    s = p.summary()
    theta = np.linspace(0.05, 6.2, 40)
    r, v_m, t_u, omega = 0.007, 6.0, 5.0, 9.0
    t = p.terms(theta, r, v_m, t_u)
    f = f_closed(theta)
    j = s["j_a"] + s["j_b"] * r**2 + s["j_c"] * r**2 * f**2 + s["j_d"] * f**2
    np.testing.assert_allclose(t["j"], j, rtol=1e-14)
    np.testing.assert_allclose(t["g"], 9.8 * (np.sin(theta) + np.cos(theta)), rtol=1e-14)
    np.testing.assert_allclose(t["f1"], s["motor_gain"] * f * v_m, rtol=1e-14)
    np.testing.assert_allclose(t["f2"], s["load_gain"] * f * t_u, rtol=1e-14)
    np.testing.assert_allclose(t["f_m"], s["motor_damping"] * f**2, rtol=1e-14)
    acc = (t["g"] * r + t["f1"] - t["f2"] * r - 0.5 * t["j_theta"] * omega**2 - t["f_m"] * omega) / t["j"]
    np.testing.assert_allclose(p.acceleration(theta, omega, r, v_m, t_u), acc, rtol=1e-13)
    assert set(t) == {"f", "f_theta", "j", "j_theta", "j_r", "j_theta_r", "g", "f_m", "f1", "f2"}


def test_plant_overrides_replace_pickle() -> None:
    p = kin.Plant(r_a=0.3, gravity="roller_mass")
    assert p.motor_gain == pytest.approx(0.76 / 0.3)
    assert p.gravity_gain == pytest.approx(1.16 * 9.8)
    assert kin.Plant(**p.params()) == p
    assert pickle.loads(pickle.dumps(p)) == p
    q = p.replace(r_a=0.24, gravity="printed")
    assert q == kin.Plant() and q != p
    assert "r_a=0.3" in repr(p)


def test_errors_name_the_argument() -> None:
    with pytest.raises(ValueError, match="`theta` is not finite"):
        kin.f(float("nan"))
    with pytest.raises(ValueError, match=r"`r` is not finite \(inf\) at flat index 2"):
        kin.output_speed(0.1, 1.0, [0.0, 0.001, np.inf])
    with pytest.raises(ValueError, match="`theta`"):
        kin.f("abc")
    with pytest.raises(TypeError, match="`theta`"):
        kin.f(object())
    with pytest.raises(ValueError, match="cannot be broadcast"):
        kin.driver_speeds(np.zeros(3), np.zeros(2), 0.0)
    with pytest.raises(ValueError, match="`r_u`"):
        kin.output_speed(0.1, 1.0, 0.001, r_u=0.0)
    with pytest.raises(ValueError, match="`r_u` = -1"):
        kin.Plant(r_u=-1.0)
    with pytest.raises(ValueError, match="`k_t`"):
        kin.Plant(k_t=float("nan"))
    with pytest.raises(TypeError, match="unknown plant parameter `foo`"):
        kin.Plant(foo=1.0)
    with pytest.raises(ValueError, match="`gravity`"):
        kin.Plant(gravity="moon")
    with pytest.raises(TypeError):
        kin.f()  # type: ignore[call-overload]


def test_version() -> None:
    assert isinstance(ivt.__version__, str) and ivt.__version__
