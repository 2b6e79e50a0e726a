"""Parameter sweeps of scenes: a grid or a seeded Monte-Carlo set, run on a
``dask.distributed`` client when one is given, else on local threads.

Each run is one :func:`ivt.sim.run` (Rust, GIL released), so local threads
run in parallel. The random draws are made up front from ``seed`` with
numpy's ``default_rng``, so the numbers do not depend on where or in which
order the runs execute: a sweep on a cluster equals the local one.

Parameters are named by dotted scene keys, e.g. ``"plant.k_t"``,
``"controller.k_mm_per_rad"``, ``"inputs.t_u"`` is not a scalar and cannot be
swept this way (edit the dict yourself and pass a list of scenes to
:func:`run_many`).
"""

import copy
import importlib
import itertools
from concurrent.futures import ThreadPoolExecutor
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np

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
    if n < 1:
        raise ValueError(f"argument `n` = {n} must be >= 1")
    rng = np.random.default_rng(seed)
    out = {}
    for key, h in spread.items():
        if not (0.0 <= h < 1.0):
            raise ValueError(f"spread of `{key}` = {h} must be in [0, 1)")
        out[key] = nominal(scene, key) * (1.0 + rng.uniform(-h, h, size=n))
    return out


def _run_summary(scene: Dict[str, Any]) -> Dict[str, Any]:
    """One run on a worker: the summary only (the channels stay there)."""
    summary: Dict[str, Any] = sim.run(scene)["summary"]
    return summary


def run_many(
    scenes: Sequence[Dict[str, Any]],
    client: Optional[Any] = None,
    max_workers: Optional[int] = None,
) -> List[Dict[str, Any]]:
    """Run scene dicts and return their summaries in order: on ``client``
    (a ``dask.distributed.Client``) if given, else on a local thread pool of
    ``max_workers`` threads (the GIL is released inside each run)."""
    scenes = list(scenes)
    for s in scenes:
        sim.check_scene(s)  # fail before anything is submitted
    if client is not None:
        futures = client.map(_run_summary, scenes, pure=False)
        results: List[Dict[str, Any]] = client.gather(futures)
        return results
    with ThreadPoolExecutor(max_workers=max_workers) as pool:
        return list(pool.map(_run_summary, scenes))


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
    """
    base = sim.scene_dict(scene)
    if (grid is None) == (spread is None):
        raise ValueError("give exactly one of `grid` and `spread`")
    params: Dict[str, List[float]]
    if grid is not None:
        keys = list(grid)
        combos = list(itertools.product(*(list(grid[k]) for k in keys)))
        params = {k: [float(c[i]) for c in combos] for i, k in enumerate(keys)}
        count = len(combos)
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
    summaries = run_many(scenes, client=client, max_workers=max_workers)
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


__all__ = ["monte_carlo_samples", "nominal", "run_many", "sweep"]
