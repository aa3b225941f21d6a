"""SmallArmBench on Dask: the problems in chunks on a cluster, results in the serial order.

``run_on_dask(problems, scheduler=ADDRESS)`` uses a running scheduler; ``local_workers=N``
starts a LocalCluster of N single-threaded worker processes for the run. Each chunk is
:func:`lynxplan.benchsuite.runner.run_chunk` on a worker (a worker warms its kernels on its
first problem of each robot, outside the figures). Planning is seeded and a node budget decides
"solved" (``runner.NODE_BUDGET``), not the wall clock: every outcome (solved, reason, path,
lengths, dense check) equals the serial run's, on a loaded machine too; only the times differ.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from lynxplan.benchsuite.problem import Problem
from lynxplan.benchsuite.runner import SAFETY_TIME_LIMIT, ProblemResult, run_chunk
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
    time_limit: float = SAFETY_TIME_LIMIT,
    progress: Callable[[int, int], None] | None = None,
) -> list[ProblemResult]:
    """Every problem's result, run on a Dask cluster, in the order of ``problems``.

    Raises:
        InputError: neither or both of ``scheduler`` and ``local_workers``; a worker count
            below 1; a scheduler that cannot be reached.
    """
    from lynxplan.fanout.cluster import Cluster, map_chunks, open_client

    parts = chunks(problems, chunk)
    with open_client(Cluster(scheduler, local_workers)) as client:
        done = map_chunks(client, run_chunk, parts, sizes=[len(p) for p in parts],
                          progress=progress, seed=seed, time_limit=time_limit)  # fmt: skip
    return [result for part in done for result in part]
