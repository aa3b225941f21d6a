"""The planning pipeline: checks, RRT-Connect, shortcutting, exact verification, timing.

:func:`plan` is the public entry point (also ``lynxplan.plan``); :class:`Planner` keeps the
per-world set-up (collision world, compiled checker) for repeated queries, as the benchmark does.
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, cast

import numpy as np

from lynxplan import _jit
from lynxplan.collision import CollisionWorld, Obstacle
from lynxplan.exceptions import InputError, PlanningFailed, ShapeError
from lynxplan.planning.bounds import STALL_DISTANCE
from lynxplan.planning.certify import verification_rows
from lynxplan.planning.problem import Goal, goal_configurations
from lynxplan.planning.rrt_connect import RrtConnectSettings, rrt_connect
from lynxplan.planning.shortcut import (
    DEFAULT_SHORTCUT_ITERATIONS,
    DEFAULT_SHORTCUT_PATIENCE,
    shortcut_path,
    shortcut_to_goals,
)
from lynxplan.planning.space import JointSpace
from lynxplan.planning.timing import DEFAULT_SAMPLE_RATE, METHODS, TimedPath, time_parameterize
from lynxplan.planning.validity import ValidityChecker
from lynxplan.planning.verify import (
    VerificationReport,
    clear_states,
    require_clear,
    verifier_of,
)
from lynxplan.trajectory.limits import DEFAULT_MAX_ACCELERATION, DEFAULT_MAX_JERK

_jit.listen()  # the planner's kernels: a notice when their first compile takes long

#: Default required clearance between the robot and anything else, in [m].
DEFAULT_CLEARANCE = 0.002


@dataclass(frozen=True)
class PlannerOptions:
    """Options of :func:`plan` (the ``planner:`` block of a ``kind: plan`` scenario).

    Attributes:
        clearance: Required distance to obstacles and between non-adjacent links, in [m].
        step: RRT-Connect extension step, Euclidean in joint space, in [rad].
        goal_bias: Probability of sampling the other tree's root.
        max_nodes: Node budget of each tree.
        shortcut_iterations: Random shortcut attempts after a path is found.
        shortcut_patience: The random shortcuts stop after this many attempts in a row that
            changed nothing (OMPL's ``maxEmptySteps``): fewer give faster planning and longer
            paths (AL5 suite, 60 seeds: 5 -> planning ~10 % faster, paths ~4 % longer; 3 ->
            ~15 % faster, ~9 % longer).
        timing: Time-parameterisation method, one of ``ruckig``, ``lspb``, ``toppra``.
        max_acceleration: Joint acceleration limit, scalar or (nq,), in [rad/s^2].
        max_jerk: Joint jerk limit (ruckig), scalar or (nq,), in [rad/s^3].
        sample_rate: Sample rate of the trajectory, in [Hz].
    """

    clearance: float = DEFAULT_CLEARANCE
    step: float = RrtConnectSettings.step
    goal_bias: float = RrtConnectSettings.goal_bias
    max_nodes: int = RrtConnectSettings.max_nodes
    shortcut_iterations: int = DEFAULT_SHORTCUT_ITERATIONS
    shortcut_patience: int = DEFAULT_SHORTCUT_PATIENCE
    timing: str = "ruckig"
    max_acceleration: float | tuple[float, ...] = DEFAULT_MAX_ACCELERATION
    max_jerk: float | tuple[float, ...] = DEFAULT_MAX_JERK
    sample_rate: float = DEFAULT_SAMPLE_RATE

    def __post_init__(self) -> None:
        checks = (
            ("clearance", self.clearance, self.clearance >= 0),
            ("step", self.step, self.step > 0),
            ("goal_bias", self.goal_bias, 0 <= self.goal_bias < 1),
            ("max_nodes", self.max_nodes, self.max_nodes >= 2),
            ("shortcut_iterations", self.shortcut_iterations, self.shortcut_iterations >= 0),
            ("shortcut_patience", self.shortcut_patience, self.shortcut_patience >= 1),
            ("sample_rate", self.sample_rate, self.sample_rate > 0),
        )
        for name, value, ok in checks:
            if not (ok and math.isfinite(float(value))):
                raise InputError(f"planner option {name} = {value!r} is out of range")
        if self.timing not in METHODS:
            raise InputError(
                f"planner option timing must be one of {', '.join(METHODS)}. Got: {self.timing!r}"
            )


def _per_joint_option(name: str, value: Any, nq: int) -> np.ndarray:
    """A planner option given as a scalar or one value per joint, as (nq,) floats."""
    array = np.asarray(value, dtype=float)
    if array.shape not in ((), (nq,)):
        raise ShapeError(f"planner option {name}", f"() or ({nq},)", array.shape)
    out: np.ndarray = np.broadcast_to(array, (nq,)).copy()
    return out


@dataclass(frozen=True)
class PlanningStats:
    """Where the time went and how big the search was.

    Attributes:
        nodes: Tree nodes created (both trees).
        iterations: RRT-Connect iterations.
        raw_waypoints: Waypoints of the path before shortcutting.
        raw_length: Joint-space length before shortcutting, in [rad].
        plan_time: RRT-Connect, in [s].
        shortcut_time: Shortcutting and smoothing, in [s].
        verify_time: Exact verification, in [s].
        timing_time: Time-parameterisation, in [s].
    """

    nodes: int
    iterations: int
    raw_waypoints: int
    raw_length: float
    plan_time: float
    shortcut_time: float
    verify_time: float
    timing_time: float

    @property
    def solve_time(self) -> float:
        """Plan + shortcut + verify, in [s] (the benchmark's planning time)."""
        return self.plan_time + self.shortcut_time + self.verify_time


@dataclass(frozen=True)
class PlannedTrajectory:
    """A planned, verified, time-parameterised motion.

    Attributes:
        waypoints: Path waypoints, shape (M, nq), in [rad] (read-only); straight joint segments.
        t: Sample times, shape (N,), in [s] (read-only).
        q: Joint angles, shape (N, nq), in [rad] (read-only).
        qd: Joint velocities, shape (N, nq), in [rad/s] (read-only).
        qdd: Joint accelerations, shape (N, nq), in [rad/s^2] (read-only).
        segment: Path segment of each sample, shape (N,) (read-only).
        verification: Exact collision verification of the path (min clearance, pairs checked).
        goal_label: Which goal configuration was reached (IK branch for a pose goal).
        goal_index: Its index among the goal configurations.
        path_length: Joint-space length of the path, in [rad].
        seed: The random seed.
        stats: Search size and timings.
        options: The options used.
    """

    waypoints: np.ndarray
    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    segment: np.ndarray
    verification: VerificationReport
    goal_label: str
    goal_index: int
    path_length: float
    seed: int
    stats: PlanningStats
    options: PlannerOptions = field(default_factory=PlannerOptions)

    @property
    def duration(self) -> float:
        """Duration, in [s]."""
        return float(self.t[-1])

    @property
    def min_clearance(self) -> float:
        """Smallest exact distance at the waypoints and certification probes, in [m]."""
        return float(self.verification.min_clearance.clearance)


class Planner:
    """A robot among fixed obstacles, prepared for repeated planning queries.

    Args:
        robot: The robot: ``model`` (Pinocchio), ``collision_model``, ``limits``
            (``lower``/``upper``/``velocity``) and ``ik`` for pose goals — an
            :class:`lynxplan.arm.Arm` or a robot of ``lynxplan.load_robot``.
        world: A :class:`lynxplan.collision.CollisionWorld` of that robot, or the obstacles.
        options: Planner options.
    """

    def __init__(
        self,
        robot: Any,
        world: CollisionWorld | Sequence[Obstacle],
        options: PlannerOptions | None = None,
    ) -> None:
        self.robot = robot
        self.options = options or PlannerOptions()
        obstacles = world.obstacles if isinstance(world, CollisionWorld) else tuple(world)
        if isinstance(world, CollisionWorld) and world.pair_is_self.any():
            self.world = world
        else:
            self.world = CollisionWorld(robot, obstacles, self_collision=True)
        self.space = JointSpace.of(robot)
        self.checker = ValidityChecker(self.world, self.options.clearance)
        self.verifier = verifier_of(self.world)
        nq = self.space.dimension
        self.velocity = np.array(robot.limits.velocity, dtype=float)
        self.acceleration = _per_joint_option("max_acceleration", self.options.max_acceleration, nq)
        self.jerk = _per_joint_option("max_jerk", self.options.max_jerk, nq)
        for name, limit in (("acceleration", self.acceleration), ("jerk", self.jerk)):
            if not (np.isfinite(limit).all() and (limit > 0).all()):
                raise InputError(f"planner option max_{name} must be positive: {limit.tolist()}")

    def _require_certifiable(self, q: np.ndarray, what: str) -> None:
        """PlanningFailed at once (not after the time limit) when the conservative checker
        cannot certify a start or goal that the exact check accepted."""
        bounds = self.checker.pair_bounds(q)
        if bounds.size and bounds.min() <= self.options.clearance + STALL_DISTANCE:
            pair = int(np.argmin(bounds))
            geometry, other = self.checker.pair_names[pair]
            raise PlanningFailed(
                0,
                0,
                0.0,
                f"the {what} is too close to {other} ({geometry}) for the planner's conservative "
                f"checker: lower bound {bounds[pair] * 1e3:.2f} mm, needs more than "
                f"{(self.options.clearance + STALL_DISTANCE) * 1e3:.2f} mm",
            )

    def _compile(self, q: np.ndarray) -> None:
        """On the first query in a process, compile (or load from numba's cache) the shortcut
        and verification kernels before the clock starts, on a path that stays at q (nq,), a
        valid configuration: their run is trivial, their compile is not. (RRT-Connect compiles
        its own kernel outside its time limit.)"""
        # (the entry points called from Python: a kernel loaded from numba's cache registers no
        # overloads for its compiled callees; .signatures: ~20 us each)
        # (Python functions, under numba's NUMBA_DISABLE_JIT, have nothing to compile)
        kernels = (cast(Any, shortcut_path), cast(Any, verification_rows))
        if all(getattr(kernel, "overloads", True) for kernel in kernels):
            return
        path = np.vstack([q, q])
        lower, upper = self.space.lower, self.space.upper
        shortcut_to_goals(self.checker, path, path[1:], 0, lower, upper, seed=0)
        self.verifier.verify(path, self.options.clearance)

    def _check_state(self, q: np.ndarray, what: str) -> None:
        require_clear(self.world, q, what, self.options.clearance)

    def solve(
        self, start: Any, goal: Goal | Any, *, seed: int = 0, time_limit: float = 1.0
    ) -> PlannedTrajectory:
        """Plan, shortcut, verify and time-parameterise (see :func:`plan`)."""
        if not (math.isfinite(time_limit) and time_limit > 0):
            raise InputError(f"time_limit must be positive. Got: {time_limit!r} s")
        q_start = self.space.check(start, "start", tolerance=1e-9)
        goals = goal_configurations(self.robot, self.space, goal)
        self._check_state(q_start, "start")
        names = (
            ["goal"] if len(goals.configurations) == 1 else [f"goal ({x})" for x in goals.labels]
        )
        problems = clear_states(self.world, goals.configurations, names, self.options.clearance)
        free = [k for k, problem in enumerate(problems) if problem is None]
        if not free:
            raise next(p for p in problems if p is not None)
        self._require_certifiable(q_start, "start")
        certifiable = [k for k in free if self.checker.is_valid(goals.configurations[k])]
        if not certifiable:
            self._require_certifiable(goals.configurations[free[0]], "goal")
        free = certifiable
        self._compile(q_start)
        settings = RrtConnectSettings(
            self.options.step, self.options.goal_bias, self.options.max_nodes
        )
        found = rrt_connect(
            self.checker,
            self.space.lower,
            self.space.upper,
            q_start,
            goals.configurations[free],
            seed=seed,
            time_limit=time_limit,
            settings=settings,
        )
        planned = time.perf_counter()
        path, reached = shortcut_to_goals(
            self.checker,
            found.path,
            goals.configurations[free],
            found.goal_index,
            self.space.lower,
            self.space.upper,
            seed=seed,
            iterations=self.options.shortcut_iterations,
            patience=self.options.shortcut_patience,
        )
        shortened = time.perf_counter()
        report = self.verifier.verify(path, self.options.clearance)
        verified = time.perf_counter()
        timed = time_parameterize(
            path,
            self.velocity,
            self.acceleration,
            self.jerk,
            method=self.options.timing,
            rate=self.options.sample_rate,
        )
        done = time.perf_counter()
        goal_index = free[reached]
        stats = PlanningStats(
            nodes=found.nodes,
            iterations=found.iterations,
            raw_waypoints=len(found.path),
            raw_length=self.space.path_length(found.path),
            plan_time=found.elapsed,  # without compiling its kernels (first call in a process)
            shortcut_time=shortened - planned,
            verify_time=verified - shortened,
            timing_time=done - verified,
        )
        return _trajectory(
            path,
            timed,
            report,
            goals.labels[goal_index],
            goal_index,
            self.space.path_length(path),
            seed,
            stats,
            self.options,
        )


def _trajectory(
    path: np.ndarray,
    timed: TimedPath,
    report: VerificationReport,
    label: str,
    goal_index: int,
    length: float,
    seed: int,
    stats: PlanningStats,
    options: PlannerOptions,
) -> PlannedTrajectory:
    for array in (path, timed.t, timed.q, timed.qd, timed.qdd, timed.segment):
        array.setflags(write=False)
    return PlannedTrajectory(
        path,
        timed.t,
        timed.q,
        timed.qd,
        timed.qdd,
        timed.segment,
        report,
        label,
        goal_index,
        length,
        seed,
        stats,
        options,
    )


def plan(
    robot: Any,
    world: CollisionWorld | Sequence[Obstacle],
    start: Any,
    goal: Goal | Any,
    *,
    seed: int = 0,
    time_limit: float = 1.0,
    options: PlannerOptions | None = None,
) -> PlannedTrajectory:
    """Plan a collision-free motion from ``start`` to ``goal``, verified and time-parameterised.

    Args:
        robot: The robot (:class:`lynxplan.arm.Arm` or a ``lynxplan.load_robot`` robot).
        world: A :class:`lynxplan.collision.CollisionWorld` of that robot, or its obstacles.
        start: Start configuration, shape (nq,), in [rad].
        goal: A :class:`~lynxplan.planning.JointGoal`, :class:`~lynxplan.planning.PoseGoal`
            (every IK branch is a goal), :class:`~lynxplan.planning.ApproachGoal`, or a bare
            array: (nq,) joint goal or (4, 4) tool pose.
        seed: Random seed; the same seed gives a bit-identical result.
        time_limit: Planning time budget of RRT-Connect, in [s].
        options: Planner options (clearance, step, node budget, timing method, limits).

    Returns:
        The trajectory: waypoints, samples t/q/qd/qdd, verification report (min clearance).

    Raises:
        ConfigurationOutsideLimitsError, ShapeError, NonFiniteInputError: bad start or goal.
        StateInCollisionError: the start or every goal configuration collides (names the link,
            the obstacle and the penetration depth).
        GoalUnreachableError: no IK branch of a pose goal within the joint limits.
        PlanningFailed: no path within the time limit / node budget (with the node count).
    """
    return Planner(robot, world, options).solve(start, goal, seed=seed, time_limit=time_limit)


__all__ = [
    "DEFAULT_CLEARANCE",
    "STALL_DISTANCE",
    "PlannedTrajectory",
    "Planner",
    "PlannerOptions",
    "PlanningStats",
    "plan",
]
