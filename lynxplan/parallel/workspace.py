"""Constant-orientation workspace of the planar 3-RRR on a grid, and stacks over orientations.

A platform centre ``(x, y)`` is in the workspace at orientation alpha when every leg reaches its
platform joint: ``|S - L| <= |c - rp u_i(alpha) - B_i| <= S + L`` (SPEC Part 4; the report scans
x 70..420 mm, y 0..320 mm on a 1 mm grid). The area is the number of grid points times the cell
area ``step^2`` (each point stands for the cell around it), which converges as the step shrinks.

Restricted to a working mode, the workspace is the part that mode can sweep without crossing a
Type II singularity: the points where that mode's direct-Jacobian determinant keeps one sign,
connected (4-neighbours) to a seed point — by default the largest such region.

Lengths in [m], angles in [rad]; ``area_mm2`` for the report's unit.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from lynxplan.exceptions import InputError, NonFiniteInputError
from lynxplan.parallel._legs import anchor
from lynxplan.parallel.geometry import ParallelGeometry
from lynxplan.parallel.ik import kernel_constants, mode_index
from lynxplan.parallel.singular import type2_grid

_DEFAULT_GEOMETRY = ParallelGeometry()
#: The report's scan region, in [m].
REPORT_X_RANGE = (0.070, 0.420)
REPORT_Y_RANGE = (0.0, 0.320)


@numba.njit(cache=True, nogil=True)
def reach_kernel(
    x: np.ndarray,
    y: np.ndarray,
    alphas: np.ndarray,
    platform: tuple[np.ndarray, np.ndarray, float],
    leg_reach: tuple[float, float],
    out: np.ndarray,
) -> None:
    """``out[k, i, j]`` = every leg reaches at centre ``(x[j], y[i])`` and orientation
    ``alphas[k]``; ``out`` has shape (K, ny, nx). ``platform`` = (base, phase, rp): the base
    anchors, the platform anchors' phases and circumradius (``kernel_constants``, [m], [rad],
    [m]); ``leg_reach`` = (lo, hi): the annulus a leg's platform anchor reaches [m]."""
    base, phase, rp = platform
    lo, hi = leg_reach
    lo2, hi2 = lo * lo, hi * hi
    nx = x.shape[0]
    dx2 = np.empty((3, nx))
    for k in range(alphas.shape[0]):
        ca, sa = math.cos(alphas[k]), math.sin(alphas[k])
        ox = np.empty(3)
        oy = np.empty(3)
        for leg in range(3):
            # Leg reaches iff the centre is in the annulus about B_i + rp u_i(alpha).
            ox[leg], oy[leg] = anchor(base, ca, sa, phase, rp, leg)
            for j in range(nx):
                dx2[leg, j] = (x[j] - ox[leg]) ** 2
        for i in range(y.shape[0]):
            dy0 = (y[i] - oy[0]) ** 2
            dy1 = (y[i] - oy[1]) ** 2
            dy2 = (y[i] - oy[2]) ** 2
            row = out[k, i]
            for j in range(nx):
                r0 = dx2[0, j] + dy0
                r1 = dx2[1, j] + dy1
                r2 = dx2[2, j] + dy2
                row[j] = lo2 <= r0 <= hi2 and lo2 <= r1 <= hi2 and lo2 <= r2 <= hi2


@numba.njit(cache=True, nogil=True)
def label_kernel(sign: np.ndarray, labels: np.ndarray) -> int:
    """4-connected labelling of the cells with equal nonzero ``sign`` (ny, nx) into ``labels``
    (0 = none, 1..n); returns n."""
    ny, nx = sign.shape
    labels[:] = 0
    stack = np.empty(ny * nx, dtype=np.int64)
    count = 0
    for start in range(ny * nx):
        si, sj = start // nx, start % nx
        if sign[si, sj] == 0 or labels[si, sj] != 0:
            continue
        count += 1
        labels[si, sj] = count
        top = 0
        stack[0] = start
        top = 1
        while top > 0:
            top -= 1
            cell = stack[top]
            i, j = cell // nx, cell % nx
            for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                a, b = i + di, j + dj
                if 0 <= a < ny and 0 <= b < nx and labels[a, b] == 0 and sign[a, b] == sign[i, j]:
                    labels[a, b] = count
                    stack[top] = a * nx + b
                    top += 1
    return count


def grid_axes(
    step: float,
    x_range: tuple[float, float] = REPORT_X_RANGE,
    y_range: tuple[float, float] = REPORT_Y_RANGE,
) -> tuple[np.ndarray, np.ndarray]:
    """Grid abscissae and ordinates covering the ranges (ends included when they fall on the
    grid), in [m]; ``step`` in [m]."""
    for name, value in (
        ("step", step),
        *zip(("x_min", "x_max"), x_range, strict=True),
        *zip(("y_min", "y_max"), y_range, strict=True),
    ):
        if not math.isfinite(value):
            raise NonFiniteInputError(name)
    if step <= 0:
        raise InputError(f"workspace grid step must be positive. Got: {step * 1e3:g} mm")
    if x_range[1] <= x_range[0] or y_range[1] <= y_range[0]:
        raise InputError(f"workspace region must have min < max. Got: x {x_range}, y {y_range} m")
    from lynxplan import guards

    cells = ((x_range[1] - x_range[0]) / step + 1) * ((y_range[1] - y_range[0]) / step + 1)
    guards.check_size(f"workspace grid points for a {step * 1e3:.3g} mm step", cells, 9.0)
    axes = []
    for lo, hi in (x_range, y_range):
        n = math.floor((hi - lo) / step + 1e-9) + 1
        if n < 2:
            raise InputError(
                f"workspace grid step {step * 1e3:g} mm is larger than the region "
                f"({(hi - lo) * 1e3:g} mm): at least 2 grid points per axis are needed"
            )
        if n > 20_000:
            raise InputError(
                f"workspace grid step {step * 1e3:g} mm gives {n} points per axis (at most 20000)"
            )
        axes.append(lo + step * np.arange(n))
    return axes[0], axes[1]


class Workspace(NamedTuple):
    """A constant-orientation workspace on a grid."""

    alpha: float
    """Platform orientation, in [rad]."""
    x: np.ndarray
    """Grid abscissae, shape (nx,), in [m]."""
    y: np.ndarray
    """Grid ordinates, shape (ny,), in [m]."""
    step: float
    """Grid step, in [m]."""
    mask: np.ndarray
    """Points in the workspace, shape (ny, nx), bool."""
    mode: int | None
    """Working mode the workspace is restricted to, or None."""

    @property
    def points(self) -> int:
        """Number of grid points in the workspace."""
        return int(np.count_nonzero(self.mask))

    @property
    def area(self) -> float:
        """Area, in [m^2] (points times ``step^2``)."""
        return self.points * self.step**2

    @property
    def area_mm2(self) -> float:
        """Area, in [mm^2]."""
        return self.area * 1e6


def reachable_stack(
    alphas: np.ndarray, x: np.ndarray, y: np.ndarray, geometry: ParallelGeometry = _DEFAULT_GEOMETRY
) -> np.ndarray:
    """Reachability of every grid point at every orientation, shape (K, ny, nx), bool.

    Args:
        alphas: Orientations, shape (K,), in [rad].
        x: Grid abscissae, shape (nx,), in [m].
        y: Grid ordinates, shape (ny,), in [m].
        geometry: Robot dimensions.
    """
    alphas = np.atleast_1d(np.asarray(alphas, dtype=float))
    if not np.all(np.isfinite(alphas)):
        raise NonFiniteInputError("alphas")
    base, phase = kernel_constants(geometry)
    out = np.empty((alphas.size, len(y), len(x)), dtype=np.bool_)
    reach_kernel(
        np.ascontiguousarray(x, dtype=float),
        np.ascontiguousarray(y, dtype=float),
        alphas,
        (base, phase, geometry.platform_circumradius),
        geometry.leg_reach,
        out,
    )
    return out


def constant_orientation_workspace(
    alpha: float,
    geometry: ParallelGeometry = _DEFAULT_GEOMETRY,
    *,
    step: float = 1e-3,
    x_range: tuple[float, float] = REPORT_X_RANGE,
    y_range: tuple[float, float] = REPORT_Y_RANGE,
    mode: int | str | None = None,
    seed: tuple[float, float] | None = None,
) -> Workspace:
    """The constant-orientation workspace at ``alpha``.

    Args:
        alpha: Platform orientation, in [rad].
        geometry: Robot dimensions.
        step: Grid step, in [m].
        x_range: Scanned abscissae (min, max), in [m].
        y_range: Scanned ordinates (min, max), in [m].
        mode: Restrict to the singularity-free region of this working mode (index or label).
        seed: With ``mode``, the centre ``(x, y)`` in [m] whose region is kept; default the
            largest region.

    Raises:
        InputError: bad step or region, or a seed outside the mode's singularity-free workspace.
    """
    from lynxplan import guards

    alpha = guards.angle("alpha", alpha)
    x, y = grid_axes(step, x_range, y_range)
    mask = reachable_stack(np.array([alpha]), x, y, geometry)[0]
    if mode is None:
        return Workspace(float(alpha), x, y, step, mask, None)
    index = mode_index(mode)
    region = mode_region(type2_grid(x, y, alpha, index, geometry), x, y, seed)
    return Workspace(float(alpha), x, y, step, region, index)


def mode_region(
    det: np.ndarray, x: np.ndarray, y: np.ndarray, seed: tuple[float, float] | None
) -> np.ndarray:
    """The 4-connected region of constant Type II sign containing ``seed`` (or the largest one),
    from the Type II index grid ``det`` (ny, nx), NaN outside the workspace."""
    sign = np.where(np.isnan(det), 0, np.sign(np.nan_to_num(det))).astype(np.int8)
    labels = np.empty(det.shape, dtype=np.int64)
    count = label_kernel(sign, labels)
    if count == 0:
        return np.zeros(det.shape, dtype=bool)
    if seed is None:
        sizes = np.bincount(labels.ravel(), minlength=count + 1)
        sizes[0] = 0
        return np.asarray(labels == int(np.argmax(sizes)))
    if not all(math.isfinite(v) for v in seed):
        raise NonFiniteInputError("seed")
    j = int(np.argmin(np.abs(x - seed[0])))
    i = int(np.argmin(np.abs(y - seed[1])))
    if labels[i, j] == 0:
        raise InputError(
            f"workspace seed ({seed[0] * 1e3:.3f}, {seed[1] * 1e3:.3f}) mm is outside the "
            "working mode's singularity-free workspace"
        )
    return np.asarray(labels == labels[i, j])


class OrientationStack(NamedTuple):
    """Constant-orientation workspaces over many orientations (the orientation workspace)."""

    alphas: np.ndarray
    """Orientations, shape (K,), in [rad]."""
    x: np.ndarray
    """Grid abscissae, shape (nx,), in [m]."""
    y: np.ndarray
    """Grid ordinates, shape (ny,), in [m]."""
    step: float
    """Grid step, in [m]."""
    masks: np.ndarray
    """Reachability, shape (K, ny, nx), bool."""

    @property
    def areas_mm2(self) -> np.ndarray:
        """Area of each constant-orientation workspace, shape (K,), in [mm^2]."""
        return np.asarray(self.masks.sum(axis=(1, 2)) * self.step**2 * 1e6)

    @property
    def total(self) -> np.ndarray:
        """Centres reachable with at least one orientation, shape (ny, nx), bool."""
        return np.asarray(self.masks.any(axis=0))

    @property
    def dexterous(self) -> np.ndarray:
        """Centres reachable with every orientation of the stack, shape (ny, nx), bool."""
        return np.asarray(self.masks.all(axis=0))


def orientation_stack(
    alphas: np.ndarray,
    geometry: ParallelGeometry = _DEFAULT_GEOMETRY,
    *,
    step: float = 1e-3,
    x_range: tuple[float, float] = REPORT_X_RANGE,
    y_range: tuple[float, float] = REPORT_Y_RANGE,
) -> OrientationStack:
    """Constant-orientation workspaces at each of ``alphas`` (K,) in [rad] on one grid."""
    from lynxplan import guards

    alphas = np.atleast_1d(guards.angles("alphas", alphas))
    x, y = grid_axes(step, x_range, y_range)
    guards.check_size("orientation workspace grid points", alphas.size * x.size * y.size, 1.0)
    return OrientationStack(alphas, x, y, step, reachable_stack(alphas, x, y, geometry))
