"""The planner's validity checker: a fast, conservative state and edge test, compiled with numba.

What it tests
    For every checked pair — primitive/obstacle, and primitive/primitive on non-adjacent links
    (the same pairs as the collision world with ``self_collision=True``: two primitives are
    skipped when they hang on the same joint or on a parent/child pair of joints, the URDF
    adjacency) — a *lower bound* of the Euclidean distance, the one of
    :mod:`lynxplan.planning.pair_bound` (oriented bounding boxes: sphere gap and separating
    axes). A state is valid when every pair's bound exceeds the required ``clearance`` (so the
    exact distance does too). The bounds of all pairs of a state come from one vectorised kernel
    over all 15 axes (:func:`lynxplan.planning.pair_bound.all_pair_bounds`); the scalar
    :func:`lynxplan.planning.pair_bound.pair_bound` (one pair, the edge axes only when the face
    axes leave a small gap) serves single pairs.

Edges
    Conservative advancement along an edge: :mod:`lynxplan.planning.edge_walk`.

The compiled kernels: :mod:`lynxplan.planning.bounds`.

Primitives fixed to the base (joint 0) do not move: their obstacle pairs are checked once,
exactly, by the problem set-up, and left out here.
"""

from __future__ import annotations

import numpy as np

from lynxplan.collision.world import CollisionWorld
from lynxplan.planning.bounds import (
    STALL_DISTANCE,
    state_bounds,
)
from lynxplan.planning.edge_walk import edge_fraction
from lynxplan.planning.kernel_model import CheckData, kernel_model, make_scratch, planner_pairs


class ValidityChecker:
    """Conservative state/edge validity of one robot among fixed obstacles.

    Args:
        world: The collision world (robot primitives + obstacles); its self-collision setting
            is ignored: self pairs are always checked.
        clearance: Required distance between the robot and anything else, in [m].

    Attributes:
        clearance: Required distance, in [m].
        nq: Number of joints.
        pair_names: ``(geometry, other)`` of every checked pair (``self:<geometry>`` for self).
        model: The arrays of the compiled kernels (joints, primitives, pairs, obstacles).
    """

    def __init__(self, world: CollisionWorld, clearance: float) -> None:
        self.clearance = float(clearance)
        self.nq = int(world.model.nq)
        pairs, names = planner_pairs(world)
        self.pair_names = tuple(names)
        self.model = kernel_model(world, pairs)
        self.scratch = make_scratch(self.model)
        #: The model, scratch and clearance, as the planner's kernels take them.
        self.data = CheckData(self.model, self.scratch, self.clearance)

    def pair_bounds(self, q: np.ndarray) -> np.ndarray:
        """Lower bound of every pair's distance. q: shape (nq,), in [rad] -> (P,), in [m]."""
        config = np.ascontiguousarray(q, dtype=float)
        bounds = np.empty(len(self.pair_names))
        state_bounds(config, self.model, self.scratch, bounds)
        return bounds

    def is_valid(self, q: np.ndarray) -> bool:
        """Whether every pair's bound exceeds the clearance at q (shape (nq,), in [rad])."""
        return bool(self.pair_bounds(q).min(initial=np.inf) > self.clearance + STALL_DISTANCE)

    def edge_fraction(self, q_a: np.ndarray, q_b: np.ndarray) -> float:
        """Largest s in [0, 1] such that the edge from q_a to q_a + s (q_b - q_a) is certified.

        q_a, q_b: shape (nq,), in [rad]. Returns -1 if q_a itself is not valid.
        """
        return float(
            edge_fraction(
                np.ascontiguousarray(q_a, dtype=float),
                np.ascontiguousarray(q_b, dtype=float),
                self.model,
                self.scratch,
                self.clearance,
            )
        )
