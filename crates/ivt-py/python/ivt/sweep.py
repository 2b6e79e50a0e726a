"""Sweeps: many independent runs, on a ``dask.distributed`` client when one
is given, else on local threads, with the results in the order of the inputs.

- :func:`sweep` and :func:`run_many` run simulator scenes over a parameter
  grid or a seeded Monte-Carlo set (each run one :func:`ivt.sim.run`).
- :func:`hb` runs one :mod:`ivt.hb` job (``"frc"``, ``"solve"``, ...) on each
  of a list of models ``(m, c, k, g, f)``; :func:`grid` and :func:`draws`
  give the parameter sets to build them from.

Every run is Rust with the GIL released (Python callbacks re-acquire it), so
local threads run in parallel. Random draws are made up front from ``seed``
with numpy's ``default_rng``, so the numbers do not depend on where or in
which order the runs execute: a sweep on a cluster equals the local one.

Scene parameters are named by dotted scene keys, e.g. ``"plant.k_t"``,
``"controller.k_mm_per_rad"``, ``"inputs.t_u"`` is not a scalar and cannot be
swept this way (edit the dict yourself and pass a list of scenes to
:func:`run_many`).
"""

import concurrent.futures
import copy
import importlib
import inspect
import itertools
import sys
from typing import Any, Callable, Dict, Generator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import hb as _hb
from . import kin, sim

SceneLike = Union[Dict[str, Any], str, Any]


def _get(scene: Dict[str, Any], key: str) -> Any:
    node: Any = scene
    for part in key.split("."):
        if not isinstance(node, dict) or part not in node:
            return None
        node = node[part]
    return node


def _set(scene: Dict[str, Any], key: str, value: Any) -> None:
    parts = key.split(".")
    node = scene
    for part in parts[:-1]:
        node = node.setdefault(part, {})
        if not isinstance(node, dict):
            raise ValueError(f"sweep key `{key}`: `{part}` is not a table")
    node[parts[-1]] = value


def nominal(scene: Dict[str, Any], key: str) -> float:
    """The value of ``key`` in ``scene``, or the printed plant's value for an
    unset ``plant.*`` parameter."""
    value = _get(scene, key)
    if value is None and key.startswith("plant."):
        value = kin.Plant().params().get(key[len("plant."):])
    if not isinstance(value, (int, float)) or isinstance(value, bool):
        raise ValueError(f"sweep key `{key}` has no numeric nominal value in the scene")
    return float(value)


def monte_carlo_samples(
    scene: Dict[str, Any], spread: Mapping[str, float], n: int, seed: int
) -> Dict[str, "np.ndarray[Any, np.dtype[np.float64]]"]:
    """Parameter values ``nominal·(1 + u)``, ``u ~ U(−h, h)`` per key (``h`` =
    ``spread[key]``, e.g. 0.2 for ±20 %), drawn from ``default_rng(seed)`` in
    the order of ``spread``."""
    return _uniform({key: nominal(scene, key) for key in spread}, spread, n, seed)


def _uniform(
    nominal: Mapping[str, Any], spread: Mapping[str, float], n: int, seed: int
) -> Dict[str, "np.ndarray[Any, np.dtype[np.float64]]"]:
    """Columns ``nominal[key]·(1 + u)``, ``u ~ U(−h, h)`` of shape (n, *shape
    of the nominal), drawn from ``default_rng(seed)`` key by key in the order
    of ``spread``."""
    if n < 1:
        raise ValueError(f"argument `n` = {n} must be >= 1")
    rng = np.random.default_rng(seed)
    out = {}
    for key, h in spread.items():
        if not (0.0 <= h < 1.0):
            raise ValueError(f"spread of `{key}` = {h} must be in [0, 1)")
        if key not in nominal:
            raise ValueError(f"spread key `{key}` has no nominal value")
        value = np.asarray(nominal[key], dtype=np.float64)
        out[key] = value * (1.0 + rng.uniform(-h, h, size=(n,) + value.shape))
    return out


def _grid_columns(axes: Mapping[str, Sequence[float]]) -> Tuple[int, Dict[str, List[float]]]:
    """The Cartesian product of ``axes`` as columns (the last key fastest)."""
    keys = list(axes)
    combos = list(itertools.product(*(list(axes[k]) for k in keys)))
    return len(combos), {k: [float(c[i]) for c in combos] for i, k in enumerate(keys)}


def grid(axes: Mapping[str, Sequence[float]]) -> List[Dict[str, float]]:
    """Every combination of the values of ``axes`` (name → values), as one
    dict per point, the last name varying fastest: ``grid({"a": [1, 2], "b":
    [3, 4]})`` → ``[{"a": 1, "b": 3}, {"a": 1, "b": 4}, {"a": 2, "b": 3},
    {"a": 2, "b": 4}]``."""
    count, columns = _grid_columns(axes)
    return [{k: v[i] for k, v in columns.items()} for i in range(count)]


def draws(
    nominal: Mapping[str, Union[float, npt.ArrayLike]],
    spread: Mapping[str, float],
    n: int,
    seed: int,
) -> List[Dict[str, Any]]:
    """A seeded Monte-Carlo set: ``n`` dicts with each key of ``spread`` drawn
    uniformly in ``nominal[key]·(1 ± spread[key])`` (a float, or an array
    drawn entry by entry, e.g. one stiffness factor per blade), the other keys
    of ``nominal`` as given. The draws come from ``default_rng(seed)`` key by
    key in the order of ``spread``, before anything runs."""
    columns = _uniform(nominal, spread, n, seed)
    rows: List[Dict[str, Any]] = []
    for i in range(n):
        row: Dict[str, Any] = dict(nominal)
        for key, column in columns.items():
            row[key] = float(column[i]) if column.ndim == 1 else column[i]
        rows.append(row)
    return rows


class _Progress:
    """A one-line progress bar on stderr: ``label: done/total [###...]``."""

    def __init__(self, total: int, label: str, show: bool) -> None:
        self.total, self.label, self.show, self.done = total, label, show, 0
        self._draw()

    def step(self) -> None:
        self.done += 1
        self._draw()

    def close(self) -> None:
        """End the line of a bar stopped early."""
        if self.show and self.done < self.total:
            sys.stderr.write("\n")

    def _draw(self) -> None:
        if not self.show:
            return
        filled = 30 * self.done // max(self.total, 1)
        bar = "#" * filled + "." * (30 - filled)
        end = "\n" if self.done == self.total else ""
        sys.stderr.write(f"\r{self.label}: {self.done}/{self.total} [{bar}]{end}")
        sys.stderr.flush()


class _Failed:
    """The exception of run ``index`` (what :func:`_map` returns in its place)."""

    def __init__(self, index: int, error: BaseException) -> None:
        self.index, self.error = index, error


def _completed(
    fn: Callable[[Any], Any],
    items: List[Any],
    client: Optional[Any],
    max_workers: Optional[int],
) -> Generator[Tuple[int, Any], None, None]:
    """(index, result or _Failed) of ``fn(item)`` for every item, as they
    complete, on ``client`` or a local thread pool; closing the generator
    cancels what has not run."""
    if client is not None:
        distributed = importlib.import_module("distributed")
        futures = client.map(fn, items, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for fut in distributed.as_completed(futures):
                i = index[fut.key]
                yield i, _Failed(i, fut.exception()) if fut.status == "error" else fut.result()
        finally:
            client.cancel(futures)
        return
    pool = concurrent.futures.ThreadPoolExecutor(max_workers=max_workers)
    try:
        local = {pool.submit(fn, item): i for i, item in enumerate(items)}
        for fut in concurrent.futures.as_completed(local):
            i, error = local[fut], fut.exception()
            yield i, _Failed(i, error) if error is not None else fut.result()
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _map(
    fn: Callable[[Any], Any],
    items: Sequence[Any],
    client: Optional[Any],
    max_workers: Optional[int],
    progress: Union[bool, str],
    stop_on_error: bool,
) -> List[Any]:
    """``fn(item)`` for every item, in order (a failed run: a :class:`_Failed`;
    with ``stop_on_error`` the first failure to complete cancels the rest and
    is the only one returned). ``progress`` (True or a label) draws a progress
    bar on stderr."""
    items = list(items)
    label = progress if isinstance(progress, str) else "ivt.sweep"
    bar = _Progress(len(items), label, bool(progress))
    out: List[Any] = [None] * len(items)
    runs = _completed(fn, items, client, max_workers)
    try:
        for i, result in runs:
            out[i] = result
            bar.step()
            if stop_on_error and isinstance(result, _Failed):
                return [result]
    finally:
        runs.close()
        bar.close()
    return out


def _run_summary(scene: Dict[str, Any]) -> Dict[str, Any]:
    """One run on a worker: the summary only (the channels stay there)."""
    summary: Dict[str, Any] = sim.run(scene)["summary"]
    return summary


def run_many(
    scenes: Sequence[Dict[str, Any]],
    client: Optional[Any] = None,
    max_workers: Optional[int] = None,
    progress: Union[bool, str] = False,
) -> List[Dict[str, Any]]:
    """Run scene dicts and return their summaries in order: on ``client``
    (a ``dask.distributed.Client``) if given, else on a local thread pool of
    ``max_workers`` threads (the GIL is released inside each run). A failing
    run raises its error. ``progress``: a progress bar on stderr (True, or
    its label)."""
    scenes = list(scenes)
    for s in scenes:
        sim.check_scene(s)  # fail before anything is submitted
    results = _map(_run_summary, scenes, client, max_workers, progress, stop_on_error=True)
    for r in results:
        if isinstance(r, _Failed):
            raise r.error
    return results


def sweep(
    scene: SceneLike,
    *,
    grid: Optional[Mapping[str, Sequence[float]]] = None,
    spread: Optional[Mapping[str, float]] = None,
    n: int = 0,
    seed: int = 0,
    client: Optional[Any] = None,
    max_workers: Optional[int] = None,
    as_frame: bool = True,
    progress: Union[bool, str] = False,
) -> Any:
    """Run ``scene`` over a parameter grid or a Monte-Carlo set.

    grid: dotted key → values; every combination runs (Cartesian product).
    spread, n, seed: Monte-Carlo — ``n`` runs with each key drawn uniformly in
    ``nominal·(1 ± spread[key])`` from ``default_rng(seed)``
    (e.g. ``spread={"plant.k_t": 0.2, "plant.j_u": 0.2}`` for ±20 %).
    Give one of ``grid`` and ``spread``.

    Returns one row per run with the swept parameters and every numeric field
    of the run summary (``ivt sim --json`` keys): a pandas DataFrame when
    ``as_frame`` and pandas is installed, else a dict of numpy arrays.
    ``progress``: a progress bar on stderr (True, or its label).
    """
    base = sim.scene_dict(scene)
    if (grid is None) == (spread is None):
        raise ValueError("give exactly one of `grid` and `spread`")
    params: Dict[str, List[float]]
    if grid is not None:
        count, params = _grid_columns(grid)
    else:
        assert spread is not None
        draws = monte_carlo_samples(base, spread, n, seed)
        params = {k: [float(x) for x in v] for k, v in draws.items()}
        count = n
    scenes = []
    for i in range(count):
        s = copy.deepcopy(base)
        for key, values in params.items():
            _set(s, key, values[i])
        scenes.append(s)
    summaries = run_many(scenes, client=client, max_workers=max_workers, progress=progress)
    columns: Dict[str, List[Any]] = {k: list(v) for k, v in params.items()}
    numeric = [
        k
        for k, v in summaries[0].items()
        if isinstance(v, (int, float)) and not isinstance(v, bool)
    ] if summaries else []
    for key in numeric:
        columns[key] = [
            float("nan") if s.get(key) is None else s[key] for s in summaries
        ]
    if as_frame:
        try:
            pd = importlib.import_module("pandas")
        except ImportError:
            pass
        else:
            return pd.DataFrame(columns)
    return {k: np.asarray(v, dtype=np.float64) for k, v in columns.items()}

# --- harmonic-balance jobs over many models (issue 46) ------------------------


def _hb_jobs() -> Dict[str, inspect.Signature]:
    """The ivt.hb functions of one model, ``name(m, c, k, g, ...)``, and their
    signatures."""
    jobs = {}
    for name, fn in vars(_hb).items():
        if name.startswith("_") or not callable(fn):
            continue
        try:
            sig = inspect.signature(fn)
        except (TypeError, ValueError):
            continue
        if list(sig.parameters)[:4] == ["m", "c", "k", "g"]:
            jobs[name] = sig
    return jobs


class _HbTask:
    """One job on one model (a plain object, so that dask ships it whole)."""

    def __init__(self, job: str, model: Tuple[Any, ...], options: Dict[str, Any]) -> None:
        self.job, self.model, self.options = job, model, options


def _run_hb(task: _HbTask) -> Any:
    m, c, k, g, f = task.model
    forcing = {} if f is None else {"f": f}
    return getattr(_hb, task.job)(m, c, k, g, **forcing, **task.options)


def _hb_task(
    job: str, sig: inspect.Signature, i: int, model: Any, options: Dict[str, Any]
) -> _HbTask:
    """The task of model ``i``, its arguments bound to the job's signature (a
    missing argument or a forcing the job does not take fails here, naming
    the model). Options the signature does not name pass on to the job (the
    large path of frc and solve takes more, e.g. ``stability``), which
    refuses those it does not take."""
    if not isinstance(model, (tuple, list)) or len(model) not in (4, 5):
        raise ValueError(f"model {i}: expected a tuple (m, c, k, g, f) or (m, c, k, g), got {model!r:.80}")
    m, c, k, g, f = (*model, None) if len(model) == 4 else model
    if f is not None and "f" not in sig.parameters:
        raise ValueError(f"model {i}: `{job}` takes no forcing; give f = None")
    forcing = {} if f is None else {"f": f}
    named = {key: value for key, value in options.items() if key in sig.parameters}
    try:
        sig.bind(m, c, k, g, **forcing, **named)
    except TypeError as e:
        raise ValueError(f"model {i}: ivt.hb.{job}: {e}") from None
    return _HbTask(job, (m, c, k, g, f), options)


def hb(
    job: str,
    models: Sequence[Sequence[Any]],
    client: Optional[Any] = None,
    *,
    max_workers: Optional[int] = None,
    progress: Union[bool, str] = False,
    errors: str = "raise",
    **options: Any,
) -> List[Any]:
    """Run the :mod:`ivt.hb` function named ``job`` on every model and return
    the results in the order of ``models``.

    job: the name of an ``ivt.hb`` function of one model, ``job(m, c, k, g,
    ...)``: ``"frc"``, ``"solve"``, ``"diagram"``, ``"all_solutions"``,
    ``"limit_cycle"``, ``"backbone"``, ... (another name is a ValueError
    listing them).
    models: tuples ``(m, c, k, g, f)`` (``f`` None, or a 4-tuple, for the
    autonomous jobs), e.g. built from :func:`grid` or :func:`draws`; each is
    run as ``ivt.hb.<job>(m, c, k, g, f=f, **options)``, so dense and large
    (scipy.sparse) models, Python callables and :mod:`ivt.hb.elements` as
    ``g`` are all taken.
    client: a ``dask.distributed.Client``; the models travel to its workers
    by (cloud)pickle: lambdas and elements included. Without one the jobs
    run on a local pool of ``max_workers`` threads. Either way each result
    equals the job run alone (the solvers are deterministic).
    progress: a progress bar on stderr (True, or its label).
    errors: ``"raise"`` (default): the first failure to complete stops the
    sweep and raises a ValueError, TypeError (for those) or RuntimeError
    naming the model, ``"model 3: ivt.hb.frc: ..."``, the job's own error as
    its ``__cause__``;
    ``"return"``: every job runs, and a failed model's entry is its
    exception instead of a result.
    options: keyword arguments of the job, the same for every model
    (``omega_from=``, ``omega_to=``, ``n=``, ``nonlinear_dofs=``, ...); a
    missing argument is found before anything runs, an option the job does
    not take when it runs.
    """
    jobs = _hb_jobs()
    if job not in jobs:
        raise ValueError(f"unknown job `{job}`: expected one of {', '.join(sorted(jobs))}")
    if errors not in ("raise", "return"):
        raise ValueError(f"argument `errors` must be 'raise' or 'return', got {errors!r}")
    tasks = [_hb_task(job, jobs[job], i, model, options) for i, model in enumerate(models)]
    results = _map(_run_hb, tasks, client, max_workers, progress, stop_on_error=errors == "raise")
    if errors == "return":
        return [r.error if isinstance(r, _Failed) else r for r in results]
    for r in results:
        if isinstance(r, _Failed):
            kind = next((t for t in (ValueError, TypeError) if isinstance(r.error, t)), RuntimeError)
            raise kind(f"model {r.index}: ivt.hb.{job}: {r.error}") from r.error
    return results


__all__ = ["draws", "grid", "hb", "monte_carlo_samples", "nominal", "run_many", "sweep"]
