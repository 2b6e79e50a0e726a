"""ivt.sweep: seeded Monte-Carlo and grid sweeps; a dask LocalCluster of two
workers returns exactly the numbers of the local thread-pool run."""

import numpy as np
import pandas as pd
import pytest

import ivt
from test_sim import short_scene


def test_monte_carlo_draws_are_seeded_and_bounded() -> None:
    d = short_scene()
    a = ivt.sweep.monte_carlo_samples(d, {"plant.k_t": 0.2, "plant.j_u": 0.2}, 200, seed=3)
    b = ivt.sweep.monte_carlo_samples(d, {"plant.k_t": 0.2, "plant.j_u": 0.2}, 200, seed=3)
    np.testing.assert_array_equal(a["plant.k_t"], b["plant.k_t"])
    assert np.all(np.abs(a["plant.k_t"] / 0.76 - 1) <= 0.2)
    assert np.all(np.abs(a["plant.j_u"] / 0.000206 - 1) <= 0.2)
    assert ivt.sweep.nominal(d, "controller.k_mm_per_rad") == 2.0


def test_grid_sweep_matches_single_runs() -> None:
    d = short_scene(2.0)
    df = ivt.sweep.sweep(d, grid={"plant.k_t": [0.7, 0.8]}, max_workers=2)
    assert isinstance(df, pd.DataFrame) and list(df["plant.k_t"]) == [0.7, 0.8]
    for i, k_t in enumerate([0.7, 0.8]):
        s = short_scene(2.0)
        s.setdefault("plant", {})["k_t"] = k_t
        ref = ivt.sim.run(s)["summary"]
        assert df["final_omega_a_rad_s"][i] == ref["final_omega_a_rad_s"]
        assert df["pulses"][i] == ref["pulses"]
    as_dict = ivt.sweep.sweep(d, grid={"plant.k_t": [0.7]}, as_frame=False)
    assert isinstance(as_dict["pulses"], np.ndarray)


def test_dask_local_cluster_equals_local_run() -> None:
    import distributed  # installed by scripts/py-test (dask[distributed]); no silent skip
    d = short_scene(2.0)
    spread = {"plant.k_t": 0.2, "plant.r_a": 0.2, "plant.j_u": 0.2}
    local = ivt.sweep.sweep(d, spread=spread, n=4, seed=11, max_workers=2)
    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
    ) as cluster, distributed.Client(cluster) as client:
        remote = ivt.sweep.sweep(d, spread=spread, n=4, seed=11, client=client)
    volatile = ["wall_time_s", "realtime_factor"]
    pd.testing.assert_frame_equal(local.drop(columns=volatile), remote.drop(columns=volatile))
    assert local["plant.k_t"].nunique() == 4  # the draws differ between runs


def test_sweep_errors() -> None:
    d = short_scene(2.0)
    with pytest.raises(ValueError, match="exactly one"):
        ivt.sweep.sweep(d)
    with pytest.raises(ValueError, match="`n`"):
        ivt.sweep.sweep(d, spread={"plant.k_t": 0.2}, n=0)
    with pytest.raises(ValueError, match="spread"):
        ivt.sweep.sweep(d, spread={"plant.k_t": 1.5}, n=2)
    with pytest.raises(ValueError, match="no numeric nominal"):
        ivt.sweep.sweep(d, spread={"controller.law": 0.1}, n=2)
    with pytest.raises(ValueError, match="plant.r_u"):
        ivt.sweep.sweep(d, grid={"plant.r_u": [-1.0]})
