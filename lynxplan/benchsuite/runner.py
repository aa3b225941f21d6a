"""Running SmallArmBench problems: lynxplan's planner, then an independent dense exact check.

Each problem is planned with :class:`lynxplan.planning.Planner` (built per problem: collision
world, compiled checker; its construction is the ``setup`` time, outside the planning figures)
and one ``solve`` (seed 0 by default). What decides "solved" is a node budget
(:data:`NODE_BUDGET`), not the wall clock: the same problem gives the same outcome and path on
any machine, loaded or not, serial or on Dask; the issue's "solved within 1 s" is then a solved
problem whose total time is at most :data:`TIME_LIMIT`. Its path is then checked by
:func:`dense_check`, independently of the planner's own verification: Pinocchio's
``computeDistances`` (coal) on the robot's collision model plus the boxes, at joint steps of at
most :data:`DENSE_STEP` along every segment. A path is *clean* when every distance there is
positive.
"""

from __future__ import annotations

import hashlib
import itertools
import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lynxplan.benchsuite.problem import Problem, suite_robot, yaw_rotation

#: Largest joint step of the dense check, in [rad].
DENSE_STEP = 0.005
#: The issue's "solved within 1 s", in [s]: the peers' planning time limit, and the total time
#: (plan + simplify + verify) within which a solved problem counts for the goal.
TIME_LIMIT = 1.0
#: RRT-Connect's node budget per tree (:attr:`PlannerOptions.max_nodes`) that decides whether a
#: problem is solved: at least what one idle core grows in 1 s on the narrow passages of the
#: SO-101 and the UR5 (measured: 0.7-1.2 s and 2.1-3.7 s; docs/smallarmbench.md), so that the
#: budget never stops a search that would end within the goal's 1 s.
NODE_BUDGET = 10_000
#: Wall-clock limit of one solve, in [s]: a safety net only, far above what the node budget takes
#: (a problem it stops says so in its reason, and is the one outcome that may differ by machine).
SAFETY_TIME_LIMIT = 60.0


@dataclass(frozen=True)
class ProblemResult:
    """What one problem gave.

    Attributes:
        name: Problem name (``<robot>_<family>_<index>``); ``robot``, ``family`` its parts.
        solved: Whether the planner returned a path.
        reason: Why not (the error's type and first line), or "".
        clean: The dense check found no contact (False when unsolved).
        min_distance: Smallest distance of the dense check, in [m] (NaN when unsolved).
        setup_time: Building the planner (collision world, checker), in [s].
        plan_time: RRT-Connect, in [s]; ``simplify_time``: shortcutting, in [s];
            ``verify_time``: the planner's exact verification, in [s].
        raw_length: Joint-space length before simplification, in [rad]; ``length`` after.
        path_digest: SHA-256 of the returned waypoints' bytes ("" when unsolved).
        solve_cpu: CPU time of this thread over the whole ``solve`` call (start/goal checks,
            plan, simplify, verify, timing law), in [s] (NaN when unsolved). Unlike the wall
            times, it does not grow while the process waits for a core on a loaded machine (the
            planner runs on one thread).
        nodes: RRT-Connect tree nodes created (both trees; 0 when the planner refused the
            problem before searching): the search's size, the same on every machine.
    """

    name: str
    robot: str
    family: str
    solved: bool
    reason: str
    clean: bool
    min_distance: float
    setup_time: float
    plan_time: float
    simplify_time: float
    verify_time: float
    raw_length: float
    length: float
    path_digest: str
    solve_cpu: float = math.nan
    nodes: int = 0

    @property
    def total_time(self) -> float:
        """Plan + simplify + verify, in [s] (NaN when unsolved)."""
        return self.plan_time + self.simplify_time + self.verify_time

    @property
    def solved_in_time(self) -> bool:
        """Solved with a total time of at most :data:`TIME_LIMIT` (the issue's goal)."""
        return self.solved and self.total_time <= TIME_LIMIT

    def outcome(self) -> tuple[Any, ...]:
        """Everything but the times: equal in a serial and a distributed run (NaN as None, so
        that an unsolved problem's outcome equals itself)."""
        figures = (self.min_distance, self.raw_length, self.length)
        return (self.name, self.solved, self.reason.split(":")[0], self.clean,
                *(None if math.isnan(x) else x for x in figures), self.path_digest,
                self.nodes)  # fmt: skip


def dense_check(robot: Any, problem: Problem, path: np.ndarray) -> float:
    """Smallest distance [m] between the robot and the boxes or itself along ``path`` (M, nq)
    [rad], sampled at joint steps of at most :data:`DENSE_STEP`; negative: a penetration.

    Self pairs are those lynxplan checks (non-adjacent links, less the SRDF's, see
    :class:`lynxplan.collision.CollisionWorld`); distances are Pinocchio's and coal's.
    """
    import coal
    import pinocchio as pin

    if robot.name not in _GEOMETRY:
        _GEOMETRY[robot.name] = _robot_geometry(robot)
    geometry = _GEOMETRY[robot.name].copy()
    links = len(geometry.geometryObjects)
    for name, centre, size, yaw in zip(
        problem.names, problem.centres, problem.sizes, problem.yaws, strict=True
    ):
        placement = pin.SE3(yaw_rotation(float(yaw)), np.asarray(centre, dtype=float))
        box = pin.GeometryObject(name, 0, 0, placement, coal.Box(*np.asarray(size, dtype=float)))
        geometry.addGeometryObject(box)
    for link in range(links):
        for obstacle in range(links, len(geometry.geometryObjects)):
            geometry.addCollisionPair(pin.CollisionPair(link, obstacle))
    model, geometry_data = robot.model, pin.GeometryData(geometry)
    data = model.createData()
    smallest = math.inf
    for q in densify(path):
        pin.computeDistances(model, data, geometry, geometry_data, q)
        smallest = min(smallest, *(r.min_distance for r in geometry_data.distanceResults))
    return smallest


_GEOMETRY: dict[str, Any] = {}


def _robot_geometry(robot: Any) -> Any:
    """A copy of the robot's collision model (meshes as coal convex shapes: the model's meshes
    are convex hulls already; GJK on them is what coal does fast) with its self pairs."""
    import pinocchio as pin

    from lynxplan.collision import CollisionWorld

    geometry = pin.GeometryModel()
    for item in robot.collision_model.geometryObjects:
        shape = item.geometry
        if hasattr(shape, "buildConvexRepresentation"):
            shape = shape.clone()
            shape.buildConvexRepresentation(False)
            shape = shape.convex
        geometry.addGeometryObject(
            pin.GeometryObject(item.name, item.parentJoint, item.parentFrame, item.placement, shape)
        )
    for a, b in CollisionWorld(robot, (), self_collision=True).self_pairs:
        geometry.addCollisionPair(pin.CollisionPair(int(a), int(b)))
    return geometry


def densify(path: np.ndarray, step: float = DENSE_STEP) -> np.ndarray:
    """The waypoints of ``path`` (M, nq) and points between them at most ``step`` [rad] apart
    in every joint, in order, shape (K, nq)."""
    rows = [path[:1]]
    for a, b in itertools.pairwise(path):
        n = max(1, math.ceil(float(np.abs(b - a).max()) / step))
        rows.append(a + np.linspace(0.0, 1.0, n + 1)[1:, None] * (b - a))
    return np.concatenate(rows)


def run_problem(
    problem: Problem, *, seed: int = 0, time_limit: float = SAFETY_TIME_LIMIT
) -> ProblemResult:
    """Plan ``problem`` with lynxplan (node budget :data:`NODE_BUDGET`, wall-clock limit
    ``time_limit`` [s]) and check the path densely."""
    from lynxplan.exceptions import LynxplanError
    from lynxplan.planning import Planner, PlannerOptions

    robot = suite_robot(problem.robot)
    began = time.perf_counter()
    planner = Planner(robot, problem.obstacles(), PlannerOptions(max_nodes=NODE_BUDGET))
    setup = time.perf_counter() - began
    nan = math.nan
    cpu = time.thread_time()
    try:
        trajectory = planner.solve(problem.start, problem.goal, seed=seed, time_limit=time_limit)
    except LynxplanError as error:
        line = (str(error).strip().splitlines() or [""])[0][:200]
        return ProblemResult(problem.name, problem.robot, problem.family, False,
                             f"{type(error).__name__}: {line}", False, nan, setup, nan, nan, nan,
                             nan, nan, "", nodes=getattr(error, "nodes", 0))  # fmt: skip
    cpu = time.thread_time() - cpu
    path = np.asarray(trajectory.waypoints, dtype=float)
    stats = trajectory.stats
    smallest = dense_check(robot, problem, path)
    return ProblemResult(
        problem.name, problem.robot, problem.family, True, "", smallest > 0.0, smallest, setup,
        stats.plan_time, stats.shortcut_time, stats.verify_time, stats.raw_length,
        trajectory.path_length, hashlib.sha256(path.tobytes()).hexdigest(), cpu, stats.nodes,
    )  # fmt: skip


_WARM: set[str] = set()


def run_chunk(
    problems: Sequence[Problem], *, seed: int = 0, time_limit: float = SAFETY_TIME_LIMIT
) -> list[ProblemResult]:
    """Run problems in order; a process's first problem of each robot is solved once before
    (numba's kernels load or compile then, not inside the figures)."""
    for problem in problems:
        if problem.robot not in _WARM:
            run_problem(problem, seed=seed, time_limit=time_limit)
            _WARM.add(problem.robot)
    return [run_problem(p, seed=seed, time_limit=time_limit) for p in problems]


def run_serial(
    problems: Sequence[Problem],
    *,
    seed: int = 0,
    time_limit: float = SAFETY_TIME_LIMIT,
    progress: Callable[[int, int], None] | None = None,
) -> list[ProblemResult]:
    """Every problem in this process, in order, with ``progress(done, total)`` after each."""
    results: list[ProblemResult] = []
    for problem in problems:
        results += run_chunk([problem], seed=seed, time_limit=time_limit)
        if progress is not None:
            progress(len(results), len(problems))
    return results
