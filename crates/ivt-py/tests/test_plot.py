"""ivt.plot draws what the results say: the artists are checked, not the
pixels — the dashed lines are exactly the unstable points, one marker sits
at each event's located (ω, amplitude), the axes are labelled — on results of
the ivt.hb functions as they return them. matplotlib's figures are made
without pyplot (the Agg canvas when saved)."""

import math
import subprocess
import sys
from typing import Any, Dict, List, Sequence, Tuple

import numpy as np
import pytest
from matplotlib.figure import Figure

from ivt import hb, plot

Pt = Tuple[float, float]


def duffing(F: float = 0.1) -> Tuple[Any, ...]:
    return (1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0), lambda th: F * math.cos(th))


def dashed(ax: Any) -> List[List[Pt]]:
    return [list(map(tuple, line.get_xydata())) for line in ax.lines if line.get_linestyle() == "--"]


def solid(ax: Any) -> List[List[Pt]]:
    return [list(map(tuple, line.get_xydata())) for line in ax.lines if line.get_linestyle() == "-"]


def events(ax: Any) -> List[Tuple[str, Pt]]:
    """(legend label or the text beside it, position) of every event marker."""
    markers = [line for line in ax.lines if line.get_gid() == "event"]
    texts = {tuple(t.xy): t.get_text() for t in ax.texts}
    return [(texts[tuple(m.get_xydata()[0])], tuple(m.get_xydata()[0])) for m in markers]


def runs(points: Sequence[Dict[str, Any]], key: str = "amplitude", x: str = "omega") -> List[List[Pt]]:
    """The runs of unstable points, in order."""
    out: List[List[Pt]] = []
    previous = True
    for p in points:
        if not p["stable"]:
            if previous:
                out.append([])
            out[-1].append((p[x], p[key]))
        previous = bool(p["stable"])
    return out


@pytest.fixture(scope="module")
def duffing_curve() -> Dict[str, Any]:
    return hb.frc(*duffing(), 0.5, 2.5, n=8, samples=32, velocity_dependent=False)


def test_frc_dashes_exactly_the_unstable_points_and_marks_each_event_once(duffing_curve: Dict[str, Any]) -> None:
    fig = plot.frc(duffing_curve)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    pts = duffing_curve["points"]
    assert dashed(ax) == runs(pts) and len(runs(pts)) == 1 and len(runs(pts)[0]) > 3
    # every point of the curve is on a solid or a dashed line; the solid lines
    # hold every stable point
    on_solid = {p for line in solid(ax) for p in line}
    assert {(p["omega"], p["amplitude"]) for p in pts if p["stable"]} <= on_solid
    # one marker per event (the two folds), at its located (ω, amplitude)
    bif = duffing_curve["bifurcations"]
    assert [b["kind"] for b in bif] == ["fold", "fold"]
    assert events(ax) == [("fold", (b["omega"], b["amplitude"])) for b in bif]
    # each fold's amplitude is that of its located orbit (max |x| over the period)
    for b in bif:
        tau = np.linspace(0, 2 * np.pi, 4096, endpoint=False)
        assert abs(np.abs(hb.eval_series(b["coeffs"], tau)).max() / b["amplitude"] - 1) < 1e-3
    assert ax.get_xlabel() == "ω" and ax.get_ylabel() == "max |x|"
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["stable", "unstable", "fold"]


def test_frc_of_duffing_frc_whose_folds_are_numbers() -> None:
    curve = hb.duffing_frc(n=8, samples=32)
    assert all(isinstance(f, float) for f in curve["folds"])
    ax = plot.frc(curve).axes[0]
    got = events(ax)
    assert [label for label, _ in got] == ["fold", "fold"]
    assert [w for _, (w, _) in got] == curve["folds"]


def test_folds_given_by_omega_alone_are_drawn_at_the_turning_point() -> None:
    # A result with numbers as folds and no bifurcations: the marker sits on
    # the path point where ω turns nearest the fold.
    pts = [{"omega": w, "amplitude": a, "stable": s} for w, a, s in
           [(1.0, 1.0, True), (1.5, 2.0, True), (1.6, 2.5, False), (1.4, 2.2, False), (1.2, 1.5, True)]]
    ax = plot.frc({"points": pts, "folds": [1.61]}).axes[0]
    assert events(ax) == [("fold", (1.61, 2.5))]
    assert dashed(ax) == [[(1.6, 2.5), (1.4, 2.2)]]
    # the stable runs reach over to the unstable neighbours: one connected curve
    assert solid(ax) == [[(1.0, 1.0), (1.5, 2.0), (1.6, 2.5)], [(1.4, 2.2), (1.2, 1.5)]]


def test_frc_of_the_string_uses_its_norm_and_folds() -> None:
    s = hb.string(kd=30.0, modes=3, harmonics=7, ns=32, ms=32, from_=3.0, to=5.0)
    ax = plot.frc(s).axes[0]
    assert ax.get_ylabel() == "‖a‖ (Eq. 114)"
    assert dashed(ax) == runs(s["points"], key="norm") and dashed(ax)
    assert len(s["folds"]) == 2
    assert events(ax) == [("fold", (f["omega"], f["norm"])) for f in s["folds"]]


def test_events_of_a_forced_van_der_pol_curve_are_labelled_by_kind() -> None:
    vdp = hb.frc(1.0, 0.0, 1.0, lambda x, v, th: -0.2 * (1 - x**2) * v,
                 lambda th: 0.2 * np.cos(th), 0.6, 1.6, n=9, samples=32, vectorized=True)
    ax = plot.frc(vdp).axes[0]
    want = [(plot.EVENT_LABELS[b["kind"]], (b["omega"], b["amplitude"])) for b in vdp["bifurcations"]]
    assert ("NS", want[[w[0] for w in want].index("NS")][1]) in events(ax)
    assert events(ax) == want
    assert dashed(ax) == runs(vdp["points"])


def test_frc_of_a_switched_branch_and_of_a_large_model() -> None:
    # switch_branch: the keys of frc; the period-2 branch of the well.
    well_g = lambda x, v, th: x * x * (3.0 + x)  # noqa: E731
    well_f = lambda th: 0.5 * math.cos(th)  # noqa: E731
    curve = hb.frc(1.0, 0.1, 2.0, well_g, well_f, 3.6, 2.2, n=6, samples=24,
                   velocity_dependent=False, vectorized=True)
    pd = next(e for e in curve["bifurcations"] if e["kind"] == "period_doubling")
    two = hb.switch_branch(1.0, 0.1, 2.0, well_g, well_f, at=pd, to=2.2, n=6, samples=24,
                           velocity_dependent=False, vectorized=True)
    ax = plot.frc(two).axes[0]
    assert dashed(ax) == runs(two["points"])
    assert events(ax) == [(plot.EVENT_LABELS[b["kind"]], (b["omega"], b["amplitude"]))
                          for b in two["bifurcations"]]
    # a condensed model: its folds are dicts of the tip's amplitude, no bifurcations
    m, c, k, tip = hb.models.cantilever(4)
    f = np.zeros(m.shape[0])
    f[tip] = 0.005
    w1 = 1.8751041**2
    big = hb.frc(m, c, k, lambda x, v, th: 200.0 * x**3, f, 0.7 * w1, 1.3 * w1,
                 nonlinear_dofs=[tip], stability=False)
    ax = plot.frc(big).axes[0]
    assert "bifurcations" not in big and len(big["folds"]) == 2
    assert events(ax) == [("fold", (fd["omega"], fd["amplitude"])) for fd in big["folds"]]
    assert dashed(ax) == []  # stability=False: no verdict, drawn solid



def test_amplitude_dof_moves_the_events_with_the_points() -> None:
    m, c, k = np.eye(2), 0.02 * np.eye(2), np.array([[2.0, -1.0], [-1.0, 2.0]])

    def g(x: Any, v: Any, th: Any) -> Any:
        out = np.zeros_like(x)
        out[:, 0] = 0.5 * x[:, 0] ** 3
        return out

    curve = hb.frc(m, c, k, g, lambda th: [0.1 * np.cos(th), 0.0], 0.9, 1.3, n=7,
                   vectorized=True, velocity_dependent=False, amplitude_dof=1)
    for e in curve["folds"] + curve["bifurcations"]:
        tau = np.linspace(0, 2 * np.pi, 4096, endpoint=False)
        x1 = hb.eval_series(np.asarray(e["coeffs"]).reshape(2, -1)[1], tau)
        assert abs(np.abs(x1).max() / e["amplitude"] - 1) < 1e-6
    ax = plot.frc(curve).axes[0]
    assert [p for _, p in events(ax)] == [(b["omega"], b["amplitude"]) for b in curve["bifurcations"]]


def test_curve2_draws_the_fold_curve_its_cusp_and_the_at_points() -> None:
    curve = hb.duffing_folds(n=8, samples=32)
    ax = plot.curve2(curve).axes[0]
    line = ax.lines[0]
    assert list(map(tuple, line.get_xydata())) == [(p["omega"], p["p"]) for p in curve["points"]]
    assert line.get_label() == "fold curve"
    at = [ln for ln in ax.lines if ln.get_label().startswith("located")]
    assert list(map(tuple, at[0].get_xydata())) == [(p["omega"], p["p"]) for p in curve["at"]]
    assert events(ax) == [("cusp", (s["omega"], s["p"])) for s in curve["special"]]
    assert len(curve["special"]) == 1
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("ω", "p")


def test_curve2_of_a_neimark_sacker_curve_labels_its_resonance() -> None:
    vdp = lambda F: (1.0, -0.2, 1.0, lambda x, v, th: 0.2 * x * x * v, lambda th: F * np.cos(th))  # noqa: E731
    frc = hb.frc(*vdp(0.2), 0.5, 1.6, n=7, samples=32, vectorized=True)
    [start] = [b for b in frc["bifurcations"] if b["kind"] == "neimark_sacker"]
    torus = hb.continue_bifurcation(vdp, start, 0.0, 0.25, at=[0.25], p_start=0.2, n=7,
                                    samples=32, vectorized=True, ds=0.01, ds_max=0.02)
    ax = plot.curve2(torus).axes[0]
    assert ax.lines[0].get_label() == "Neimark–Sacker curve"
    assert events(ax) == [("1:1", (s["omega"], s["p"])) for s in torus["special"]]
    assert [s["kind"] for s in torus["special"]] == ["resonance_1_1"]


def test_curve2_of_a_fold_of_limit_cycles_is_drawn_in_nu_mu() -> None:
    family = lambda mu, nu: (1.0, -mu, 1.0, lambda x, v, th: -(nu * x * x - x**4) * v, None)  # noqa: E731
    curve = hb.cycle_fold_curve(family, 1.0, 0.6, -0.2, 0.1, at=[0.7], n=10, samples=48, vectorized=True)
    ax = plot.curve2(curve).axes[0]
    assert list(map(tuple, ax.lines[0].get_xydata())) == [(p["nu"], p["mu"]) for p in curve["points"]]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("ν", "μ")


def test_cycles_dashes_the_unstable_cycles_and_marks_hopf_and_fold() -> None:
    family = lambda mu: (1.0, -mu, 1.0, lambda x, v, th: -(x * x - x**4) * v, None)  # noqa: E731
    out = hb.cycle_branch(family, -0.2, 0.1, at=[-0.1], n=12, samples=64)
    ax = plot.cycles(out).axes[0]
    assert dashed(ax) == runs(out["points"], x="p") and dashed(ax)
    [hopf] = out["hopf"]
    [fold] = out["bifurcations"]
    assert events(ax) == [("Hopf", (hopf["p"], 0.0)), ("fold", (fold["p"], fold["amplitude"]))]
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("p", "max |x|")


def test_backbone_is_drawn_at_its_peak_over_the_frc_axes(duffing_curve: Dict[str, Any]) -> None:
    fig = plot.frc(duffing_curve)
    bb = hb.backbone(1.0, 0.0, 1.0, hb.elements.cubic_spring(1.0), 1.0, [1.0], 0.01, 1.5, n=8, samples=32)
    assert plot.backbone(bb, fig.axes[0]) is fig
    line = fig.axes[0].lines[-1]
    assert line.get_label() == "backbone"
    assert list(map(tuple, line.get_xydata())) == [(p["omega"], p["peak"]) for p in bb["points"]]
    tau = np.linspace(0, 2 * np.pi, 8192, endpoint=False)
    for p in bb["points"][:: max(1, len(bb["points"]) // 8)]:
        exact = np.abs(hb.eval_series(p["coeffs"], tau)).max()  # max |x|, an independent grid
        assert abs(p["peak"] / exact - 1) < 1e-4 and p["peak"] > p["amplitude"] * 0.999
    dm = hb.damped_modes(1.0, 0.04, 1.0, hb.elements.cubic_spring(1.0), 0.01, 1.0, n=8, samples=32)
    ax = plot.backbone(dm).axes[0]
    assert ax.lines[0].get_label() == "damped mode"
    assert list(map(tuple, ax.lines[0].get_xydata())) == [(p["omega"], p["peak"]) for p in dm["points"]]


def test_solutions_fill_the_stable_orbits_and_leave_the_unstable_open() -> None:
    found = hb.all_solutions(*duffing(), 1.4, n=8, samples=32)
    ax = plot.solutions(found, 1.4).axes[0]
    by_label = {ln.get_label(): ln for ln in ax.lines}
    stable = [s["amplitude"] for s in found if s["stable"]]
    unstable = [s["amplitude"] for s in found if not s["stable"]]
    assert list(by_label["stable orbits"].get_ydata()) == stable and len(stable) == 2
    assert list(by_label["unstable orbits"].get_ydata()) == unstable and len(unstable) == 1
    assert by_label["unstable orbits"].get_markerfacecolor() == "none"


def test_poincare_marks_the_orbit_section_and_samples_a_time_series() -> None:
    orbit = hb.duffing(n=10, samples=32, omega_f=0.4)
    ax = plot.poincare(orbit).axes[0]
    section = [ln for ln in ax.lines if ln.get_label() == "orbit's section"][0]
    x0 = float(hb.eval_series(orbit["coeffs"], 0.0))
    v0 = 0.4 * float(hb.eval_series(orbit["coeffs"], 0.0, 1))
    assert np.allclose(section.get_xydata(), [[x0, v0]])
    # a subharmonic orbit of order 2 has two section points, half its period apart
    two = {"coeffs": orbit["coeffs"], "omega_f": 0.8, "subharmonic": 2}
    pts = [ln for ln in plot.poincare(two).axes[0].lines if ln.get_label() == "orbit's section"][0]
    assert len(pts.get_xydata()) == 2
    # a limit cycle has no forcing period: its orbit alone
    cycle = {"coeffs": orbit["coeffs"], "omega": 0.4}
    assert [ln.get_label() for ln in plot.poincare(cycle).axes[0].lines] == ["orbit"]
    # a time series: the states at t0 + k·period from k = skip on, interpolated
    t = np.linspace(0.0, 10.0, 1001)
    ax = plot.poincare((t, np.cos(t), -np.sin(t)), period=2.5, skip=1).axes[0]
    got = [ln for ln in ax.lines if ln.get_label() == "trajectory's section"][0].get_xydata()
    tk = np.array([2.5, 5.0, 7.5, 10.0])
    assert np.allclose(got, np.c_[np.cos(tk), -np.sin(tk)], atol=1e-4)
    assert (ax.get_xlabel(), ax.get_ylabel()) == ("x", "dx/dt")
    with pytest.raises(ValueError, match="period"):
        plot.poincare((t, t, t))
    with pytest.raises(ValueError, match="n_dof"):
        plot.poincare(orbit, n_dof=2)


def test_each_function_draws_into_the_given_axes_and_returns_its_figure(duffing_curve: Dict[str, Any]) -> None:
    fig = Figure()
    sub = fig.subfigures(1, 2)[1]
    ax = sub.add_subplot()
    assert plot.frc(duffing_curve, ax) is fig
    assert ax.lines and fig.axes == [ax]
    assert plot.solutions([{"amplitude": 1.0, "stable": True}], 1.0, ax) is fig


def test_import_ivt_works_without_matplotlib_and_ivt_plot_names_the_extra() -> None:
    code = (
        "import sys\n"
        "sys.modules['matplotlib'] = None  # as if it were not installed\n"
        "import ivt\n"
        "ivt.hb.duffing(n=4, samples=16)\n"
        "try:\n"
        "    import ivt.plot\n"
        "except ImportError as e:\n"
        "    print(e)\n"
        "else:\n"
        "    raise SystemExit('imported')\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    assert "pip install 'ivt[plot]'" in run.stdout
