"""Bidirectional RRT-Connect (Kuffner & LaValle 2000) with goal biasing, compiled with numba.

Two trees: tree 0 rooted at the start, tree 1 rooted at every goal configuration (a pose goal
gives one root per collision-free IK branch). Each iteration, in the compiled kernel:

1. sample a configuration uniformly in the joint limits (with probability ``goal_bias``, a root
   of the other tree instead);
2. *extend* the active tree: from its nearest node (linear scan, Euclidean) one step of at most
   ``step`` [rad] towards the sample; the edge is certified by the validity checker's
   conservative advancement (:func:`lynxplan.planning.edge_walk.edge_fraction`), after a
   quick test of its midpoint (a blocked extension is usually blocked there);
3. *connect* the other tree to the new node: the straight edge from its nearest node is walked
   as far as it is certified; nodes are added every ``step`` along it (the points there are
   tested first, and the walk covers the edge only up to the last clear one); reaching the new
   node joins the trees;
4. swap the trees.

A node's pair slacks (bound minus clearance, the start of every edge walk from it) are computed
once, when the node is added by an extension (its state test gives them) or on first use.

The planner knows nothing about the robot: only the joint box, the kernel arrays of the checker
and a random state (:mod:`lynxplan.planning.rng`). The caller runs the kernel in chunks of
iterations and checks its time limit between chunks; the state lives in arrays, so the result
depends on the seed only.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, NamedTuple

import numba
import numpy as np

from lynxplan._jit import check_python_plan, compile_before_timing
from lynxplan.exceptions import PlanningFailed
from lynxplan.planning import rng as _rng
from lynxplan.planning.bounds import point_is_clear, probes_are_clear, state_bounds
from lynxplan.planning.edge_walk import (
    ALL_JOINTS,
    edge_fraction_from,
    edge_is_free_after_probes,
    state_slacks,
)
from lynxplan.planning.kernel_model import GRID_POINTS, njit_no_refcount, njit_refcounted
from lynxplan.planning.space import draw_sample, nearest, steer
from lynxplan.planning.validity import ValidityChecker

#: Kernel status codes.
RUNNING, SOLVED, NODE_LIMIT = 0, 1, 2
#: Iterations per kernel call between two time-limit checks.
CHUNK_ITERATIONS = 256


@dataclass(frozen=True)
class RrtConnectSettings:
    """Settings of RRT-Connect.

    Attributes:
        step: Longest extension towards a sample, Euclidean in joint space, in [rad].
        goal_bias: Probability of sampling the other tree's root instead of a random state.
        max_nodes: Node budget of each tree.
    """

    # Measured on the AL5 suite (20 seeds): against 0.6 rad / 0.1, a third less search and
    # shortcut work at the mean for paths as short (the one-joint straightening removes the
    # wander of longer random steps).
    step: float = 1.5
    goal_bias: float = 0.05
    max_nodes: int = 20000


@dataclass(frozen=True)
class RrtConnectResult:
    """A path found by RRT-Connect.

    Attributes:
        path: Waypoints from the start to one goal, shape (N, nq), in [rad].
        goal_index: Which goal configuration (root of tree 1) the path ends at.
        nodes: Nodes created in both trees.
        iterations: Sampling iterations made.
        elapsed: Time spent, in [s].
    """

    path: np.ndarray
    goal_index: int
    nodes: int
    iterations: int
    elapsed: float


@numba.njit(cache=True)
def _add(
    nodes: np.ndarray,
    parents: np.ndarray,
    counts: np.ndarray,
    tree: int,
    q: np.ndarray,
    parent: int,
) -> int:
    index = counts[tree]
    nodes[tree, index, :] = q
    parents[tree, index] = parent
    counts[tree] = index + 1
    return int(index)


class Trees(NamedTuple):
    """The two trees of RRT-Connect, as the kernels take them (only the first counts[tree] rows
    of a tree are read)."""

    #: Nodes, (2, M, nq), in [rad].
    nodes: np.ndarray
    #: Parent of each node, (2, M) (a root's: -1).
    parents: np.ndarray
    #: The pairs' slacks at each node once known, (2, M, P), in [m].
    slacks: np.ndarray
    #: 1 where a node's slacks are known, (2, M).
    known: np.ndarray
    #: Nodes per tree, (2,).
    counts: np.ndarray
    #: Roots per tree, (2,).
    roots: np.ndarray
    #: [active tree, joint node of tree 0, joint node of tree 1, iterations done], (4,).
    meta: np.ndarray

    def grown(self, capacity: int) -> Trees:
        """The same trees in arrays of ``capacity`` rows."""
        nq, pairs = self.nodes.shape[2], self.slacks.shape[2]
        rows = self.nodes.shape[1]
        nodes, parents = np.empty((2, capacity, nq)), np.empty((2, capacity), dtype=np.int64)
        slacks, known = np.empty((2, capacity, pairs)), np.zeros((2, capacity), dtype=np.int8)
        nodes[:, :rows], parents[:, :rows] = self.nodes, self.parents
        slacks[:, :rows], known[:, :rows] = self.slacks, self.known
        return Trees(nodes, parents, slacks, known, self.counts, self.roots, self.meta)


class Search(NamedTuple):
    """The sampling of RRT-Connect: joint limits lower, upper (nq,), in [rad], the extension
    step [rad] and the goal bias."""

    lower: np.ndarray
    upper: np.ndarray
    step: float
    goal_bias: float


@njit_refcounted()  # returns a view: counted even when called from an uncounted kernel
def _slacks(trees: Trees, tree: int, index: int, check: Any) -> np.ndarray:
    """The pairs' slacks at a tree node (P,), computed on first use (a node's slacks never
    change)."""
    model, scratch, clearance = check
    if trees.known[tree, index] == 0:
        out = trees.slacks[tree, index]
        state_bounds(trees.nodes[tree, index], model, scratch, out)
        for p in range(out.shape[0]):
            out[p] -= clearance
        trees.known[tree, index] = 1
    result: np.ndarray = trees.slacks[tree, index]
    return result


@numba.njit(cache=True)
def _extends(
    trees: Trees, tree: int, near: int, new: np.ndarray, fresh: np.ndarray, check: Any
) -> bool:
    """Whether the edge from node ``near`` of ``tree`` to ``new`` (nq,; its slacks: fresh
    (P,)) is certified whole (a blocked extension is usually blocked at its midpoint: that
    quick test first; its bounds then serve the walk)."""
    model, scratch, clearance = check
    base = trees.nodes[tree, near]
    if not point_is_clear(base, new, 0.5, model, scratch, clearance, np.int64(0)):
        return False
    start = _slacks(trees, tree, near, check)
    reached = edge_fraction_from(
        base, new, (start, fresh), np.int64(1), model, scratch, clearance, np.int64(ALL_JOINTS)
    )
    return bool(reached >= 1.0)


@numba.njit(cache=True)
def _connect(
    base: np.ndarray,
    new: np.ndarray,
    pieces: int,
    slacks: tuple[np.ndarray, np.ndarray],
    check: Any,
    ahead: np.ndarray,
) -> float:
    """How far the straight edge from ``base`` to ``new`` (nq,; their slacks: slacks, two (P,)
    arrays) is certified, as a fraction; only the multiples of 1 / pieces below it matter (the
    connection adds nodes there).

    The piece points are tested first (quick state tests, in order): the walk then covers the
    edge only up to the last point that passes, is skipped when the first one fails, and uses
    the passed points' bounds as its grid (up to :data:`GRID_POINTS` of them). ahead: (2, P)
    work rows.
    """
    model, scratch, clearance = check
    start = slacks[0]
    clear = pieces
    wide = pieces - 1 > GRID_POINTS  # more points than grid rows: no grid
    for k in range(1, pieces):
        if not point_is_clear(
            base, new, k / pieces, model, scratch, clearance, 0 if wide else k - 1
        ):
            clear = k - 1
            break
        if wide:
            ahead[0] = scratch.grid[0]
    if clear == 0:
        return 0.0
    if clear == pieces:
        points = 0 if wide else pieces - 1
        return edge_fraction_from(
            base, new, slacks, points, model, scratch, clearance, np.int64(ALL_JOINTS)
        )
    fraction = clear / pieces
    target = base + fraction * (new - base)
    for p in range(ahead.shape[1]):
        ahead[1, p] = (ahead[0, p] if wide else scratch.grid[clear - 1, p]) - clearance
    # the grid points before the last one that passed, as fractions of the shorter edge
    points = 0 if wide else clear - 1
    for k in range(points):
        scratch.grid_at[k] = (k + 1) / clear
    reached = edge_fraction_from(
        base, target, (start, ahead[1]), points, model, scratch, clearance, np.int64(ALL_JOINTS)
    )
    return fraction * reached if reached < 1.0 else fraction


@numba.njit(cache=True)
def rrt_connect_kernel(
    search: Search, check: Any, trees: Trees, state: np.ndarray, iterations: int
) -> int:
    """Run up to ``iterations`` RRT-Connect iterations; returns RUNNING, SOLVED or NODE_LIMIT.

    state: random state (1,) uint64.
    """
    model, scratch, clearance = check
    lower, upper, step, goal_bias = search
    nodes, parents, slacks, known, counts, roots, meta = trees
    nq = lower.shape[0]
    capacity = nodes.shape[1]
    sample = np.empty(nq)
    new = np.empty(nq)
    fresh = np.empty(slacks.shape[2])
    ahead = np.empty((2, slacks.shape[2]))
    for _ in range(iterations):
        a = meta[0]
        b = 1 - a
        meta[3] += 1
        if counts[0] + 2 >= capacity or counts[1] + 2 >= capacity:
            return NODE_LIMIT
        draw_sample(lower, upper, goal_bias, nodes[b], roots[b], state, sample)
        near = nearest(nodes[a], counts[a], sample)
        if not steer(nodes[a, near], sample, step, new):
            meta[0] = b
            continue
        if not state_slacks(new, model, scratch, clearance, fresh):
            meta[0] = b
            continue
        if not _extends(trees, a, near, new, fresh, check):
            meta[0] = b
            continue
        added = _add(nodes, parents, counts, a, new, near)
        slacks[a, added, :] = fresh
        known[a, added] = 1
        # Connect tree b to the new node as far as the straight edge is certified.
        other = nearest(nodes[b], counts[b], new)
        base = nodes[b, other].copy()
        length = 0.0
        for j in range(nq):
            length += (new[j] - base[j]) ** 2
        length = math.sqrt(length)
        start = _slacks(trees, b, other, check)
        pieces = max(1, math.ceil(length / step))
        reached = _connect(base, new, pieces, (start, fresh), check, ahead)
        parent = other
        for k in range(1, pieces + 1):
            s = k / pieces
            if s > reached:
                break
            if counts[b] + 1 >= capacity:
                return NODE_LIMIT
            for j in range(nq):
                sample[j] = base[j] + s * (new[j] - base[j])
            parent = _add(nodes, parents, counts, b, sample, parent)
        if reached >= 1.0:
            meta[1 + a] = added
            meta[1 + b] = parent
            return SOLVED
        meta[0] = b
    return RUNNING


@njit_no_refcount()
def straight_goal(
    start: np.ndarray, goals: np.ndarray, model: Any, scratch: Any, clearance: float
) -> int:
    """The first goal (K, nq) whose straight edge from start (nq,) is certified, or -1 (a
    blocked edge is usually blocked at a quarter or its midpoint: those quick tests first,
    :func:`lynxplan.planning.bounds.probes_are_clear`)."""
    for k in range(goals.shape[0]):
        if probes_are_clear(
            start, goals[k], model, scratch, clearance
        ) and edge_is_free_after_probes(start, goals[k], model, scratch, clearance):
            return k
    return -1


@njit_refcounted()
def _solution(nodes: np.ndarray, parents: np.ndarray, meta: np.ndarray) -> tuple[np.ndarray, int]:
    """The path through the joined trees: tree 0 from its root to node meta[1], then tree 1
    from node meta[2] to its root (nodes (2, M, nq), parents (2, M), root parent -1), without
    repeated points (the joint nodes coincide); and the tree-1 root it ends at."""
    nq = nodes.shape[2]
    depth = np.zeros(2, dtype=np.int64)
    for tree in range(2):
        index = meta[1 + tree]
        while index >= 0:
            depth[tree] += 1
            index = parents[tree, index]
    path = np.empty((depth[0] + depth[1], nq))
    index = meta[1]
    for k in range(depth[0] - 1, -1, -1):  # tree 0: root first
        path[k] = nodes[0, index]
        index = parents[0, index]
    index, root = meta[2], meta[2]
    for k in range(depth[0], depth[0] + depth[1]):
        path[k] = nodes[1, index]
        root = index
        index = parents[1, index]
    count = 1
    for k in range(1, path.shape[0]):
        gap = 0.0
        for j in range(nq):
            gap += (path[k, j] - path[count - 1, j]) ** 2
        if math.sqrt(gap) > 1e-12:
            path[count] = path[k]
            count += 1
    return path[:count].copy(), int(root)


@njit_refcounted()
def rrt_connect_begin(
    start: np.ndarray,
    goals: np.ndarray,
    capacity: int,
    search: Search,
    check: Any,
    state: np.ndarray,
    iterations: int,
) -> tuple[Any, ...]:
    """The straight edge to a goal, else the trees and their first ``iterations`` iterations,
    in one compiled call (the Python steps they replace cost more than their work between
    compiled calls).

    start: (nq,); goals: (K, nq), the roots of tree 1; capacity: rows of each tree. Returns
    (status, path, goal index, trees); the path (N, nq) and its goal (a root of tree 1) when
    the status is SOLVED, else an empty path and -1.
    """
    model, scratch, clearance = check
    nq, count = start.shape[0], goals.shape[0]
    trees = Trees(
        np.empty((2, capacity, nq)),
        np.empty((2, capacity), dtype=np.int64),  # rows written before they are read
        np.empty((2, capacity, model.pairs.shape[0])),  # filled on first use (known)
        np.zeros((2, capacity), dtype=np.int8),
        np.array([1, count], dtype=np.int64),
        np.array([1, count], dtype=np.int64),
        np.array([0, -1, -1, 0], dtype=np.int64),
    )
    nodes, parents = trees.nodes, trees.parents
    for j in range(nq):
        nodes[0, 0, j] = start[j]
    parents[0, 0] = -1
    for k in range(count):
        for j in range(nq):
            nodes[1, k, j] = goals[k, j]
        parents[1, k] = -1
    k = straight_goal(start, goals, model, scratch, clearance)
    if k >= 0:  # the straight edge first: free space needs no tree
        path = np.empty((2, nq))
        for j in range(nq):
            path[0, j], path[1, j] = start[j], goals[k, j]
        return SOLVED, path, k, trees
    status = rrt_connect_kernel(search, check, trees, state, iterations)
    if status == SOLVED:
        path, goal = _solution(nodes, parents, trees.meta)
        return status, path, goal, trees
    return status, np.empty((0, nq)), -1, trees


#: Nodes each tree has room for at first; the arrays double when a kernel call might fill them.
INITIAL_CAPACITY = 4096


def _room(capacity: int, used: int, per_call: int, limit: int) -> int:
    """Rows each tree needs before a kernel call that may add ``per_call`` nodes to a tree of
    ``used``: ``capacity`` while it suffices, else doubled (at least enough), at most ``limit``."""
    if capacity < limit and used + per_call >= capacity:
        return min(limit, max(2 * capacity, used + per_call + 1))
    return capacity


def rrt_connect(
    checker: ValidityChecker,
    lower: np.ndarray,
    upper: np.ndarray,
    start: np.ndarray,
    goals: np.ndarray,
    *,
    seed: int,
    time_limit: float,
    settings: RrtConnectSettings = RrtConnectSettings(),
) -> RrtConnectResult:
    """Plan from ``start`` (nq,) to any of ``goals`` (K, nq), in [rad].

    The start and every goal must be valid for the checker (the caller checks them first).

    Raises:
        PlanningFailed: the time limit [s] or the node budget was reached first.
    """
    began = time.perf_counter()
    limit = settings.max_nodes + 1
    # Trees grow in blocks (a budget of 10^7 nodes must not reserve gigabytes up front); one
    # kernel call adds at most CHUNK_ITERATIONS * (1 + pieces of the longest connect) nodes.
    per_call = CHUNK_ITERATIONS * (
        2 + math.ceil(float(np.linalg.norm(upper - lower)) / settings.step)
    )
    capacity = _room(min(limit, INITIAL_CAPACITY), len(goals), per_call, limit)
    state = _rng.seed_state(seed)
    search = Search(lower, upper, float(settings.step), float(settings.goal_bias))
    first = (start, goals, capacity, search, checker.data, state, CHUNK_ITERATIONS)
    # the first call in a process: compile (or load) the kernel outside the time limit
    began += compile_before_timing(rrt_connect_begin, first)
    status, path, goal_index, trees = rrt_connect_begin(*first)
    counts, meta = trees.counts, trees.meta
    if status == SOLVED:  # the straight edge to a goal, or found in the first iterations
        return RrtConnectResult(
            path, int(goal_index), int(counts.sum()), int(meta[3]), time.perf_counter() - began
        )

    def arguments(trees: Trees) -> tuple[Any, ...]:
        return (search, checker.data, trees, state, CHUNK_ITERATIONS)

    began += compile_before_timing(rrt_connect_kernel, arguments(trees))
    began += compile_before_timing(_solution, (trees.nodes, trees.parents, meta))
    while status != SOLVED:
        elapsed = time.perf_counter() - began
        check_python_plan(elapsed, time_limit)  # a first plan run as Python: compiled instead
        rows = trees.nodes.shape[1]
        if status == NODE_LIMIT and rows >= limit:
            raise PlanningFailed(
                int(counts.sum()), int(meta[3]), elapsed, f"node limit {settings.max_nodes} reached"
            )
        if status == NODE_LIMIT:  # not the budget: grow, go on
            trees = trees.grown(min(limit, 2 * rows))
        elif elapsed >= time_limit:
            raise PlanningFailed(
                int(counts.sum()), int(meta[3]), elapsed, f"time limit {time_limit:g} s reached"
            )
        capacity = _room(trees.nodes.shape[1], int(counts.max()), per_call, limit)
        if capacity > trees.nodes.shape[1]:
            trees = trees.grown(capacity)
        status = rrt_connect_kernel(*arguments(trees))
    path, goal_index = _solution(trees.nodes, trees.parents, meta)
    return RrtConnectResult(
        path, goal_index, int(counts.sum()), int(meta[3]), time.perf_counter() - began
    )
