"""Large IK batches on Dask: ``Robot.ik_batch`` of consecutive chunks of poses on workers,
concatenated in order: the same arrays as one serial ``ik_batch`` (each target is solved on its
own; the chunks only split the rows).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from lynxplan.exceptions import InputError
from lynxplan.fanout.cluster import Cluster, map_chunks, open_client

#: Poses per Dask task (about 6 MB of poses out, 13 MB of answers back for 4 branch slots).
IK_CHUNK = 50_000


def _ik_chunk(poses: np.ndarray, robot: Any) -> Any:
    """``robot.ik_batch(poses)`` on a worker."""
    return robot.ik_batch(poses)


def ik_batch_on_dask(
    robot: Any,
    poses: np.ndarray,
    *,
    cluster: Cluster,
    chunk: int = IK_CHUNK,
    progress: Callable[[int, int], None] | None = None,
) -> Any:
    """``robot.ik_batch(poses)`` in chunks on ``cluster``: the same :class:`RobotIkBatch`.

    Args:
        robot: A :class:`lynxplan.robots.Robot`.
        poses: Target tool poses, shape (N, 4, 4), [m], N >= 1.
        cluster: Where to run (:func:`lynxplan.fanout.cluster_from_options`).
        chunk: Poses per task.
        progress: Called as ``progress(done, total)`` in poses as chunks finish.

    Raises:
        InputError: a chunk below 1 or no poses; an unreachable scheduler.
    """
    from lynxplan.robots.results import RobotIkBatch

    if chunk < 1:
        raise InputError(f"IK batch chunk must be at least 1. Got: {chunk}")
    if poses.ndim != 3 or poses.shape[0] < 1:
        raise InputError(f"IK batch poses must have shape (N, 4, 4), N >= 1. Got: {poses.shape}")
    parts = [poses[k : k + chunk] for k in range(0, poses.shape[0], chunk)]
    with open_client(cluster) as client:
        [robot_f] = client.scatter([robot], broadcast=True)
        done = map_chunks(client, _ik_chunk, parts, sizes=[len(p) for p in parts],
                          progress=progress, robot=robot_f)  # fmt: skip
    arrays: dict[str, Any] = {}
    for name in RobotIkBatch._fields[:-1]:
        arrays[name] = np.concatenate([getattr(part, name) for part in done])
        arrays[name].setflags(write=False)
    return RobotIkBatch(**arrays, branch_names=done[0].branch_names)
