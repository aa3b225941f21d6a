"""Connect to a Dask scheduler or start a LocalCluster; run chunks and gather them in order.

``--dask-scheduler ADDRESS`` uses a running scheduler (``tcp://host:8786``); ``--dask-local N``
starts a LocalCluster of N single-threaded worker processes for the run and closes it after.
Bad options and an unreachable scheduler are one-line :class:`InputError` messages naming the
option.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Any

from lynxplan.exceptions import InputError

#: How long a client waits for the scheduler before the run is refused.
CONNECT_TIMEOUT = "20s"


@dataclass(frozen=True)
class Cluster:
    """Where a run goes: a running scheduler, or a LocalCluster started for the run.

    Attributes:
        scheduler: Address of a running scheduler (``tcp://host:8786``), or None.
        local_workers: Worker processes of a LocalCluster (one thread each), or None.
        connect_timeout: How long to wait for the scheduler (Dask duration, e.g. ``"20s"``).
    """

    scheduler: str | None = None
    local_workers: int | None = None
    connect_timeout: str = CONNECT_TIMEOUT


def cluster_from_options(scheduler: str | None, local_workers: int | None) -> Cluster | None:
    """The cluster that ``--dask-scheduler`` / ``--dask-local`` name; None when neither is given.

    Raises:
        InputError: both options; a worker count below 1; an empty address.
    """
    if scheduler is not None and local_workers is not None:
        raise InputError("give one of --dask-local N and --dask-scheduler ADDRESS, not both")
    if local_workers is not None and local_workers < 1:
        raise InputError(f"--dask-local needs at least 1 worker. Got: {local_workers}")
    if scheduler is not None and not scheduler.strip():
        raise InputError("--dask-scheduler needs an address such as tcp://host:8786. Got: ''")
    if scheduler is None and local_workers is None:
        return None
    return Cluster(scheduler, local_workers)


@contextmanager
def open_client(cluster: Cluster) -> Iterator[Any]:
    """A ``distributed.Client`` of ``cluster``; a LocalCluster is closed on exit.

    Raises:
        InputError: the scheduler cannot be reached within ``cluster.connect_timeout``.
    """
    import distributed

    start_local: Any = distributed.LocalCluster
    client_of: Any = distributed.Client
    checked = cluster_from_options(cluster.scheduler, cluster.local_workers)
    if checked is None:
        raise InputError("give one of --dask-scheduler ADDRESS and --dask-local N")
    local: Any = None
    if cluster.local_workers is not None:
        local = start_local(
            n_workers=cluster.local_workers, threads_per_worker=1, processes=True,
            dashboard_address=None,
        )  # fmt: skip
    try:
        try:
            client = client_of(local or cluster.scheduler, timeout=cluster.connect_timeout)
        except (OSError, ValueError) as error:
            raise InputError(
                f"--dask-scheduler {cluster.scheduler}: cannot connect ({_one_line(error)})"
            ) from error
        with client:
            yield client
    finally:
        if local is not None:
            local.close()


def map_chunks(
    client: Any,
    function: Callable[..., Any],
    parts: Sequence[Any],
    *,
    sizes: Sequence[int] | None = None,
    progress: Callable[[int, int], None] | None = None,
    **kwargs: Any,
) -> list[Any]:
    """``[function(part, **kwargs) for part in parts]`` on the cluster, in the order of ``parts``.

    Args:
        client: A ``distributed.Client`` (:func:`open_client`).
        function: Module-level function (workers import it by name).
        parts: The chunks, each one task.
        sizes: Items in each chunk (for ``progress``); default 1 each.
        progress: Called as ``progress(done, total)`` in items as chunks finish.
        kwargs: Passed to every call (large objects: scatter them first).
    """
    import distributed

    as_completed: Any = distributed.as_completed
    counts = list(sizes) if sizes is not None else [1] * len(parts)
    if len(counts) != len(parts):
        raise InputError(f"map_chunks: {len(counts)} sizes for {len(parts)} parts")
    futures = [client.submit(function, part, pure=False, **kwargs) for part in parts]
    order = {future.key: k for k, future in enumerate(futures)}
    results: list[Any] = [None] * len(parts)
    done, total = 0, sum(counts)
    for future in as_completed(futures):
        k = order[future.key]
        results[k] = future.result()
        future.release()
        done += counts[k]
        if progress is not None:
            progress(done, total)
    return results


def _one_line(error: BaseException) -> str:
    return " ".join(str(error).split()) or type(error).__name__
