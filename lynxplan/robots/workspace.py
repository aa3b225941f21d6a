"""Workspace of any robot by sampling: tool points of random configurations, their voxel
occupancy volume, reach and height range.

The AL5 has a finer estimate (:mod:`lynxplan.arm.workspace`: a planar envelope refined at its
boundary and revolved over the base joint's range); this module works for every chain
:func:`lynxplan.load_robot` loads, through the robot's batch FK. The voxel volume counts the
voxels that hold a sampled tool point: it grows towards the true volume with more samples (a
lower estimate once the voxels are small against the workspace's thickness).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from lynxplan import guards
from lynxplan.exceptions import OutOfRangeError

#: Configurations per FK batch (memory: about 200 bytes each).
CHUNK = 200_000
#: Smallest voxel edge [m]: voxel indices of points within 10 m fit 21 bits per axis.
MIN_VOXEL = 1e-5


@dataclass(frozen=True)
class SampledWorkspace:
    """Tool points of uniformly random configurations within the joint limits.

    Attributes:
        positions: Kept tool points (a uniform subset), shape (K, 3), in [m].
        samples: Configurations sampled.
        volume_voxels: Volume of the voxels holding a tool point, in [m^3].
        voxel_size: Voxel edge, in [m].
        max_reach: Largest distance of a tool point from the base frame origin, in [m].
        z_range: Lowest and highest tool point height in the base frame, in [m].
    """

    positions: np.ndarray
    samples: int
    volume_voxels: float
    voxel_size: float
    max_reach: float
    z_range: tuple[float, float]


def sample_workspace(
    robot: Any,
    *,
    samples: int = 1_000_000,
    voxel_size: float = 0.005,
    seed: int = 0,
    keep: int = 200_000,
    progress: Callable[[int, int], None] | None = None,
) -> SampledWorkspace:
    """Sample ``samples`` configurations uniformly within the robot's limits.

    Args:
        robot: A :class:`lynxplan.robots.Robot`.
        samples: Number of random configurations (chunks of :data:`CHUNK`).
        voxel_size: Voxel edge of the occupancy volume, in [m].
        seed: Random seed (results are reproducible).
        keep: At most this many tool points are kept (for plots).
        progress: Called as ``progress(done, total)`` after each chunk.

    Raises:
        OutOfRangeError / InputError: a count, seed or length outside its documented range.
    """
    samples = guards.count("workspace samples", samples)
    guards.positive_length("workspace voxel_size", voxel_size)
    if not voxel_size >= MIN_VOXEL:
        raise OutOfRangeError("workspace voxel_size", voxel_size, f">= {MIN_VOXEL:g} m")
    rng = np.random.default_rng(guards.seed("workspace seed", seed))
    voxels: set[int] = set()
    kept: list[np.ndarray] = []
    max_reach, z_min, z_max = 0.0, math.inf, -math.inf
    done = 0
    while done < samples:
        size = min(CHUNK, samples - done)
        q = rng.uniform(robot.limits.lower, robot.limits.upper, size=(size, robot.nq))
        points = np.asarray(robot.fk(q))[:, :3, 3]
        index = np.floor(points / voxel_size).astype(np.int64) + 2**20  # in (0, 2**21)
        keys = (index[:, 0] << 42) | (index[:, 1] << 21) | index[:, 2]
        voxels.update(np.unique(keys).tolist())
        max_reach = max(max_reach, float(np.linalg.norm(points, axis=1).max()))
        z_min, z_max = min(z_min, float(points[:, 2].min())), max(z_max, float(points[:, 2].max()))
        kept.append(points[: max(1, keep * size // samples)])
        done += size
        if progress is not None:
            progress(done, samples)
    positions = np.concatenate(kept)
    positions.setflags(write=False)
    return SampledWorkspace(
        positions, samples, len(voxels) * voxel_size**3, voxel_size, max_reach, (z_min, z_max)
    )
