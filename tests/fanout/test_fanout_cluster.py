"""lynxplan.fanout.cluster: option checks, an unreachable scheduler, chunks gathered in order."""

from __future__ import annotations

import pytest

from lynxplan.exceptions import InputError
from lynxplan.fanout import Cluster, cluster_from_options, map_chunks, open_client


def test_options_name_one_cluster_or_none() -> None:
    assert cluster_from_options(None, None) is None
    assert cluster_from_options("tcp://h:8786", None) == Cluster("tcp://h:8786")
    assert cluster_from_options(None, 2) == Cluster(local_workers=2)


@pytest.mark.parametrize(
    ("scheduler", "workers", "message"),
    [
        ("tcp://h:8786", 2, "give one of --dask-local N and --dask-scheduler ADDRESS, not both"),
        (None, 0, r"--dask-local needs at least 1 worker\. Got: 0"),
        (None, -3, r"--dask-local needs at least 1 worker\. Got: -3"),
        (" ", None, "--dask-scheduler needs an address such as tcp://host:8786"),
    ],
)
def test_bad_options_are_one_line_input_errors(
    scheduler: str | None, workers: int | None, message: str
) -> None:
    with pytest.raises(InputError, match=message) as error:
        cluster_from_options(scheduler, workers)
    assert "\n" not in str(error.value)


def test_an_unreachable_scheduler_is_an_input_error_naming_it() -> None:
    cluster = Cluster(scheduler="tcp://127.0.0.1:9", connect_timeout="1s")
    refused = r"--dask-scheduler tcp://127\.0\.0\.1:9: cannot connect"
    with pytest.raises(InputError, match=refused), open_client(cluster):
        pass


def test_neither_option_is_refused_by_open_client() -> None:
    neither = "give one of --dask-scheduler ADDRESS and --dask-local N"
    with pytest.raises(InputError, match=neither), open_client(Cluster()):
        pass


def test_chunks_come_back_in_order_with_progress(dask_cluster: Cluster) -> None:
    seen: list[tuple[int, int]] = []
    parts = [[k, k + 1] for k in range(0, 20, 2)]
    with open_client(dask_cluster) as client:
        sums = map_chunks(
            client, sum, parts, sizes=[2] * 10, progress=lambda d, n: seen.append((d, n))
        )
        rounded = map_chunks(client, round, [1.26, 2.71, 3.14], ndigits=1)
    assert sums == [4 * k + 1 for k in range(10)]
    assert rounded == [1.3, 2.7, 3.1]
    assert [d for d, _ in seen] == list(range(2, 21, 2)) and {n for _, n in seen} == {20}
