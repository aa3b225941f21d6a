"""Workspace sweeps on Dask: the serial sweep's chunks on workers, merged into the same estimate.

The serial sweeps (:func:`lynxplan.arm.workspace.estimate_workspace`,
:func:`lynxplan.robots.workspace.sample_workspace`) draw chunk after chunk from one
``numpy.random.default_rng(seed)`` stream. Here the worker of a chunk starting at sample ``s``
makes the same generator and advances it by ``s * nq`` draws (PCG64 ``advance``: one 64-bit draw
per uniform double), so it draws the very numbers the serial sweep draws for that chunk; nothing
but seeds and offsets is shipped. Chunks follow the serial chunk boundaries, so that the kept
tool points (the first ``keep * size // samples`` of each chunk) are the same too. Each worker
returns its chunk's reductions (occupied planar cells, occupied voxel keys, reach, height
range, kept points); the client merges them: the estimate equals the serial one bit for bit.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, NamedTuple

import numpy as np

from lynxplan import guards
from lynxplan.exceptions import OutOfRangeError
from lynxplan.fanout.cluster import Cluster, map_chunks, open_client

#: Configurations per chunk of the AL5 sweep (the serial sweep's chunk).
AL5_CHUNK = 500_000
#: Tasks of the AL5's exact boundary refinement (candidate cells split evenly).
MEMBERSHIP_TASKS = 16


class ChunkReduction(NamedTuple):
    """What one chunk of samples contributes to the estimate."""

    planar: np.ndarray | None
    """Occupied (z, signed r) cells, shape (n, n), bool (the AL5 only; else None)."""
    voxels: np.ndarray
    """Occupied voxel keys, sorted and unique, int64."""
    reach: float
    """Largest distance of a tool point (from the shoulder / the base origin), [m]."""
    z_min: float
    """Lowest tool point, [m]."""
    z_max: float
    """Highest tool point, [m]."""
    kept: np.ndarray
    """Tool points kept for plots, shape (k, 3), [m]."""


def _chunks(samples: int, chunk: int, keep: int, floor: int) -> list[tuple[int, int, int]]:
    """(start, size, kept rows) of each serial chunk."""
    return [
        (
            start,
            min(chunk, samples - start),
            max(floor, keep * min(chunk, samples - start) // samples),
        )
        for start in range(0, samples, chunk)
    ]


def _draw(seed: int, start: int, size: int, lower: np.ndarray, upper: np.ndarray) -> np.ndarray:
    """The serial stream's configurations ``start .. start + size``, shape (size, n), [rad]."""
    rng = np.random.default_rng(seed)
    rng.bit_generator.advance(start * lower.shape[0])  # type: ignore[attr-defined]
    return rng.uniform(lower, upper, size=(size, lower.shape[0]))


def _al5_chunk(part: tuple[int, int, int], geometry: Any, limits: Any, seed: int,
               cell: float, voxel_size: float) -> ChunkReduction:  # fmt: skip
    """One chunk of :func:`lynxplan.arm.workspace.estimate_workspace`, as it computes it."""
    from lynxplan.arm.workspace import planar_tool_kernel

    start, size, kept = part
    reach = geometry.max_reach
    n_cells, n_vox = math.ceil(2 * reach / cell) + 2, math.ceil(2 * reach / voxel_size) + 2
    q = _draw(seed, start, size, limits.lower, limits.upper)
    planar = np.empty((size, 2))
    planar_tool_kernel(q, geometry.a2, geometry.a3, geometry.d5, planar)
    occupied = np.zeros((n_cells, n_cells), dtype=bool)
    ir = np.floor((planar[:, 0] + reach) / cell).astype(np.int64)
    iz = np.floor((planar[:, 1] + reach) / cell).astype(np.int64)
    occupied[iz, ir] = True
    points = np.column_stack(
        (np.cos(q[:, 0]) * planar[:, 0], np.sin(q[:, 0]) * planar[:, 0], planar[:, 1])
    )
    index = np.floor((points + reach) / voxel_size).astype(np.int64)
    keys = np.unique((index[:, 0] * n_vox + index[:, 1]) * n_vox + index[:, 2])
    return ChunkReduction(
        occupied, keys, float(np.sqrt((planar**2).sum(axis=1)).max()),
        float(planar[:, 1].min()), float(planar[:, 1].max()), points[:kept],
    )  # fmt: skip


def _robot_chunk(part: tuple[int, int, int], robot: Any, seed: int,
                 voxel_size: float) -> ChunkReduction:  # fmt: skip
    """One chunk of :func:`lynxplan.robots.workspace.sample_workspace`, as it computes it."""
    start, size, kept = part
    q = _draw(seed, start, size, robot.limits.lower, robot.limits.upper)
    points = np.asarray(robot.fk(q))[:, :3, 3]
    index = np.floor(points / voxel_size).astype(np.int64) + 2**20
    keys = np.unique((index[:, 0] << 42) | (index[:, 1] << 21) | index[:, 2])
    return ChunkReduction(
        None, keys, float(np.linalg.norm(points, axis=1).max()),
        float(points[:, 2].min()), float(points[:, 2].max()), points[:kept],
    )  # fmt: skip


def _membership_chunk(points: np.ndarray, geometry: Any, limits: Any, step: float) -> np.ndarray:
    """:func:`lynxplan.arm.workspace.exact_membership` of planar points (k, 2) [m]."""
    from lynxplan.arm.workspace import exact_membership

    return exact_membership(points, geometry, limits, step)


def _membership_on(client: Any, geometry: Any, limits: Any, step: float) -> Any:
    """The exact membership test (most of the serial sweep's time: 2.3 of 4.5 s at 2e6 samples
    and 1 mm cells) in chunks on the cluster, for :func:`lynxplan.arm.workspace.refine_boundary`
    (geometry and limits: their futures)."""

    def membership(points: np.ndarray) -> np.ndarray:
        parts = np.array_split(points, max(1, min(MEMBERSHIP_TASKS, points.shape[0] // 1000)))
        return np.concatenate(map_chunks(client, _membership_chunk, parts, geometry=geometry,
                                         limits=limits, step=step))  # fmt: skip

    return membership


def _merge(parts: list[ChunkReduction]) -> tuple[int, float, float, float, np.ndarray]:
    """Occupied voxel count, reach, z range and kept points of all chunks."""
    voxels: set[int] = set()  # a set: 7x faster than np.unique of the concatenated keys
    for part in parts:
        voxels.update(part.voxels.tolist())
    reach = max([0.0, *(p.reach for p in parts)])
    z_min, z_max = min(p.z_min for p in parts), max(p.z_max for p in parts)
    return len(voxels), reach, z_min, z_max, np.concatenate([p.kept for p in parts])


def estimate_workspace_on_dask(
    geometry: Any,
    limits: Any,
    *,
    cluster: Cluster,
    samples: int = 2_000_000,
    voxel_size: float = 0.005,
    cell: float = 0.001,
    seed: int = 0,
    keep: int = 200_000,
    progress: Callable[[int, int], None] | None = None,
) -> Any:
    """:func:`lynxplan.arm.workspace.estimate_workspace` on ``cluster``: the same estimate.

    Raises:
        InputError: as the serial sweep; an unreachable scheduler.
    """
    from lynxplan.arm import workspace as serial

    samples, seed = serial.checked_inputs(geometry, samples, voxel_size, cell, seed)
    reach = geometry.max_reach
    parts = _chunks(samples, AL5_CHUNK, keep, 0)
    with open_client(cluster) as client:
        geometry_f, limits_f = client.scatter([geometry, limits], broadcast=True)
        done = map_chunks(
            client, _al5_chunk, parts, sizes=[p[1] for p in parts], progress=progress,
            geometry=geometry_f, limits=limits_f, seed=seed, cell=cell, voxel_size=voxel_size,
        )  # fmt: skip
        planar = np.logical_or.reduce([p.planar for p in done])
        centres = (np.arange(planar.shape[0]) + 0.5) * cell - reach
        step = serial.membership_step(geometry, cell)
        member = serial.refine_boundary(
            planar, centres, _membership_on(client, geometry_f, limits_f, step)
        )
    voxel_count, max_reach, z_min, z_max, kept = _merge(done)
    sweep = float(limits.upper[0] - limits.lower[0])
    volume_revolution = sweep * float((member * np.abs(centres)[None, :]).sum()) * cell**2
    return serial.WorkspaceEstimate(
        positions=kept,
        samples=samples,
        envelope=serial._fold_envelope(member, cell, reach),
        volume_revolution=volume_revolution,
        volume_voxels=voxel_count * voxel_size**3,
        voxel_size=voxel_size,
        max_reach=max_reach,
        z_range=(z_min, z_max),
    )


def sample_workspace_on_dask(
    robot: Any,
    *,
    cluster: Cluster,
    samples: int = 1_000_000,
    voxel_size: float = 0.005,
    seed: int = 0,
    keep: int = 200_000,
    progress: Callable[[int, int], None] | None = None,
) -> Any:
    """:func:`lynxplan.robots.workspace.sample_workspace` on ``cluster``: the same result.

    Raises:
        InputError: as the serial sweep; an unreachable scheduler.
    """
    from lynxplan.robots import workspace as serial

    samples = guards.count("workspace samples", samples)
    guards.positive_length("workspace voxel_size", voxel_size)
    if not voxel_size >= serial.MIN_VOXEL:
        raise OutOfRangeError("workspace voxel_size", voxel_size, f">= {serial.MIN_VOXEL:g} m")
    seed = guards.seed("workspace seed", seed)
    parts = _chunks(samples, serial.CHUNK, keep, 1)
    with open_client(cluster) as client:
        [robot_f] = client.scatter([robot], broadcast=True)
        done = map_chunks(
            client, _robot_chunk, parts, sizes=[p[1] for p in parts], progress=progress,
            robot=robot_f, seed=seed, voxel_size=voxel_size,
        )  # fmt: skip
    voxel_count, max_reach, z_min, z_max, kept = _merge(done)
    kept.setflags(write=False)
    return serial.SampledWorkspace(
        kept, samples, voxel_count * voxel_size**3, voxel_size, max_reach, (z_min, z_max)
    )
