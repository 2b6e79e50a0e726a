"""Two-parameter curves of Neimark–Sacker points (issue 27, item 1) through
`hb.continue_bifurcation`: the job of the Rust test
crates/ivt-hb/tests/ns_points.rs, whose reference values, quoted here, are
by RK4 shooting (independent of HB)."""
import numpy as np

from ivt import hb


def test_continue_bifurcation_van_der_pol_neimark_sacker_curve():
    family = lambda F: (1.0, -0.2, 1.0, lambda x, v, th: 0.2 * x * x * v,
                        lambda th: F * np.cos(th))
    frc = hb.frc(*family(0.2), 0.5, 1.6, n=9, samples=32, events=True, vectorized=True)
    [start] = [b for b in frc["bifurcations"]
               if b["kind"] == "neimark_sacker" and abs(b["omega"] - 0.945) < 0.01]
    curve = hb.continue_bifurcation(family, start, 0.0, 0.3, at=[0.3], p_start=0.2,
                                    n=9, samples=32, vectorized=True, ds=0.01, ds_max=0.02,
                                    max_points=400)
    assert curve["kind"] == "neimark_sacker" and curve["termination"] == "left_interval"
    assert all(0 < p["angle"] < np.pi for p in curve["points"])
    # By shooting: the curve ends at the 1:1 resonance on the fold curve at
    # F = 0.1924005859; the NS point at F = 0.3 is at ω = 0.8980504973.
    [r11] = curve["special"]
    assert r11["kind"] == "resonance_1_1" and abs(r11["p"] - 0.1924005859) < 1e-7
    assert r11["angle"] == 0.0
    [at] = curve["at"]
    assert at["p"] == 0.3 and abs(at["omega"] - 0.8980504973) < 1e-7, at["omega"]


def test_continue_bifurcation_refuses_a_branch_point_start():
    family = lambda F: (1.0, -0.2, 1.0, lambda x, v, th: 0.2 * x * x * v,
                        lambda th: F * np.cos(th))
    start = {"kind": "branch_point", "omega": 1.0, "coeffs": np.zeros(19)}
    try:
        hb.continue_bifurcation(family, start, 0.0, 0.3, p_start=0.2, n=9, samples=32)
    except ValueError as e:
        assert "branch_point" in str(e)
    else:
        raise AssertionError("a branch point start must be refused")
