"""``--dask-scheduler``: runs and large /ik batches go to a Dask cluster (a LocalCluster started
by the test), with the same answers as the library."""

from __future__ import annotations

import numpy as np
import pytest
from service_server import SCENARIOS, Server

from lynxplan.arm import load_arm
from lynxplan.client import Client


@pytest.fixture(scope="module")
def cluster():
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=True,
                                  dashboard_address=None) as local:  # fmt: skip
        yield local


def test_runs_and_large_batches_go_to_dask(cluster, tmp_path) -> None:
    import distributed

    server = Server(tmp_path / "data", "--dask-scheduler", cluster.scheduler_address)
    try:
        with Client(server.url) as client, distributed.Client(cluster) as dask:
            result = client.run(SCENARIOS / "free_motion.yaml", quick=True,
                                out_dir=tmp_path / "out")
            assert result.state == "succeeded" and result.ok
            assert (tmp_path / "out" / "trajectory.csv").stat().st_size > 0
            arm = load_arm()
            rng = np.random.default_rng(4)
            T = arm.fk(rng.uniform(arm.limits.lower, arm.limits.upper, size=(60_000, 5)))
            remote, local = client.ik(T), arm.ik_batch(T)
            for name in local._fields:
                np.testing.assert_array_equal(getattr(remote, name), getattr(local, name))
            assert {"execute_run_packed", "ik_batch_arrays"} <= _task_prefixes(dask)
            version = client._json("GET", "/version")
            assert version["executor"] == "dask"
    finally:
        server.stop()


def _task_prefixes(dask) -> set[str]:
    def prefixes(dask_scheduler) -> list[str]:
        return sorted(dask_scheduler.task_prefixes)

    return set(dask.run_on_scheduler(prefixes))
