"""Figures of harmonic-balance results with matplotlib: the pictures every
user draws by hand, from the dicts the :mod:`ivt.hb` functions return, as
they return them.

- :func:`frc`: a response curve (amplitude against ω) with its unstable
  stretches dashed and its events (folds, period doublings ``PD``,
  Neimark–Sacker points ``NS``, branch points ``BP``) marked and labelled —
  of :func:`ivt.hb.frc`, :func:`ivt.hb.duffing_frc`,
  :func:`ivt.hb.switch_branch` and :func:`ivt.hb.string`;
- :func:`curve2`: a two-parameter curve (fold, period-doubling or
  Neimark–Sacker curve of :func:`ivt.hb.continue_bifurcation` and
  :func:`ivt.hb.duffing_folds`; a fold of limit cycles of
  :func:`ivt.hb.cycle_fold_curve`) with its special points (cusps, the
  resonances 1:1 … 1:4) and the points located at the requested
  parameters;
- :func:`cycles`: a branch of limit cycles (:func:`ivt.hb.cycle_branch`),
  unstable cycles dashed, its Hopf points and folds marked;
- :func:`backbone`: a backbone or damped nonlinear mode
  (:func:`ivt.hb.backbone`, :func:`ivt.hb.damped_modes`), drawn over a
  response curve when given its axes;
- :func:`solutions`: the orbits :func:`ivt.hb.all_solutions` found at one
  frequency, stable ones filled and unstable ones open;
- :func:`poincare`: a periodic orbit in the phase plane (x, dx/dt) with its
  stroboscopic Poincaré section, or the section of a time series.

Each returns the :class:`matplotlib.figure.Figure` and draws into ``ax``
when one is given (so that pictures can be overlaid), else into a new
figure made without :mod:`matplotlib.pyplot` (no global state; save it with
``fig.savefig("frc.png")``). The command line draws the same pictures with
``--plot FILE.png``.

Conventions, the same on the command line: along a curve, the points are
split into runs of one stability verdict; each run of unstable points is
one dashed line through exactly those points, each run of stable points one
solid line extended to the neighbouring unstable point on either side, so
that the curve stays connected (stability changes on that segment, where
the event is marked). A point whose verdict is unknown (``stable`` None,
e.g. ``stability=False``) is drawn as stable. Events are drawn one marker
each, at their located (ω, amplitude), with a text label beside them.

matplotlib is an optional extra of the wheel: ``pip install 'ivt[plot]'``.
``import ivt`` works without it; ``import ivt.plot`` then raises an
ImportError that says so.
"""

from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

try:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure, SubFigure
except ImportError as _missing:  # pragma: no cover - exercised by tests/test_wheel.py
    raise ImportError(
        "ivt.plot needs matplotlib, an optional extra of the ivt wheel: "
        "pip install 'ivt[plot]' (or pip install matplotlib)"
    ) from _missing

from . import hb

__all__ = ["backbone", "curve2", "cycles", "frc", "poincare", "solutions"]

#: A result dict of an :mod:`ivt.hb` function.
Result = Mapping[str, Any]
#: A time series for :func:`poincare`: (t, x, dx/dt), three 1-D arrays.
TimeSeries = Tuple[Any, Any, Any]

#: The label of each event kind on a response curve or a branch.
EVENT_LABELS: Dict[str, str] = {
    "fold": "fold",
    "period_doubling": "PD",
    "neimark_sacker": "NS",
    "branch_point": "BP",
}
#: The marker of each event kind (any other: a diamond).
_MARKERS: Dict[str, str] = {"fold": "v", "PD": "s", "NS": "D", "BP": "P", "Hopf": "*", "cusp": "^"}

_STABLE = "C0"
_UNSTABLE = "C3"
_EVENTS = "k"


def _figure_of(ax: Optional[Axes]) -> Tuple[Figure, Axes]:
    """The figure to return and the axes to draw into: a new figure (no
    pyplot) when `ax` is None."""
    if ax is None:
        fig = Figure(figsize=(7.0, 4.4), layout="constrained")
        return fig, fig.add_subplot()
    parent: Union[Figure, SubFigure, None] = ax.get_figure()
    while isinstance(parent, SubFigure):
        parent = parent.figure
    if not isinstance(parent, Figure):
        raise ValueError("`ax` is not on a matplotlib Figure")
    return parent, ax


def _runs(points: Sequence[Tuple[float, float, bool]]) -> List[Tuple[List[float], List[float], bool]]:
    """The curve's pieces in order as (xs, ys, stable): each unstable run
    holds exactly its points, each stable run its points plus the
    neighbouring unstable point on either side."""
    runs: List[Tuple[List[float], List[float], bool]] = []
    for i, (x, y, stable) in enumerate(points):
        if runs and runs[-1][2] == stable:
            runs[-1][0].append(x)
            runs[-1][1].append(y)
            continue
        xs, ys = [x], [y]
        if stable and i > 0:
            # unstable → stable: the stable run starts at the last unstable point
            xs.insert(0, points[i - 1][0])
            ys.insert(0, points[i - 1][1])
        elif not stable and runs:
            # stable → unstable: the stable run ends at this point
            runs[-1][0].append(x)
            runs[-1][1].append(y)
        runs.append((xs, ys, stable))
    return runs


def _draw_runs(
    ax: Axes,
    points: Sequence[Tuple[float, float, bool]],
    labels: Tuple[str, str] = ("stable", "unstable"),
    colors: Tuple[str, str] = (_STABLE, _UNSTABLE),
) -> None:
    """Stable runs solid, unstable runs dashed; one legend entry each."""
    seen = set()
    for xs, ys, stable in _runs(points):
        label = labels[0] if stable else labels[1]
        ax.plot(
            xs,
            ys,
            linestyle="-" if stable else "--",
            color=colors[0] if stable else colors[1],
            linewidth=1.6,
            label=label if label not in seen else "_nolegend_",
        )
        seen.add(label)


def _draw_events(ax: Axes, events: Sequence[Tuple[str, float, float]]) -> None:
    """One marker per event (one legend entry per label), its label written
    beside it."""
    seen = set()
    for label, x, y in events:
        ax.plot(
            [x],
            [y],
            linestyle="none",
            marker=_MARKERS.get(label, "d"),
            markersize=8,
            color=_EVENTS,
            label=label if label not in seen else "_nolegend_",
            gid="event",
        )
        ax.annotate(label, (x, y), xytext=(6, 6), textcoords="offset points", fontsize=9)
        seen.add(label)


def _finish(ax: Axes, x_label: str, y_label: str, title: Optional[str]) -> None:
    ax.set_xlabel(x_label)
    ax.set_ylabel(y_label)
    if title:
        ax.set_title(title)
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=9)


def _stable(p: Mapping[str, Any]) -> bool:
    """A point's verdict; unknown (None or absent) counts as stable."""
    return p.get("stable") is not False


def _size_key(points: Sequence[Mapping[str, Any]]) -> str:
    """The key of the ordinate: ``amplitude`` (max |x|), or ``norm`` (‖a‖)
    for the STHB string."""
    return "norm" if points and "norm" in points[0] and "amplitude" not in points[0] else "amplitude"


def _turn_amplitude(points: Sequence[Mapping[str, Any]], omega: float, key: str) -> float:
    """The size at the path's turning point nearest `omega` (a fold given by
    its ω alone)."""
    w = np.array([float(p["omega"]) for p in points])
    turns = [i for i in range(1, len(w) - 1) if (w[i] - w[i - 1]) * (w[i + 1] - w[i]) <= 0]
    candidates = turns or list(range(len(w)))
    i = min(candidates, key=lambda j: abs(w[j] - omega))
    return float(points[i][key])


def _curve_events(result: Result, points: Sequence[Mapping[str, Any]], key: str) -> List[Tuple[str, float, float]]:
    """The events of a response curve, one per event: the `bifurcations`
    (which include the folds) when the result has them, else the `folds`
    (dicts, or numbers: ω alone)."""
    out: List[Tuple[str, float, float]] = []
    events = result.get("bifurcations")
    if events is None:
        events = [f if isinstance(f, Mapping) else {"omega": float(f)} for f in result.get("folds", [])]
        events = [{"kind": "fold", **e} for e in events]
    for e in events:
        omega = e.get("omega")
        if omega is None:
            continue
        size = e.get(key)
        if size is None and e.get("index") is not None and 0 <= int(e["index"]) < len(points):
            size = points[int(e["index"])][key]
        if size is None:
            if not points:
                continue
            size = _turn_amplitude(points, float(omega), key)
        out.append((EVENT_LABELS.get(str(e.get("kind", "fold")), str(e.get("kind"))), float(omega), float(size)))
    return out


def frc(result: Result, ax: Optional[Axes] = None, *, title: Optional[str] = None) -> Figure:
    """Draw a frequency-response curve: amplitude against ω, stable runs
    solid, unstable runs dashed, each event marked and labelled (``fold``,
    ``PD``, ``NS``, ``BP``).

    `result` is the dict of :func:`ivt.hb.frc` (dense or large model),
    :func:`ivt.hb.duffing_frc` (whose ``folds`` are numbers),
    :func:`ivt.hb.switch_branch` or :func:`ivt.hb.string` (whose ordinate is
    ``norm``, ‖a‖). The events are its ``bifurcations`` (the folds among
    them), or its ``folds`` where it has no ``bifurcations``; an event
    without an amplitude is drawn at the path point before it.

    Returns the figure; draws into `ax` when given.
    """
    points = result["points"]
    key = _size_key(points)
    fig, ax = _figure_of(ax)
    _draw_runs(ax, [(float(p["omega"]), float(p[key]), _stable(p)) for p in points])
    _draw_events(ax, _curve_events(result, points, key))
    _finish(ax, "ω", "‖a‖ (Eq. 114)" if key == "norm" else "max |x|", title)
    return fig


def _special_label(kind: str) -> str:
    """The label of a special point of a two-parameter curve: ``cusp``,
    ``1:1`` … ``1:4``."""
    return kind.replace("resonance_", "").replace("_", ":") if kind.startswith("resonance_") else kind


_CURVE_NAMES = {
    "fold": "fold curve",
    "period_doubling": "period-doubling curve",
    "neimark_sacker": "Neimark–Sacker curve",
}


def curve2(result: Result, ax: Optional[Axes] = None, *, title: Optional[str] = None) -> Figure:
    """Draw a two-parameter curve with its special points.

    - a bifurcation curve of :func:`ivt.hb.continue_bifurcation` or
      :func:`ivt.hb.duffing_folds` in (ω, p): the curve, its ``special``
      points marked and labelled (``cusp``, ``1:1``, ``1:2``, ``1:3``,
      ``1:4``) and its ``at`` points (located at the requested p) marked;
    - a fold of limit cycles of :func:`ivt.hb.cycle_fold_curve` in (ν, μ):
      the curve, its ``special`` points (cusps) and its ``at`` points.

    Returns the figure; draws into `ax` when given.
    """
    points = result["points"]
    cycle_folds = bool(points) and "nu" in points[0]
    xk, yk = ("nu", "mu") if cycle_folds else ("omega", "p")
    name = "fold of limit cycles" if cycle_folds else _CURVE_NAMES.get(str(result.get("kind")), "curve")
    fig, ax = _figure_of(ax)
    ax.plot([float(p[xk]) for p in points], [float(p[yk]) for p in points], "-", color=_STABLE, label=name)
    at = result.get("at") or []
    if at:
        ax.plot(
            [float(p[xk]) for p in at],
            [float(p[yk]) for p in at],
            linestyle="none",
            marker="o",
            markersize=5,
            color=_UNSTABLE,
            label="located at the requested parameter",
        )
    special = [(_special_label(str(s["kind"])), float(s[xk]), float(s[yk])) for s in result.get("special") or []]
    _draw_events(ax, special)
    _finish(ax, "ν" if cycle_folds else "ω", "μ" if cycle_folds else "p", title)
    return fig


def cycles(result: Result, ax: Optional[Axes] = None, *, title: Optional[str] = None) -> Figure:
    """Draw a branch of limit cycles (:func:`ivt.hb.cycle_branch`): the
    cycles' amplitude against the parameter p, stable runs solid, unstable
    runs dashed; the Hopf points (amplitude 0) and the folds of cycles marked
    and labelled; the cycles solved at the requested p (``at``) as dots.

    Returns the figure; draws into `ax` when given.
    """
    points = result["points"]
    fig, ax = _figure_of(ax)
    _draw_runs(
        ax,
        [(float(c["p"]), float(c["amplitude"]), _stable(c)) for c in points],
        labels=("stable cycles", "unstable cycles"),
    )
    at = result.get("at") or []
    if at:
        ax.plot(
            [float(c["p"]) for c in at],
            [float(c["amplitude"]) for c in at],
            linestyle="none",
            marker="o",
            markersize=5,
            color="C2",
            label="cycles at the requested p",
        )
    events = [("Hopf", float(h["p"]), 0.0) for h in result.get("hopf") or []]
    events += [
        (EVENT_LABELS.get(str(f.get("kind", "fold")), "fold"), float(f["p"]), float(f["amplitude"]))
        for f in result.get("bifurcations") or []
    ]
    _draw_events(ax, events)
    _finish(ax, "p", "max |x|", title)
    return fig


def backbone(result: Result, ax: Optional[Axes] = None, *, title: Optional[str] = None) -> Figure:
    """Draw a backbone (:func:`ivt.hb.backbone`) or a damped nonlinear mode
    (:func:`ivt.hb.damped_modes`): ω against max |x| of the reference DOF
    (each point's ``peak``, the measure of a response curve's amplitude), so
    that given the axes of :func:`frc` it is drawn over the response curve.

    Returns the figure; draws into `ax` when given.
    """
    points = result["points"]
    damped = bool(points) and "damping_ratio" in points[0]
    fig, ax = _figure_of(ax)
    ax.plot(
        [float(p["omega"]) for p in points],
        [float(p["peak"]) for p in points],
        "-.",
        color="C2",
        linewidth=1.6,
        label="damped mode" if damped else "backbone",
    )
    _finish(ax, "ω", "max |x|", title)
    return fig


def solutions(
    found: Sequence[Mapping[str, Any]], omega: float, ax: Optional[Axes] = None, *, title: Optional[str] = None
) -> Figure:
    """Draw the orbits :func:`ivt.hb.all_solutions` found at frequency
    `omega`: their amplitudes (max |x| of DOF 0) at ω, stable ones filled,
    unstable ones open; over a response curve when given its axes.

    Returns the figure; draws into `ax` when given.
    """
    fig, ax = _figure_of(ax)
    for stable, face, label in ((True, "C0", "stable orbits"), (False, "none", "unstable orbits")):
        amps = [float(s["amplitude"]) for s in found if _stable(s) == stable]
        if amps:
            ax.plot(
                [omega] * len(amps),
                amps,
                linestyle="none",
                marker="o",
                markersize=8,
                markerfacecolor=face,
                markeredgecolor="C0",
                label=label,
            )
    _finish(ax, "ω", "max |x|", title)
    return fig


def _orbit_section(
    result: Result, dof: int, n_dof: int, omega_f: Optional[float]
) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(x, dx/dt) over one period of an HB orbit and at its stroboscopic
    section points."""
    coeffs = np.asarray(result["coeffs"], dtype=float)
    if coeffs.size % n_dof:
        raise ValueError(f"{coeffs.size} coefficients do not split into n_dof = {n_dof} DOFs")
    block = coeffs.reshape(n_dof, -1)[dof]
    sub = int(result.get("subharmonic", 1))
    forced = omega_f is not None or "omega_f" in result
    if omega_f is None:
        omega_f = result.get("omega_f", result.get("omega"))
    if omega_f is None:
        raise ValueError("the orbit carries no frequency: pass omega_f=")
    omega = float(omega_f) / sub  # τ = ω t, the response frequency
    tau = np.linspace(0.0, 2.0 * np.pi, 801)
    x = hb.eval_series(block, tau)
    v = omega * hb.eval_series(block, tau, 1)
    # Stroboscopic at the forcing period 2π/ω_f: τ advances by 2π/sub. An
    # autonomous orbit (a limit cycle: `omega`, no `omega_f`) has no forcing
    # period, hence no section of its own.
    ts = 2.0 * np.pi * np.arange(sub) / sub if forced else np.zeros(0)
    return x, v, hb.eval_series(block, ts), omega * hb.eval_series(block, ts, 1)


def poincare(
    data: Union[Result, TimeSeries],
    ax: Optional[Axes] = None,
    *,
    period: Optional[float] = None,
    omega_f: Optional[float] = None,
    dof: int = 0,
    n_dof: int = 1,
    skip: int = 0,
    title: Optional[str] = None,
) -> Figure:
    """Draw a stroboscopic Poincaré section in the phase plane (x, dx/dt).

    - `data` an HB orbit (the dict of :func:`ivt.hb.solve`,
      :func:`ivt.hb.duffing`, :func:`ivt.hb.limit_cycle` or a point of a
      curve): the orbit of DOF `dof` (of `n_dof`) over one period as a
      closed curve, and, for a forced orbit (one with ``omega_f``, or
      `omega_f` given), its section — the states one forcing period 2π/ω_f
      apart (one point, p points for a subharmonic of order p) — marked.
      A limit cycle (``omega``, no ``omega_f``) has no forcing period: its
      orbit alone is drawn.
    - `data` a time series ``(t, x, v)``: the states at t₀ + k·`period`
      (linear interpolation between samples), k ≥ `skip`, as dots, over
      the trajectory in light grey. `period` is required.

    Returns the figure; draws into `ax` when given (e.g. an integration's
    section over the orbit it settles onto).
    """
    fig, ax = _figure_of(ax)
    if isinstance(data, Mapping):
        x, v, xs, vs = _orbit_section(data, dof, n_dof, omega_f)
        ax.plot(x, v, "-", color=_STABLE, linewidth=1.8, label="orbit", zorder=3)
        if xs.size:
            ax.plot(xs, vs, linestyle="none", marker="o", markersize=9, markerfacecolor="none",
                    markeredgecolor=_EVENTS, markeredgewidth=1.6, label="orbit's section", zorder=4)
    else:
        if period is None or not period > 0:
            raise ValueError("a time series needs period= > 0 (the section's spacing in t)")
        t, x, v = (np.asarray(a, dtype=float).ravel() for a in data)
        if not t.shape == x.shape == v.shape:
            raise ValueError(f"t, x, v must have one length, got {t.size}, {x.size}, {v.size}")
        if t.size < 2 or not np.all(np.diff(t) > 0):
            raise ValueError("t must increase, with at least two samples")
        ks = np.arange(skip, int(np.floor((t[-1] - t[0]) / period + 1e-9)) + 1)
        tk = t[0] + ks * period
        ax.plot(x, v, "-", color="0.8", linewidth=0.7, label="trajectory", zorder=1)
        ax.plot(
            np.interp(tk, t, x),
            np.interp(tk, t, v),
            linestyle="none",
            marker=".",
            markersize=7,
            color=_UNSTABLE,
            label="trajectory's section",
            zorder=2,
        )
    _finish(ax, "x", "dx/dt", title)
    return fig
