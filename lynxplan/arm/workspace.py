"""Workspace of the 5-DOF arm: the report's grid, dense sampling, reach envelope, volume.

The tool point depends on q1..q4 only (q5 turns the pen about its own axis). In the arm's
vertical plane it sits at signed radial distance ``r`` and height ``z`` (SPEC Part 1 closed form);
q1 in [q1_min, q1_max] sweeps that planar region P about the base axis. With q1 spanning a half
turn, r > 0 and r < 0 cover opposite half-spaces, so the volume is exactly
``V = (q1_max - q1_min) * integral over P of |r| dr dz`` — estimated here on a fine (r, z) grid —
and cross-checked by counting occupied voxels of dense 3-D samples.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numba
import numpy as np

from lynxplan.arm.geometry import ArmGeometry, JointLimits
from lynxplan.exceptions import InputError, OutOfRangeError

#: Report sampling steps, in [rad]: q1 by pi/60, q2..q4 by pi/15.
REPORT_STEP_Q1 = math.pi / 60
REPORT_STEP_ARM = math.pi / 15


class Envelope(NamedTuple):
    """Occupancy of the (radial, height) half-plane, r = sqrt(x^2 + y^2) >= 0."""

    occupied: np.ndarray
    """Occupied cells, shape (n_z, n_r), bool; row i is height ``z_edges[i]..z_edges[i+1]``."""
    r_edges: np.ndarray
    """Cell edges along the radial axis, shape (n_r + 1,), in [m]."""
    z_edges: np.ndarray
    """Cell edges along the height axis, shape (n_z + 1,), in [m]."""
    cell: float
    """Cell size, in [m]."""


class WorkspaceEstimate(NamedTuple):
    """Dense workspace estimate. Lengths in [m], volumes in [m^3]."""

    positions: np.ndarray
    """Sampled tool points, shape (N, 3) (a subsample is kept for plots when N is large)."""
    samples: int
    """Number of configurations sampled."""
    envelope: Envelope
    """Reach envelope in the (radial, height) half-plane, from the planar region P."""
    volume_revolution: float
    """Volume by revolving P about the base axis over the q1 range (grid cell ``envelope.cell``)."""
    volume_voxels: float
    """Volume of the occupied voxels of the 3-D samples (a lower bound that grows with N)."""
    voxel_size: float
    """Voxel edge used for ``volume_voxels``."""
    max_reach: float
    """Largest distance of a sampled tool point from the shoulder."""
    z_range: tuple[float, float]
    """Lowest and highest sampled tool heights."""


@numba.njit(cache=True, nogil=True)
def planar_tool_kernel(q: np.ndarray, a2: float, a3: float, d5: float, out: np.ndarray) -> None:
    """Signed radial distance and height of the tool point, q (N, >=4) -> out (N, 2), in [m]."""
    for k in range(q.shape[0]):
        q2, q23 = q[k, 1], q[k, 1] + q[k, 2]
        q234 = q23 + q[k, 3]
        out[k, 0] = d5 * math.sin(q234) + a3 * math.cos(q23) + a2 * math.cos(q2)
        out[k, 1] = a3 * math.sin(q23) + a2 * math.sin(q2) - d5 * math.cos(q234)


@numba.njit(cache=True, nogil=True)
def _in_range(x: float, lo: float, hi: float) -> bool:
    """Whether angle x, moved by whole turns, lies in [lo, hi]."""
    return lo + (x - lo) % (2.0 * math.pi) <= hi


@numba.njit(cache=True, nogil=True)
def planar_membership_kernel(
    points: np.ndarray,
    a2: float,
    a3: float,
    d5: float,
    lower: np.ndarray,
    upper: np.ndarray,
    step: float,
    out: np.ndarray,
) -> None:
    """Whether each planar point (r, z) (N, 2) is a tool point of some q2..q4 within limits.

    Scans the approach pitch psi = q2 + q3 + q4 over its range with ``step`` [rad]; for each psi
    the wrist centre is fixed, and the planar 2R IK (both elbows) and the q4 range decide. A point
    within ``d5 * step`` of the boundary can be missed.
    """
    psi_lo = lower[1] + lower[2] + lower[3]
    psi_hi = upper[1] + upper[2] + upper[3]
    n_steps = math.ceil((psi_hi - psi_lo) / step) + 1
    for k in range(points.shape[0]):
        r, z = points[k, 0], points[k, 1]
        out[k] = False
        for i in range(n_steps):
            psi = min(psi_lo + i * step, psi_hi)
            wr, wz = r - d5 * math.sin(psi), z + d5 * math.cos(psi)
            c3 = (wr * wr + wz * wz - a2 * a2 - a3 * a3) / (2.0 * a2 * a3)
            if c3 < -1.0 or c3 > 1.0:
                continue
            s3 = math.sqrt(1.0 - c3 * c3)
            phi = math.atan2(wz, wr)
            beta = math.atan2(a3 * s3, a2 + a3 * c3)
            for q3, q2 in ((-math.acos(c3), phi + beta), (math.acos(c3), phi - beta)):
                if (
                    _in_range(q3, lower[2], upper[2])
                    and _in_range(q2, lower[1], upper[1])
                    and _in_range(psi - q2 - q3, lower[3], upper[3])
                ):
                    out[k] = True
                    break
            if out[k]:
                break


def report_grid(limits: JointLimits) -> np.ndarray:
    """The report's sampling grid: q1 by pi/60, q2..q4 by pi/15 within limits, q5 = 0.

    Returns:
        Configurations, shape (N, 5), in [rad] (N = 164,944 for the AL5 limits).
    """
    axes = [np.arange(limits.lower[0], limits.upper[0] + 1e-12, REPORT_STEP_Q1)]
    axes += [
        np.arange(limits.lower[joint], limits.upper[joint] + 1e-12, REPORT_STEP_ARM)
        for joint in (1, 2, 3)
    ]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 4)
    return np.column_stack((grid, np.zeros(grid.shape[0])))


def tool_positions(q: np.ndarray, geometry: ArmGeometry) -> np.ndarray:
    """Tool points of configurations q (N, 5) in [rad] -> (N, 3) in [m]."""
    planar = np.empty((q.shape[0], 2))
    planar_tool_kernel(np.ascontiguousarray(q), geometry.a2, geometry.a3, geometry.d5, planar)
    return np.column_stack(
        (np.cos(q[:, 0]) * planar[:, 0], np.sin(q[:, 0]) * planar[:, 0], planar[:, 1])
    )


def checked_inputs(
    geometry: ArmGeometry, samples: int, voxel_size: float, cell: float, seed: int
) -> tuple[int, int]:
    """The sample count and seed of :func:`estimate_workspace` checked (and the sizes they imply:
    the planar grid, the voxel indices), for the serial sweep and the Dask one alike.

    Raises:
        InputError: for a non-positive sample count, voxel or cell size, a grid too large.
    """
    if samples < 1:
        raise InputError(f"workspace: samples must be >= 1. Got: {samples}")
    for name, value in (("voxel_size", voxel_size), ("cell", cell)):
        if not (math.isfinite(value) and value > 0):
            raise InputError(f"workspace: {name} must be a positive length in m. Got: {value}")
    from lynxplan import guards

    samples = guards.count("workspace samples", samples)
    guards.positive_length("workspace voxel_size", voxel_size)
    guards.positive_length("workspace cell", cell)
    seed = guards.seed("workspace seed", seed)
    reach = geometry.max_reach
    guards.grid_cells("workspace planar grid cells", 2 * reach, cell, 2)
    if 2 * reach / voxel_size + 2 > 2**20:  # voxel indices (per axis cubed) must fit an int64
        raise OutOfRangeError(
            "workspace voxel_size", voxel_size, f">= {2 * reach / 2**20:.3g} m for this arm"
        )
    return samples, seed


def estimate_workspace(
    geometry: ArmGeometry,
    limits: JointLimits,
    *,
    samples: int = 2_000_000,
    voxel_size: float = 0.005,
    cell: float = 0.001,
    seed: int = 0,
    keep: int = 200_000,
    progress: Callable[[int, int], None] | None = None,
) -> WorkspaceEstimate:
    """Sample the workspace densely and estimate its envelope and volume.

    Args:
        geometry: Arm dimensions.
        limits: Joint limits; configurations are drawn uniformly within them.
        samples: Number of random configurations (millions are fine: chunks of 500,000).
        voxel_size: Voxel edge for the 3-D occupancy volume, in [m].
        cell: Cell edge of the planar (r, z) grid for the envelope and revolution volume, in [m].
        seed: Random seed (results are reproducible).
        keep: At most this many tool points are kept in the result (for plots).
        progress: Called as ``progress(done, total)`` after each chunk.

    Raises:
        InputError: for a non-positive sample count, voxel or cell size.
    """
    samples, seed = checked_inputs(geometry, samples, voxel_size, cell, seed)
    rng = np.random.default_rng(seed)
    reach = geometry.max_reach
    n_cells = math.ceil(2 * reach / cell) + 2
    planar_counts = np.zeros((n_cells, n_cells), dtype=bool)  # (z, signed r) over [-reach, reach]
    voxels: set[int] = set()
    n_vox = math.ceil(2 * reach / voxel_size) + 2
    kept: list[np.ndarray] = []
    max_reach, z_min, z_max = 0.0, math.inf, -math.inf
    done, chunk = 0, 500_000
    while done < samples:
        size = min(chunk, samples - done)
        q = rng.uniform(limits.lower, limits.upper, size=(size, 5))
        planar = np.empty((size, 2))
        planar_tool_kernel(q, geometry.a2, geometry.a3, geometry.d5, planar)
        ir = np.floor((planar[:, 0] + reach) / cell).astype(np.int64)
        iz = np.floor((planar[:, 1] + reach) / cell).astype(np.int64)
        planar_counts[iz, ir] = True
        points = np.column_stack(
            (np.cos(q[:, 0]) * planar[:, 0], np.sin(q[:, 0]) * planar[:, 0], planar[:, 1])
        )
        index = np.floor((points + reach) / voxel_size).astype(np.int64)
        voxels.update(np.unique((index[:, 0] * n_vox + index[:, 1]) * n_vox + index[:, 2]).tolist())
        max_reach = max(max_reach, float(np.sqrt((planar**2).sum(axis=1)).max()))
        z_min, z_max = min(z_min, float(planar[:, 1].min())), max(z_max, float(planar[:, 1].max()))
        kept.append(points[: max(0, keep * size // samples)])
        done += size
        if progress is not None:
            progress(done, samples)
    centres = (np.arange(n_cells) + 0.5) * cell - reach
    step = membership_step(geometry, cell)
    planar_member = refine_boundary(
        planar_counts, centres, lambda points: exact_membership(points, geometry, limits, step)
    )
    sweep = float(limits.upper[0] - limits.lower[0])
    # Revolution volume (midpoint rule): sweep * sum over member cells of |r| * cell^2.
    volume_revolution = sweep * float((planar_member * np.abs(centres)[None, :]).sum()) * cell**2
    return WorkspaceEstimate(
        positions=np.concatenate(kept),
        samples=samples,
        envelope=_fold_envelope(planar_member, cell, reach),
        volume_revolution=volume_revolution,
        volume_voxels=len(voxels) * voxel_size**3,
        voxel_size=voxel_size,
        max_reach=max_reach,
        z_range=(z_min, z_max),
    )


def _shifted_any(mask: np.ndarray, radius: int) -> np.ndarray:
    """Dilation of a 2-D mask by a (2 radius + 1)^2 square."""
    out = mask.copy()
    for di in range(-radius, radius + 1):
        for dj in range(-radius, radius + 1):
            out |= np.roll(np.roll(mask, di, axis=0), dj, axis=1)
    return np.asarray(out)


def refine_boundary(
    sampled: np.ndarray,
    centres: np.ndarray,
    membership: Callable[[np.ndarray], np.ndarray],
) -> np.ndarray:
    """Planar membership at cell centres: sampled interior cells are kept, and every cell near
    the sampled boundary (or in a sampling hole) is decided by the exact membership test.

    Args:
        sampled: (nz, nr) bool, the cells a sample fell in.
        centres: (n,) cell centres along r and z, in [m].
        membership: The exact test of planar points (k, 2) (r, z) [m] -> (k,) bool
            (:func:`exact_membership`, or the same in chunks on a Dask cluster).
    """
    interior = ~_shifted_any(~sampled, 1)
    candidates = _shifted_any(sampled, 2) & ~interior
    iz, ir = np.nonzero(candidates)
    member = membership(np.column_stack((centres[ir], centres[iz])))
    result: np.ndarray = interior.copy()
    result[iz[member], ir[member]] = True
    return result


def membership_step(geometry: ArmGeometry, cell: float) -> float:
    """The exact membership test's wrist-angle step [rad] for cells of ``cell`` [m]."""
    return 0.5 * cell / geometry.d5


def exact_membership(
    points: np.ndarray, geometry: ArmGeometry, limits: JointLimits, step: float
) -> np.ndarray:
    """:func:`planar_membership_kernel` of planar points (k, 2) (r, z) [m]: (k,) bool."""
    member = np.empty(points.shape[0], dtype=np.bool_)
    planar_membership_kernel(
        points, geometry.a2, geometry.a3, geometry.d5, limits.lower, limits.upper, step, member
    )
    return member


def _fold_envelope(planar: np.ndarray, cell: float, reach: float) -> Envelope:
    """Signed-r occupancy -> occupancy of the half-plane r >= 0 (both signs folded)."""
    n = planar.shape[1]
    centre = round(reach / cell)  # index of the cell starting at r = 0
    positive = planar[:, centre:]
    negative = planar[:, :centre][:, ::-1]
    width = max(positive.shape[1], negative.shape[1])
    folded = np.zeros((planar.shape[0], width), dtype=bool)
    folded[:, : positive.shape[1]] |= positive
    folded[:, : negative.shape[1]] |= negative
    r_edges = (np.arange(width + 1)) * cell + (centre * cell - reach)
    z_edges = np.arange(n + 1) * cell - reach
    return Envelope(folded, r_edges, z_edges, cell)
