"""Path shortcutting and smoothing, compiled with numba; every change is re-validated.

Three passes over a piecewise-linear joint path, all with the planner's validity checker:

1. *Greedy vertex shortcuts*: from the start, each kept waypoint is joined to the farthest
   later waypoint it sees directly (one quick midpoint test, then the certified edge), so the
   random cuts start from a path with few corners.
2. *Partial shortcutting* (Geraerts & Overmars 2007): pick two random points of the path by arc
   length (anywhere on its segments, not only at waypoints); if the straight edge between them
   is certified free (conservative advancement), it replaces the part of the path between them.
   Cutting between interior points rounds corners off progressively, so this pass also smooths
   the path towards the taut one; each accepted cut shortens the path (triangle inequality).
3. *Vertex pruning*: a waypoint whose two neighbours see each other is removed.

The parts of the old path kept around a cut are pieces of certified edges, and the cut itself is
certified before it is accepted: the path stays valid after every change ("verify after every
shortcut" — pyroboplan's ``shortcut_path`` does not, and returns paths through obstacles).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from lynxplan.planning import rng as _rng
from lynxplan.planning.edge_walk import edge_is_free
from lynxplan.planning.validity import ValidityChecker, point_is_clear

#: Shortcut attempts by default.
DEFAULT_SHORTCUT_ITERATIONS = 60
#: Random cuts stop after this many attempts in a row that changed nothing.
DEFAULT_SHORTCUT_PATIENCE = 10
#: Points closer than this in joint space are merged, in [rad].
_MERGE_DISTANCE = 1e-9


@numba.njit(cache=True)
def _point_at(
    path: np.ndarray, cumulative: np.ndarray, count: int, u: float, out: np.ndarray
) -> int:
    """The point at arc length u into out (nq,); returns its segment index."""
    segment = 0
    while segment < count - 2 and cumulative[segment + 1] <= u:
        segment += 1
    length = cumulative[segment + 1] - cumulative[segment]
    s = 0.0 if length <= 0.0 else (u - cumulative[segment]) / length
    s = min(max(s, 0.0), 1.0)
    for j in range(path.shape[1]):
        out[j] = path[segment, j] + s * (path[segment + 1, j] - path[segment, j])
    return segment


@numba.njit(cache=True)
def _distance(a: np.ndarray, b: np.ndarray) -> float:
    total = 0.0
    for j in range(a.shape[0]):
        total += (a[j] - b[j]) ** 2
    return float(np.sqrt(total))


@numba.njit(cache=True)
def _greedy(path: np.ndarray, count: int, model: Any, scratch: Any, clearance: float) -> int:
    """Vertex shortcuts, farthest first: from each kept waypoint, the farthest later waypoint
    it sees directly becomes the next one (in place on path[:count]); returns the new count."""
    kept = 0
    i = 0
    while i < count - 1:
        j = count - 1
        while j > i + 1:
            if point_is_clear(path[i], path[j], 0.5, model, scratch, clearance) and edge_is_free(
                path[i], path[j], model, scratch, clearance
            ):
                break
            j -= 1
        kept += 1
        path[kept] = path[j]
        i = j
    # path[0..kept] now holds the kept waypoints (later ones were copied down in order).
    return kept + 1


@numba.njit(cache=True)
def shortcut_kernel(
    path: np.ndarray,
    count: int,
    iterations: int,
    state: np.ndarray,
    model: Any,
    scratch: Any,
    clearance: float,
    work: np.ndarray,
    patience: int,
    greedy: bool,
) -> int:
    """Greedy vertex shortcuts (if ``greedy``), partial shortcuts then vertex pruning, in place on
    path[:count]; returns the new count.

    path: (capacity, nq) with capacity >= count + 2 * iterations; work: same shape. The cuts stop
    early after ``patience`` attempts in a row that changed nothing.
    """
    nq = path.shape[1]
    cumulative = np.empty(path.shape[0])
    first = np.empty(nq)
    second = np.empty(nq)
    if greedy:
        count = _greedy(path, count, model, scratch, clearance)
    idle = 0
    for _ in range(iterations):
        if count < 3 or idle >= patience:
            break
        idle += 1
        cumulative[0] = 0.0
        for k in range(1, count):
            cumulative[k] = cumulative[k - 1] + _distance(path[k - 1], path[k])
        total = cumulative[count - 1]
        u1 = _rng.uniform(state) * total
        u2 = _rng.uniform(state) * total
        if u1 > u2:
            u1, u2 = u2, u1
        i1 = _point_at(path, cumulative, count, u1, first)
        i2 = _point_at(path, cumulative, count, u2, second)
        if i1 == i2:
            continue
        if not point_is_clear(first, second, 0.5, model, scratch, clearance) or (
            not edge_is_free(first, second, model, scratch, clearance)
        ):
            continue
        idle = 0
        # New path: path[0..i1], first, second, path[i2+1..count-1].
        size = 0
        for k in range(i1 + 1):
            work[size] = path[k]
            size += 1
        if _distance(first, work[size - 1]) > _MERGE_DISTANCE:
            work[size] = first
            size += 1
        if _distance(second, path[i2 + 1]) > _MERGE_DISTANCE:
            work[size] = second
            size += 1
        for k in range(i2 + 1, count):
            work[size] = path[k]
            size += 1
        for k in range(size):
            path[k] = work[k]
        count = size
    k = 1
    while k < count - 1:
        if edge_is_free(path[k - 1], path[k + 1], model, scratch, clearance):
            for m in range(k, count - 1):
                path[m] = path[m + 1]
            count -= 1
        else:
            k += 1
    return count


def merge_collinear(path: np.ndarray) -> np.ndarray:
    """The path without waypoints that lie on the straight line of their neighbours (RRT-Connect
    adds one every step along a connection): the same straight segments, fewer waypoints."""
    keep = np.empty(len(path), dtype=np.int64)
    merged: np.ndarray = path[keep[: _collinear_kernel(path, keep)]]
    return merged


@numba.njit(cache=True)
def _collinear_kernel(path: np.ndarray, keep: np.ndarray) -> int:
    """Indices of the waypoints to keep -> keep[:count]; returns count."""
    count = 1
    keep[0] = 0
    nq = path.shape[1]
    for k in range(1, path.shape[0] - 1):
        last = keep[count - 1]
        norm_before = norm_after = 0.0
        for j in range(nq):
            norm_before += (path[k, j] - path[last, j]) ** 2
            norm_after += (path[k + 1, j] - path[k, j]) ** 2
        norm_before, norm_after = np.sqrt(norm_before), np.sqrt(norm_after)
        if norm_before > 0 and norm_after > 0:
            gap = 0.0
            for j in range(nq):
                before = (path[k, j] - path[last, j]) / norm_before
                after = (path[k + 1, j] - path[k, j]) / norm_after
                gap += (before - after) ** 2
            if np.sqrt(gap) <= 1e-12:
                continue
        keep[count] = k
        count += 1
    keep[count] = path.shape[0] - 1
    return count + 1


def shortcut(
    checker: ValidityChecker,
    path: np.ndarray,
    *,
    seed: int,
    iterations: int = DEFAULT_SHORTCUT_ITERATIONS,
    patience: int = DEFAULT_SHORTCUT_PATIENCE,
    greedy: bool = True,
) -> np.ndarray:
    """Shortcut and smooth a valid path (N, nq), in [rad]; returns a new (M, nq) path.

    Deterministic for a given ``seed``; ``iterations`` random cuts are attempted.
    """
    path = merge_collinear(path)
    count = len(path)
    capacity = count + 2 * iterations + 2
    buffer = np.zeros((capacity, path.shape[1]))
    buffer[:count] = path
    work = np.zeros_like(buffer)
    # A stream of its own: the planner's draws and the shortcutter's never overlap.
    state = _rng.seed_state(seed ^ 0x5DEECE66D)
    count = shortcut_kernel(
        buffer,
        count,
        iterations,
        state,
        checker.model,
        checker.scratch,
        checker.clearance,
        work,
        patience,
        greedy,
    )
    result: np.ndarray = buffer[:count].copy()
    return result
