"""One real Dask LocalCluster (2 single-threaded worker processes) for the fan-out tests."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from lynxplan.fanout import Cluster


@pytest.fixture(scope="session")
def dask_cluster() -> Iterator[Cluster]:
    """A running scheduler with 2 workers, as ``--dask-scheduler ADDRESS`` names one."""
    import distributed

    with distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    ) as cluster:
        yield Cluster(scheduler=cluster.scheduler_address)
