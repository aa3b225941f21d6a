"""Planning test helpers: the problem suite, loaded through the scenario layer, and the
independent dense exact check of a returned trajectory."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from lynxplan.collision import CollisionWorld

SUITE_DIR = Path(__file__).resolve().parents[2] / "scenarios" / "planning"
SUITE = sorted(SUITE_DIR.glob("*.yaml"))
#: The dense check refines the trajectory's samples at least this many times ...
DENSE_REFINEMENT = 10
#: ... and further until no joint moves more than this between two exact checks, in [rad]
#: (OMPL's fine resolution in the issue is 0.005 rad).
DENSE_JOINT_STEP = 0.002
#: Exact distances (coal) are accurate to ~1e-9 m: tolerance of the clearance comparison, [m].
CLEARANCE_TOLERANCE = 1e-7
#: Relative slack of the velocity/acceleration limit checks (floating point only).
LIMIT_RELATIVE_TOLERANCE = 1e-6
#: Joint position limit tolerance, in [rad].
POSITION_TOLERANCE = 1e-9

SLOW = pytest.mark.skipif(
    os.environ.get("LYNXPLAN_SLOW") != "1", reason="slow: set LYNXPLAN_SLOW=1 (or lynxplan bench)"
)


def load_problem(path: Path) -> Any:
    """The planner inputs of a suite file (:class:`lynxplan.scenarios.plan.PlanInputs`)."""
    from lynxplan.scenarios import load_scenario
    from lynxplan.scenarios.plan import plan_inputs

    return plan_inputs(load_scenario(path).scenario)


def dense_min_distance(world: CollisionWorld, q: np.ndarray) -> tuple[float, np.ndarray]:
    """Smallest exact distance over every pair along the sampled motion, densely.

    Each sample interval is split into max(DENSE_REFINEMENT, moves / DENSE_JOINT_STEP) pieces
    (linear in joint space between samples). Pairs are pruned with the collision world's sphere
    lower bounds (an implementation independent of the planner's checker): a pair whose bound
    exceeds the best exact distance at that configuration cannot be the minimum.

    Returns:
        The smallest distance, in [m], and the configuration where it occurs, (nq,).
    """
    steps = np.abs(np.diff(q, axis=0)).max(axis=1)
    pieces = np.maximum(DENSE_REFINEMENT, np.ceil(steps / DENSE_JOINT_STEP)).astype(int)
    dense = [q[:1]]
    for k, count in enumerate(pieces.tolist()):
        s = np.arange(1, count + 1)[:, None] / count
        dense.append(q[k] + s * (q[k + 1] - q[k]))
    config = np.vstack(dense)
    poses = world.primitive_poses(config)
    bounds = world.lower_bounds(poses)
    best, where = np.inf, config[0]
    for n in np.flatnonzero(bounds.min(axis=1) < 0.01).tolist():
        for pair in np.argsort(bounds[n]).tolist():
            if bounds[n, pair] >= min(best, 0.01):
                break
            distance = world.distance(poses[n], pair)
            if distance < best:
                best, where = distance, config[n]
    if not np.isfinite(best):  # nothing within 1 cm: the bound is the answer's floor
        best = float(bounds.min())
    return float(best), where
