"""The cuts of the path simplifier (:mod:`lynxplan.planning.shortcut`), compiled with numba.

A *full* cut replaces the path between two points (by arc length) with the straight edge between
them; a *partial* cut (Geraerts & Overmars 2007) moves one joint linearly in the arc length
between them while the others keep their motion. A cut is applied, in place, only when it
shortens the path enough and every new edge is certified by the planner's checker; the parts of
the old path kept around it are pieces of certified edges, so the path stays valid after every
change.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from lynxplan.planning.bounds import PROBES, point_is_clear, probes_are_clear, state_bounds
from lynxplan.planning.edge_walk import (
    ALL_JOINTS,
    edge_fraction_from,
    edge_is_free_after_probes,
    joint_bit,
)
from lynxplan.planning.kernel_model import njit_no_refcount, njit_refcounted
from lynxplan.planning.motion import copy_row

#: Joints that move less than this beyond their net displacement get no partial shortcut, [rad].
WANDER_TOLERANCE = 1e-3
#: A partial shortcut must shorten the path by at least this, in [rad].
MIN_GAIN = 1e-3
#: Points closer than this in joint space are merged, in [rad].
MERGE_DISTANCE = 1e-9


@njit_no_refcount()
def point_at(
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


@njit_no_refcount()
def distance(a: np.ndarray, b: np.ndarray) -> float:
    total = 0.0
    for j in range(a.shape[0]):
        total += (a[j] - b[j]) ** 2
    return float(np.sqrt(total))


@njit_refcounted()  # returns a view: counted even when called from an uncounted kernel
def slacks_at(
    points: np.ndarray, k: int, slacks: np.ndarray, known: np.ndarray, check: Any
) -> np.ndarray:
    """Every pair's slack at points[k] (P,), in [m], computed on first use (slacks: (N, P),
    known: (N,) flags)."""
    model, scratch, clearance = check
    if not known[k]:
        state_bounds(points[k], model, scratch, slacks[k])
        for p in range(slacks.shape[1]):
            slacks[k, p] -= clearance
        known[k] = True
    result: np.ndarray = slacks[k]
    return result


@numba.njit(cache=True)
def greedy_shortcuts(path: np.ndarray, count: int, check: Any) -> int:
    """Vertex shortcuts, farthest first: from each kept waypoint, the farthest later waypoint
    it sees directly becomes the next one (in place on path[:count]); returns the new count.
    Each waypoint's pair slacks are computed once (the edge walks start and end there)."""
    model, scratch, clearance = check
    slacks = np.empty((count, model.pairs.shape[0]))
    known = np.zeros(count, dtype=np.bool_)
    kept = 0
    i = np.int64(0)  # not a literal 0: numba would compile slacks_at for it as well
    while i < count - 1:
        j = count - 1
        while j > i + 1:
            if probes_are_clear(path[i], path[j], model, scratch, clearance):
                start = slacks_at(path, i, slacks, known, check)
                end = slacks_at(path, j, slacks, known, check)
                reached = edge_fraction_from(
                    path[i],
                    path[j],
                    (start, end),
                    np.int64(PROBES),
                    model,
                    scratch,
                    clearance,
                    np.int64(ALL_JOINTS),
                )
                if reached >= 1.0:
                    break
            j -= 1
        kept += 1
        path[kept] = path[j]  # kept <= i < j: the rows still to read keep their indices
        i = j
    # path[0..kept] now holds the kept waypoints (later ones were copied down in order).
    return kept + 1


@numba.njit(cache=True)
def segments_free(points: np.ndarray, size: int, check: Any, moved: int) -> bool:
    """Whether every straight edge between consecutive rows of points[:size] is certified
    (quick midpoint tests of all edges first: a blocked edge is usually blocked there; their
    bounds then serve the walks, and so do the points' slacks, each computed once).

    moved: the joints (bit j: joint j) in which the edges differ from pieces of certified
    edges (the path's, before a partial cut or a goal switch changed those joints), or
    ALL_JOINTS (:func:`lynxplan.planning.edge_walk.edge_walk`)."""
    model, scratch, clearance = check
    pairs = model.pairs.shape[0]
    middle = np.empty((max(size - 1, 0), pairs))
    for k in range(size - 1):
        if not point_is_clear(
            points[k], points[k + 1], 0.5, model, scratch, clearance, np.int64(0)
        ):
            return False
        middle[k] = scratch.grid[0]
    slacks = np.empty((size, pairs))
    known = np.zeros(size, dtype=np.bool_)
    for k in range(size - 1):
        start = slacks_at(points, k, slacks, known, check)
        end = slacks_at(points, k + 1, slacks, known, check)
        scratch.grid[0] = middle[k]
        scratch.grid_at[0] = 0.5
        reached = edge_fraction_from(
            points[k], points[k + 1], (start, end), np.int64(1), model, scratch, clearance, moved
        )
        if reached < 1.0:
            return False
    return True


@njit_no_refcount()
def splice(
    path: np.ndarray,
    count: int,
    i1: int,
    i2: int,
    points: np.ndarray,
    size: int,
    work: np.ndarray,
) -> int:
    """path[:count] with its waypoints i1+1..i2 replaced by points[:size], in place (work:
    scratch rows); an end point within MERGE_DISTANCE of its neighbour (path[i1], path[i2+1])
    is left out. Returns the new count."""
    total = 0
    for k in range(i1 + 1):
        copy_row(work, total, path, k)
        total += 1
    start = 0 if distance(points[0], path[i1]) > MERGE_DISTANCE else 1
    stop = size if distance(points[size - 1], path[i2 + 1]) > MERGE_DISTANCE else size - 1
    for k in range(start, stop):
        copy_row(work, total, points, k)
        total += 1
    for k in range(i2 + 1, count):
        copy_row(work, total, path, k)
        total += 1
    for k in range(total):
        copy_row(path, k, work, k)
    return total


@njit_no_refcount()
def full_cut(
    path: np.ndarray, count: int, cut: tuple[float, float, float], check: Any, rows: Any
) -> int:
    """Full shortcut: the straight edge between the points at arc lengths u1 < u2 (cut = (u1,
    u2, gain)) replaces the path between them when it shortens the path by at least ``gain``
    [rad] and is certified (in place); returns the new count, or 0 when nothing changed."""
    model, scratch, clearance = check
    u1, u2, gain = cut
    cumulative, work, piece = rows
    first, second = piece[0], piece[1]
    i1 = point_at(path, cumulative, count, u1, first)
    i2 = point_at(path, cumulative, count, u2, second)
    if i1 == i2 or count + 2 > path.shape[0] or distance(first, second) > (u2 - u1) - gain:
        return 0
    if not probes_are_clear(first, second, model, scratch, clearance) or (
        not edge_is_free_after_probes(first, second, model, scratch, clearance)
    ):
        return 0
    # path[..i1], first, second, path[i2+1..] (np.int64: no extra compile for a literal 2)
    return splice(path, count, i1, i2, piece, np.int64(2), work)


@numba.njit(cache=True)
def wandering_joint(path: np.ndarray, count: int, r: float) -> int:
    """A joint drawn with probability proportional to its excess motion along path[:count]
    (total variation minus net displacement, in [rad]; r uniform in [0, 1)), or -1 when no
    joint moves more than :data:`WANDER_TOLERANCE` beyond its net displacement."""
    nq: int = path.shape[1]
    excess = np.empty(nq)
    total = 0.0
    for j in range(nq):
        variation = 0.0
        for k in range(1, count):
            variation += abs(path[k, j] - path[k - 1, j])
        excess[j] = max(0.0, variation - abs(path[count - 1, j] - path[0, j]) - WANDER_TOLERANCE)
        total += excess[j]
    if total <= 0.0:
        return -1
    target = r * total
    for j in range(nq):
        target -= excess[j]
        if target < 0.0:
            return j
    return nq - 1


@numba.njit(cache=True)
def partial_cut(
    path: np.ndarray,
    count: int,
    cut: tuple[float, float, float],
    joint: int,
    check: Any,
    rows: Any,
) -> int:
    """Partial shortcut of one joint (Geraerts & Overmars 2007): between the points at arc
    lengths u1 < u2 (cut = (u1, u2, gain)), that joint moves linearly in the arc length while the
    others keep their motion. Applied in place when it shortens the path by at least ``gain``
    [rad] and every new edge is certified; returns the new count, or 0 when nothing changed."""
    u1, u2, gain = cut
    cumulative, work, piece = rows
    first, second = piece[0], piece[1]
    i1 = point_at(path, cumulative, count, u1, first)
    i2 = point_at(path, cumulative, count, u2, second)
    if i1 == i2 or count + 2 > path.shape[0]:
        return 0
    # piece: first, waypoints i1+1..i2 with the joint re-interpolated, second.
    size = 1
    for k in range(i1 + 1, i2 + 1):
        piece[size + 1, :] = path[k]
        w = (cumulative[k] - u1) / (u2 - u1)
        piece[size + 1, joint] = first[joint] + w * (second[joint] - first[joint])
        size += 1
    # rows: 0 first, 2..size waypoints, then second; move second behind them
    piece[size + 1, :] = second
    piece[1, :] = piece[0]
    points = piece[1 : size + 2]
    size += 1
    length = 0.0
    for k in range(size - 1):
        length += distance(points[k], points[k + 1])
    if length >= (u2 - u1) - gain:
        return 0
    # In the other joints, each new edge runs along a piece of an edge of the path.
    if not segments_free(points, size, check, joint_bit(joint)):
        return 0
    return splice(path, count, i1, i2, points, size, work)
