"""Path shortcutting and smoothing, compiled with numba; every change is certified.

Five passes over a piecewise-linear joint path, all with the planner's validity checker:

1. *Greedy vertex shortcuts*: from the start, each kept waypoint is joined to the farthest
   later waypoint it sees directly (one quick midpoint test, then the certified edge), so the
   random cuts start from a path with few corners.
2. *Goal switch* (goal sets only: the IK branches or rolls of a pose goal): the end moves to
   another goal configuration when that shortens the path; the offset between the goals is
   blended in along the arc length, so a goal that differs in one joint (a roll) turns that
   joint during the whole motion instead of at the end.
3. *One-joint straightening*: a *partial* cut (Geraerts & Overmars 2007) moves one joint
   linearly in the arc length between two points of the path while the others keep their
   motion; it is tried for every joint over the whole path, the most wandering joint first
   (:data:`FLATTEN_LEVELS` > 1: then over its halves, ...), and kept when it gains at least
   :data:`FLATTEN_MIN_GAIN` of the path's length. RRT-Connect's random samples make joints
   that matter little for collisions (a wrist roll) wander, and a straight cut of all joints
   rarely removes that where the others must go around an obstacle: most of the length the
   random cuts would take many tries to remove goes here in one try per joint.
4. *Random shortcuts* between two random points of the path by arc length (anywhere on its
   segments, not only at waypoints): a *full* cut, the straight edge between the points, or
   (a fraction ``partial`` of the attempts, none by default) a partial cut of one joint drawn in
   proportion to its excess motion (total variation beyond its net displacement). A full cut
   that would gain less than :data:`FULL_MIN_GAIN` of the path's length is not certified and
   changes nothing. The cuts stop after ``patience`` attempts in a row that changed nothing.
5. *Vertex shortcuts* again (as 1.): the cuts leave corners on the old path's segments, and
   most of them see past their neighbours.

A cut is kept when it shortens the path (a random full cut by at least :data:`FULL_MIN_GAIN`
of its length, a random partial cut by at least :data:`MIN_GAIN`) and every new edge is
certified. The parts of the old path kept around a cut are pieces of
certified edges: the path stays valid after every change ("verify after every shortcut" —
pyroboplan's ``shortcut_path`` does not, and returns paths through obstacles).

The input path's edges must be certified by the same checker (RRT-Connect's are): a partial
cut or a goal switch changes some joints only, and the pairs that none of them moves keep the
distances they had on the path's edges (:func:`lynxplan.planning.edge_walk.edge_walk`'s
``moved``), so only the others are walked again. (Waypoints closer than 1e-9 rad are merged:
the kept edges are the certified ones to that tolerance, about 1e-9 m at the arm's reach.)
"""

from __future__ import annotations

from typing import Any, NamedTuple

import numba
import numpy as np

from lynxplan._arrays import kernel_input
from lynxplan.planning import rng as _rng
from lynxplan.planning.cuts import (
    MIN_GAIN,
    distance,
    full_cut,
    greedy_shortcuts,
    partial_cut,
    segments_free,
    wandering_joint,
)
from lynxplan.planning.edge_walk import joint_bit
from lynxplan.planning.kernel_model import njit_refcounted
from lynxplan.planning.motion import copy_row
from lynxplan.planning.validity import ValidityChecker

#: Shortcut attempts by default.
DEFAULT_SHORTCUT_ITERATIONS = 60
#: Random cuts stop after this many attempts in a row that changed nothing.
DEFAULT_SHORTCUT_PATIENCE = 12
#: A random full cut must shorten the path by at least this fraction of its length; a cut that
#: would gain less is not certified (without this, a quarter to a third of the certified cuts
#: gained < 0.1 %, each at the cost of an edge walk of every pair). With the patience raised from
#: 7 to 12 (a skipped cut counts as an attempt that changed nothing), paths as short as before in
#: less time: AL5 suite, 60 seeds, total of the median lengths 30.41 -> 30.55 rad (of the means
#: 31.49 -> 31.42), median planning 1.02-1.06 -> 0.90-0.92 ms in three alternating runs. (1 % and
#: a patience of 16: 29.10 rad, ~5 % more time.)
FULL_MIN_GAIN = 0.015
#: Fraction of the random attempts that are partial (one-joint) shortcuts. None by default:
#: after the one-joint straightening, full cuts with a little more patience give paths as short
#: (AL5 suite, 20 seeds: total of the median lengths 31.22 rad against 31.16 with half of the
#: attempts partial and a patience of 5) in less time (the shortcut stage ~60 us less at the
#: median): a partial cut certifies every segment it spans, a full cut one edge.
DEFAULT_PARTIAL_FRACTION = 0.0
#: Levels of the one-joint straightening pass (:func:`_flatten`): whole path, halves, ...
FLATTEN_LEVELS = 1
#: The one-joint straightening keeps a cut only when it shortens the path by at least this
#: fraction of its length: most of its cuts that gain less are of joints that carry the arm
#: around an obstacle (a shoulder), whose certification costs as much as a useful one.
FLATTEN_MIN_GAIN = 0.02


@numba.njit(cache=True)
def _flatten(path: np.ndarray, count: int, levels: int, check: Any, rows: Any) -> int:
    """Partial shortcuts of each joint over the whole path, then over its halves, ... (``levels``
    levels: 2^level equal parts of the arc length at level ``level``), in place on
    path[:count]; returns the new count. A joint that wanders over the whole path (a wrist roll
    that turns away and back) is straightened in one try instead of many random ones. The joints
    go in order of their motion beyond their net displacement, largest first (the largest gains
    first; the joints tried later then move less)."""
    nq = path.shape[1]
    cumulative = rows[0]
    excess = np.empty(nq)  # each joint's motion beyond its net displacement: largest first
    for j in range(nq):
        excess[j] = -abs(path[count - 1, j] - path[0, j])
        for k in range(1, count):
            excess[j] += abs(path[k, j] - path[k - 1, j])
    order = np.argsort(-excess)
    for level in range(levels):
        parts = 2**level
        for joint in order:
            for part in range(parts):
                if count < 3:
                    return count
                cumulative[0] = 0.0
                for k in range(1, count):
                    cumulative[k] = cumulative[k - 1] + distance(path[k - 1], path[k])
                total = cumulative[count - 1]
                cut = (
                    total * part / parts,
                    total * (part + 1) / parts,
                    max(MIN_GAIN, FLATTEN_MIN_GAIN * total),
                )
                size = partial_cut(path, count, cut, joint, check, rows)
                if size > 0:
                    count = size
    return count


@numba.njit(cache=True)
def _switch_goal(
    path: np.ndarray,
    count: int,
    goals: np.ndarray,
    current: int,
    bounds: np.ndarray,
    check: Any,
    piece: np.ndarray,
) -> int:
    """Move the end of path[:count] to another goal configuration when that shortens it: the
    offset to the new goal is blended in along the arc length (every waypoint moves by its
    fraction of the length), so a goal differing in one joint (another roll of an approach
    goal) turns that joint during the whole motion. The nearest goals are tried first; the
    new path must stay within the joint limits bounds (2, nq) and every edge be certified.
    Returns the goal index reached (``current`` if unchanged)."""
    nq = path.shape[1]
    old = 0.0
    for k in range(1, count):
        old += distance(path[k - 1], path[k])
    if old <= 0.0:
        return current
    offsets = np.empty(goals.shape[0])
    for g in range(goals.shape[0]):
        offsets[g] = distance(goals[g], goals[current])
    for g in np.argsort(offsets):
        if g == current:
            continue
        along = 0.0
        inside = True
        piece[0] = path[0]
        for k in range(1, count):
            along += distance(path[k - 1], path[k])
            for j in range(nq):
                value = path[k, j] + along / old * (goals[g, j] - goals[current, j])
                inside = inside and bounds[0, j] <= value <= bounds[1, j]
                piece[k, j] = value
        piece[count - 1] = goals[g]
        length = 0.0
        for k in range(1, count):
            length += distance(piece[k - 1], piece[k])
        if not inside or length >= old - MIN_GAIN:
            continue
        moved = np.int64(0)  # the joints the switch changes; the others keep the path's edges
        for k in range(count):
            for j in range(nq):
                if piece[k, j] != path[k, j]:
                    moved |= joint_bit(j)
        if segments_free(piece, count, check, moved):
            for k in range(count):
                path[k] = piece[k]
            return int(g)
    return current


class ShortcutSettings(NamedTuple):
    """The passes of :func:`shortcut_to_goals`, as the kernel takes them."""

    #: Random cut attempts, at most.
    iterations: int
    #: The random cuts stop after this many attempts in a row that changed nothing.
    patience: int
    #: Greedy vertex shortcuts first.
    greedy: bool
    #: Fraction of the random attempts that are partial (one-joint) cuts.
    partial: float
    #: Levels of the one-joint straightening.
    levels: int


@numba.njit(cache=True)
def shortcut_kernel(
    path: np.ndarray,
    count: int,
    settings: ShortcutSettings,
    state: np.ndarray,
    check: Any,
    ends: tuple[np.ndarray, np.ndarray, np.ndarray],
    work: np.ndarray,
) -> int:
    """Greedy vertex shortcuts (if ``settings.greedy``), goal switch, one-joint straightening
    over ``settings.levels`` levels, random full and partial cuts (a fraction
    ``settings.partial`` of the attempts) then greedy vertex shortcuts, in place on
    path[:count]; returns the new count.

    path: (capacity, nq); a cut adds at most two rows, and none is made once the capacity is
    reached (count + 2 * (iterations + nq * (2^levels - 1)) suffices); work: same shape. The
    cuts stop early after ``settings.patience`` attempts in a row that changed nothing. ends:
    goals (K, nq) goal configurations; goal (1,) the index of the one path[count - 1] is,
    updated; bounds (2, nq) joint limits, in [rad].
    """
    iterations, patience, greedy, partial, levels = settings
    goals, goal, bounds = ends
    nq = path.shape[1]
    cumulative = np.empty(path.shape[0])
    piece = np.empty((path.shape[0] + 2, nq))
    rows = (cumulative, work, piece)
    if greedy:
        count = greedy_shortcuts(path, count, check)
    if goals.shape[0] > 1 and count >= 2:
        goal[0] = _switch_goal(path, count, goals, goal[0], bounds, check, piece)
    count = _flatten(path, count, levels, check, rows)
    idle = 0
    for _ in range(iterations):
        if count < 3 or idle >= patience:
            break
        idle += 1
        cumulative[0] = 0.0
        for k in range(1, count):
            cumulative[k] = cumulative[k - 1] + distance(path[k - 1], path[k])
        total = cumulative[count - 1]
        u1 = _rng.uniform(state) * total
        u2 = _rng.uniform(state) * total
        if u1 > u2:
            u1, u2 = u2, u1
        if _rng.uniform(state) < partial:
            joint = wandering_joint(path, count, _rng.uniform(state))
            if joint < 0:
                continue
            size = partial_cut(path, count, (u1, u2, MIN_GAIN), joint, check, rows)
            if size > 0:
                count, idle = size, 0
            continue
        size = full_cut(path, count, (u1, u2, FULL_MIN_GAIN * total), check, rows)
        if size > 0:
            count, idle = size, 0
    return greedy_shortcuts(path, count, check)


@numba.njit(cache=True)
def _collinear_kernel(path: np.ndarray, keep: np.ndarray) -> int:
    """Indices of the waypoints to keep -> keep[:count]; returns count."""
    if path.shape[0] <= 2:  # nothing between the ends
        for k in range(path.shape[0]):
            keep[k] = k
        return int(path.shape[0])
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
    partial: float = DEFAULT_PARTIAL_FRACTION,
    levels: int = FLATTEN_LEVELS,
) -> np.ndarray:
    """Shortcut and smooth a path (N, nq), in [rad], whose edges the checker certifies (as the
    planner's are); returns a new (M, nq) path with the same ends, certified too.

    Deterministic for a given ``seed``; one-joint straightening over ``levels`` levels (0:
    none), then at most ``iterations`` random cuts, a fraction ``partial`` of them one-joint
    (partial) shortcuts.
    """
    return shortcut_to_goals(
        checker,
        path,
        path[-1:],
        0,
        np.full(path.shape[1], -np.inf),
        np.full(path.shape[1], np.inf),
        seed=seed,
        iterations=iterations,
        patience=patience,
        greedy=greedy,
        partial=partial,
        levels=levels,
    ).path


class ShortcutResult(NamedTuple):
    """A shortcut path and the goal configuration it ends at."""

    #: Waypoints, shape (M, nq), in [rad].
    path: np.ndarray
    #: Index of its last waypoint among the goal configurations.
    goal_index: int


def shortcut_to_goals(
    checker: ValidityChecker,
    path: np.ndarray,
    goals: np.ndarray,
    goal_index: int,
    lower: np.ndarray,
    upper: np.ndarray,
    *,
    seed: int,
    iterations: int = DEFAULT_SHORTCUT_ITERATIONS,
    patience: int = DEFAULT_SHORTCUT_PATIENCE,
    greedy: bool = True,
    partial: float = DEFAULT_PARTIAL_FRACTION,
    levels: int = FLATTEN_LEVELS,
) -> ShortcutResult:
    """:func:`shortcut` of a path (N, nq) that ends at ``goals[goal_index]`` (goals: (K, nq),
    in [rad], every one valid): the path may move its end to another goal configuration when
    that shortens it (another IK branch or roll of a pose goal), within the joint limits
    ``lower``, ``upper`` (nq,), in [rad].
    """
    # A stream of its own: the planner's draws and the shortcutter's never overlap.
    state = _rng.seed_state(seed ^ 0x5DEECE66D)
    shortened, goal = shortcut_path(
        kernel_input(np.asarray(path, dtype=float)),
        kernel_input(np.asarray(goals, dtype=float)),
        int(goal_index),
        kernel_input(np.array([lower, upper], dtype=float)),
        state,
        ShortcutSettings(int(iterations), int(patience), bool(greedy), float(partial), int(levels)),
        checker.data,
    )
    return ShortcutResult(shortened, int(goal))


@njit_refcounted()
def shortcut_path(
    path: np.ndarray,
    goals: np.ndarray,
    goal_index: int,
    bounds: np.ndarray,
    state: np.ndarray,
    settings: ShortcutSettings,
    check: Any,
) -> tuple[np.ndarray, int]:
    """:func:`shortcut_to_goals` in one compiled call (the Python steps around the kernel
    cost more than their work between compiled calls): the path (N, nq) without its collinear
    waypoints (RRT-Connect adds one every step along a connection), copied into work arrays
    with room for every cut, :func:`shortcut_kernel`; returns the new path (M, nq) and the index
    of the goal it ends at. bounds: joint limits (2, nq), in [rad]; state: random state (1,)
    uint64, advanced."""
    keep = np.empty(path.shape[0], dtype=np.int64)
    count = _collinear_kernel(path, keep)
    nq = path.shape[1]
    capacity = count + 2 * (settings.iterations + nq * (2**settings.levels - 1)) + 2
    buffer = np.zeros((capacity, nq))
    for k in range(count):
        copy_row(buffer, k, path, keep[k])
    work = np.zeros_like(buffer)
    goal = np.full(1, goal_index, dtype=np.int64)
    count = shortcut_kernel(buffer, count, settings, state, check, (goals, goal, bounds), work)
    return buffer[:count].copy(), int(goal[0])
