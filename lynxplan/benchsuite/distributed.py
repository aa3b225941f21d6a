"""SmallArmBench on Dask: the problems in chunks on a cluster, results in the serial order.

``run_on_dask(problems, scheduler=ADDRESS)`` uses a running scheduler; ``local_workers=N``
starts a LocalCluster of N single-threaded worker processes for the run. Each chunk is
:func:`lynxplan.benchsuite.runner.run_chunk` on a worker (a worker warms its kernels on its
first problem of each robot, outside the figures). Planning is seeded: every outcome (solved,
reason, path, lengths, dense check) equals the serial run's; only the times differ. The one
exception is a problem that the wall-clock time limit decides: one solved near the limit in one run
can time out in another (measured on the loaded 2-core machine: 1 of 60 problems, so101_shelf_001,
whose search needs about 2 s there).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import Any

from lynxplan.benchsuite.problem import Problem
from lynxplan.benchsuite.runner import TIME_LIMIT, ProblemResult, run_chunk
from lynxplan.exceptions import InputError

#: Problems per Dask task.
CHUNK = 8


def chunks(problems: Sequence[Problem], size: int = CHUNK) -> list[list[Problem]]:
    """``problems`` in consecutive chunks of at most ``size``."""
    if size < 1:
        raise InputError(f"chunk size must be at least 1. Got: {size}")
    return [list(problems[k : k + size]) for k in range(0, len(problems), size)]


def run_on_dask(
    problems: Sequence[Problem],
    *,
    scheduler: str | None = None,
    local_workers: int | None = None,
    chunk: int = CHUNK,
    seed: int = 0,
    time_limit: float = TIME_LIMIT,
    progress: Callable[[int, int], None] | None = None,
) -> list[ProblemResult]:
    """Every problem's result, run on a Dask cluster, in the order of ``problems``.

    Raises:
        InputError: neither or both of ``scheduler`` and ``local_workers``; a worker count
            below 1; a scheduler that cannot be reached.
    """
    import distributed

    client_of: Any = distributed.Client
    local_cluster: Any = distributed.LocalCluster
    as_completed: Any = distributed.as_completed

    if (scheduler is None) == (local_workers is None):
        raise InputError("give one of --dask-scheduler ADDRESS and --dask-local N")
    cluster: Any = None
    if local_workers is not None:
        if local_workers < 1:
            raise InputError(f"--dask-local needs at least 1 worker. Got: {local_workers}")
        cluster = local_cluster(
            n_workers=local_workers, threads_per_worker=1, processes=True,
            dashboard_address=None,
        )  # fmt: skip
    try:
        try:
            client = client_of(cluster if cluster is not None else scheduler, timeout="20s")
        except OSError as error:
            raise InputError(f"--dask-scheduler {scheduler}: cannot connect ({error})") from error
        with client:
            parts = chunks(problems, chunk)
            futures = [
                client.submit(run_chunk, part, seed=seed, time_limit=time_limit, pure=False)
                for part in parts
            ]
            order = {future.key: k for k, future in enumerate(futures)}
            done: dict[int, list[ProblemResult]] = {}
            count = 0
            for future in as_completed(futures):
                done[order[future.key]] = future.result()
                count += len(done[order[future.key]])
                if progress is not None:
                    progress(count, len(problems))
    finally:
        if cluster is not None:
            cluster.close()
    return [result for k in range(len(parts)) for result in done[k]]
