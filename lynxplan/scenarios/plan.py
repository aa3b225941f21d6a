"""Scenario kind ``plan``: a motion planned among obstacles, verified and time-parameterised.

Example (``scenarios/planning/`` holds the problem suite)::

    kind: plan
    name: window
    units: {length: m, angle: deg}
    robot: {}                                   # the shipped AL5
    obstacles:                                  # same entries as kind: task
      - {name: wall, type: box, min_corner: [-0.3, 0.15, -0.09], size: [0.6, 0.02, 0.5]}
    start: [30, 100, -120, 90, 0]               # joint angles, in the file's angle unit
    goal: {q: [90, 90, -90, 90, 0]}             # or {pose: 3-4 rows}, or {position, approach}
    planner:
      seed: 0                                   # same seed -> bit-identical trajectory
      time_limit: 1.0                           # [s]
      clearance: 0.002                          # required clearance, file's length unit
      step: 86                                  # RRT-Connect step, file's angle unit
      goal_bias: 0.05
      max_nodes: 20000                          # per tree
      shortcut_iterations: 60
      shortcut_patience: 12                     # random cuts stop after 12 that changed nothing
      timing: ruckig                            # ruckig | lspb | toppra
      sample_rate: 100                          # [Hz]
      acceleration: 458                         # angle unit / s^2, scalar or per joint
      jerk: 3438                                # angle unit / s^3 (ruckig)
    expect:
      solved: true
      collision_free: true
      min_clearance: ">= 2 mm"
      max_duration: "<= 10 s"

An unsolvable problem is not an error: ``solved`` is false and ``nodes`` says how many tree
nodes were tried before the time limit or node budget (expect ``solved: false``). A start or
goal in collision, or a goal out of reach, is an error naming the link, the obstacle and the
penetration depth.

Metrics: ``solved``, ``collision_free`` (exact verification passed), ``within_limits`` (joint
position, velocity and acceleration limits at every sample), ``min_clearance`` [m]
(:data:`lynxplan.scenarios.report.MIN_CLEARANCE_DEFINITION`: the smallest exact distance over the
samples of the trajectory written to ``trajectory.csv``; the summary, ``details.min_clearance``
and ``clearance.png`` show this same value; the planner certifies the required clearance on the
continuous geometric path), ``duration`` [s], ``path_length``
[rad] (joint space), ``nodes``, ``waypoints``, ``planning_time`` [s] (plan + shortcut + verify).
Artifacts: ``trajectory.csv`` and, unless quick or switched off in ``outputs``,
``clearance.png`` and ``<name>.html``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from pydantic import Field

from lynxplan._jit import kernels_run_as_python
from lynxplan.scenarios.base import (
    SI_UNITS,
    Finite,
    KindOutput,
    Positive,
    Quantity,
    RobotRef,
    ScenarioModel,
    StrictModel,
    TargetEntry,
    Units,
    scale_obstacles,
    scale_translation,
    scaled,
)
from lynxplan.scenarios.task import ObstacleEntry, OutputsEntry
from lynxplan.units import angle_factor, length_factor

NAME = "plan"

PerJoint = Positive | Annotated[list[Positive], Field(min_length=1, max_length=12)]


class GoalEntry(TargetEntry):
    """A start or goal: joint angles, a tool pose (every IK branch), or a position + approach."""


class PlannerEntry(StrictModel):
    """Planner options (see :class:`lynxplan.planning.PlannerOptions`)."""

    seed: int = Field(0, ge=0, lt=2**63, description="Random seed, 0 <= seed < 2**63.")
    time_limit: Positive = Field(1.0, le=3600, description="Planning time budget, in [s].")
    clearance: Annotated[float, Field(ge=0, allow_inf_nan=False)] | None = Field(
        None, description="Required clearance, file's length unit (default 2 mm)."
    )
    step: Positive | None = Field(None, description="RRT-Connect step, file's angle unit.")
    goal_bias: Annotated[float, Field(ge=0, lt=1)] | None = Field(
        None, description="Probability of sampling the other tree's root (default 0.05)."
    )
    max_nodes: int = Field(20000, ge=2, le=10_000_000, description="Node budget per tree.")
    shortcut_iterations: int = Field(60, ge=0, le=100_000)
    shortcut_patience: int = Field(
        12,
        ge=1,
        le=100_000,
        description="Random shortcuts stop after this many attempts in a row that changed nothing.",
    )
    timing: Literal["ruckig", "lspb", "toppra"] = "ruckig"
    sample_rate: Positive = Field(100.0, le=1e5, description="Samples per second, in [Hz].")
    acceleration: PerJoint | None = Field(None, description="Angle unit/s^2 (default 8 rad/s^2).")
    jerk: PerJoint | None = Field(None, description="Angle unit/s^3 (default 60 rad/s^3).")


class Input(ScenarioModel):
    """A ``plan`` scenario: start, goal, obstacles, planner options, expectations."""

    metrics: ClassVar[dict[str, Quantity]] = {
        "solved": "bool",
        "collision_free": "bool",
        "within_limits": "bool",
        "min_clearance": "length",
        "duration": "time",
        "path_length": "angle",
        "nodes": "count",
        "waypoints": "count",
        "planning_time": "time",
    }

    kind: Literal["plan"]
    units: Units = Units(length="m", angle="rad")
    robot: RobotRef = Field(default_factory=RobotRef)
    obstacles: list[ObstacleEntry] = Field(default_factory=list, max_length=1000)
    start: Annotated[list[Finite], Field(min_length=1, max_length=12)] = Field(
        description="Start joint angles, in the file's angle unit."
    )
    goal: GoalEntry
    planner: PlannerEntry = Field(default_factory=PlannerEntry)
    outputs: OutputsEntry = Field(default_factory=OutputsEntry)

    def si_inputs(self) -> dict[str, Any]:
        """Inputs in [m] and [rad] (limits in rad/s^n)."""
        length, angle = length_factor(self.units.length), angle_factor(self.units.angle)
        data = super().si_inputs()
        data["units"] = dict(SI_UNITS)
        scale_obstacles(data["obstacles"], length, angle)
        data["start"] = scaled(data["start"], angle)
        goal = data["goal"]
        goal.update(
            q=scaled(goal["q"], angle),
            pose=scale_translation(goal["pose"], length),
            position=scaled(goal["position"], length),
        )
        planner = data["planner"]
        planner["clearance"] = scaled(planner["clearance"], length)
        for key in ("step", "acceleration", "jerk"):
            planner[key] = scaled(planner[key], angle)
        return data


Scenario = Input


def _obstacles(scenario: Input) -> list[Any]:
    from lynxplan.task.setup import _obstacle

    length, angle = length_factor(scenario.units.length), angle_factor(scenario.units.angle)
    return [
        _obstacle(entry, entry.name or f"obstacle_{i}", length, angle)
        for i, entry in enumerate(scenario.obstacles)
    ]


def _goal(scenario: Input) -> Any:
    from lynxplan.planning import ApproachGoal, JointGoal, PoseGoal

    length, angle = length_factor(scenario.units.length), angle_factor(scenario.units.angle)
    goal = scenario.goal
    if goal.q is not None:
        return JointGoal(np.array(goal.q) * angle)
    if goal.pose is not None:
        pose = np.eye(4)
        pose[: len(goal.pose)] = np.array(goal.pose)
        pose[:3, 3] *= length
        return PoseGoal(pose)
    return ApproachGoal(np.array(goal.position) * length, np.array(goal.approach))


def planner_options(scenario: Input) -> Any:
    """The :class:`lynxplan.planning.PlannerOptions` of a scenario's ``planner:`` block."""
    from lynxplan.planning import PlannerOptions

    length, angle = length_factor(scenario.units.length), angle_factor(scenario.units.angle)
    entry = scenario.planner
    values: dict[str, Any] = {
        "max_nodes": entry.max_nodes,
        "shortcut_iterations": entry.shortcut_iterations,
        "shortcut_patience": entry.shortcut_patience,
        "timing": entry.timing,
        "sample_rate": entry.sample_rate,
    }
    if entry.clearance is not None:
        values["clearance"] = entry.clearance * length
    if entry.step is not None:
        values["step"] = entry.step * angle
    if entry.goal_bias is not None:
        values["goal_bias"] = entry.goal_bias
    for key in ("acceleration", "jerk"):
        value = getattr(entry, key)
        if isinstance(value, list):
            values[f"max_{key}"] = tuple(float(v) * angle for v in value)
        elif value is not None:
            values[f"max_{key}"] = float(value) * angle
    return PlannerOptions(**values)


@dataclass(frozen=True)
class PlanInputs:
    """A scenario resolved to planner inputs (SI units).

    Attributes:
        robot: The loaded robot.
        obstacles: The obstacles.
        start: Start configuration, shape (nq,), in [rad].
        goal: The goal (:mod:`lynxplan.planning.problem`).
        options: Planner options.
        seed: Random seed.
        time_limit: Planning time budget, in [s].
        solvable: Whether the file expects a solution (``expect: {solved: false}`` says not).
    """

    robot: Any
    obstacles: list[Any]
    start: np.ndarray
    goal: Any
    options: Any
    seed: int
    time_limit: float
    solvable: bool


def plan_inputs(scenario: Input) -> PlanInputs:
    """The planner inputs of a scenario (loads the robot: the AL5 or any URDF robot); warns
    about lengths implausible for the robot (:func:`warn_implausible_lengths`)."""
    from lynxplan.scenarios.plausible import warn_implausible_lengths
    from lynxplan.scenarios.robot import load_robot_entry

    robot = load_robot_entry(scenario.robot)
    goal = scenario.goal
    target = goal.position if goal.pose is None else [row[3] for row in goal.pose[:3]]
    targets = [] if target is None else [("goal", target)]
    warn_implausible_lengths(robot, scenario.units.length, scenario.obstacles, targets)
    return PlanInputs(
        robot,
        _obstacles(scenario),
        np.array(scenario.start) * angle_factor(scenario.units.angle),
        _goal(scenario),
        planner_options(scenario),
        scenario.planner.seed,
        scenario.planner.time_limit,
        scenario.expect.get("solved", True) is not False,
    )


def run(scenario: Input, *, quick: bool = False) -> KindOutput:
    """Plan, verify, time-parameterise; measure limits and per-sample clearance (no files)."""
    import time

    from lynxplan.exceptions import PlanningFailed
    from lynxplan.planning import Planner

    began = time.perf_counter()
    inputs = plan_inputs(scenario)
    robot = inputs.robot
    planner = Planner(robot, inputs.obstacles, inputs.options)
    built = time.perf_counter()
    try:
        trajectory = planner.solve(
            inputs.start, inputs.goal, seed=inputs.seed, time_limit=inputs.time_limit
        )
    except PlanningFailed as failure:
        metrics = {
            "solved": False,
            "collision_free": False,
            "within_limits": False,
            "min_clearance": float("nan"),
            "duration": float("nan"),
            "path_length": float("nan"),
            "nodes": failure.nodes,
            "waypoints": 0,
            "planning_time": failure.elapsed,
        }
        summary = f"plan {scenario.name}: unsolved: {failure}"
        return KindOutput(
            metrics,
            summary,
            {"failure": str(failure)},
            payload=None,
            stage_seconds={"setup": built - began, "plan": failure.elapsed},
        )
    solved = time.perf_counter()
    limits = limit_violations(trajectory, planner)
    closest = min_clearance(planner.world, trajectory.t, trajectory.q)
    metrics = {
        "solved": True,
        "collision_free": trajectory.verification.collision_free,
        "within_limits": not limits,
        "min_clearance": closest.clearance,
        "duration": trajectory.duration,
        "path_length": trajectory.path_length,
        "nodes": trajectory.stats.nodes,
        "waypoints": len(trajectory.waypoints),
        "planning_time": trajectory.stats.solve_time,
    }
    summary = (
        f"plan {scenario.name}: solved with {trajectory.stats.nodes} nodes in "
        f"{trajectory.stats.solve_time * 1e3:.1f} ms (plan + shortcut + verify); "
        f"{len(trajectory.waypoints)} waypoints, {trajectory.path_length:.3f} rad, "
        f"{trajectory.duration:.3f} s; min clearance {closest.describe(scenario.units.length)}; "
        f"goal {trajectory.goal_label}"
    )
    details = {
        "waypoints": trajectory.waypoints.tolist(),
        "goal": trajectory.goal_label,
        "min_clearance": closest.as_dict(),
        # the verifier's smallest distance where it queried the geometric path: a different
        # (coarser) quantity, not the metric; time is the path parameter (waypoint index)
        "verification_probes_min_clearance": trajectory.verification.min_clearance._asdict(),
        "limit_violations": limits,
        "stats": {**trajectory.stats.__dict__, "solve_time": trajectory.stats.solve_time},
        # planning_time's kernels: "python" on a first run from the command line (_jit)
        "kernels": "python" if kernels_run_as_python() else "compiled",
        "verification": {
            "self_collision_pairs": trajectory.verification.self_collision_pairs,
            "obstacle_pairs": trajectory.verification.obstacle_pairs,
            "exact_queries": trajectory.verification.exact_queries,
        },
    }
    payload = {
        "trajectory": trajectory,
        "robot": robot,
        "planner": planner,
        "clearances": closest.per_sample,
        "closest": closest,
    }
    stages = {
        "setup": built - began,
        "plan": trajectory.stats.solve_time,
        "timing": trajectory.stats.timing_time,
        "clearance_profile": time.perf_counter() - solved,
    }
    return KindOutput(metrics, summary, details, payload=payload, stage_seconds=stages)


@dataclass(frozen=True)
class ClosestApproach:
    """The ``min_clearance`` of a plan (:data:`~lynxplan.scenarios.report.
    MIN_CLEARANCE_DEFINITION`), computed once and reported by the metric, the summary, the
    details and the plot alike.

    Attributes:
        clearance: Smallest exact distance over the samples, in [m] (NaN: nothing to collide
            with).
        link: The robot link of the closest pair ("" when none).
        obstacle: The obstacle (``self:<geometry>`` for a self pair; "" when none).
        time: Time of the sample, in [s].
        per_sample: The smallest distance at each sample, shape (N,), in [m].
    """

    clearance: float
    link: str
    obstacle: str
    time: float
    per_sample: np.ndarray

    def as_dict(self) -> dict[str, Any]:
        """``details.min_clearance`` of ``report.json`` (SI)."""
        return {
            "clearance": self.clearance,
            "link": self.link,
            "obstacle": self.obstacle,
            "time": self.time,
        }

    def describe(self, length_unit: str) -> str:
        """``6.983 mm (link_4 to wall at t = 1.23 s)``: in mm for metre files, else the file's
        length unit."""
        unit = "mm" if length_unit == "m" else length_unit
        if not np.isfinite(self.clearance):
            return "not measured (nothing to collide with)"
        return (
            f"{self.clearance / length_factor(unit):.4g} {unit} ({self.link} to {self.obstacle} "
            f"at t = {self.time:.3f} s)"
        )


def min_clearance(world: Any, t: np.ndarray, q: np.ndarray) -> ClosestApproach:
    """The plan's ``min_clearance``: exact (coal) smallest distance over every collision pair
    at each sample q (N, nq) [rad] at times t (N,) [s], and where it is smallest."""
    from lynxplan.planning.verify import verifier_of

    distances, pairs = verifier_of(world).closest(np.asarray(q, dtype=float))
    worst = int(np.argmin(distances))
    if pairs[worst] < 0 or not np.isfinite(distances[worst]):
        return ClosestApproach(float("nan"), "", "", float("nan"), distances)
    link, _geometry, obstacle = world.pair_names(int(pairs[worst]))
    return ClosestApproach(
        float(distances[worst]), link, obstacle, float(np.asarray(t)[worst]), distances
    )


def limit_violations(trajectory: Any, planner: Any) -> list[str]:
    """Joint position, velocity and acceleration limits at every sample; what is exceeded."""
    from lynxplan.constants import LIMIT_CHECK_RELATIVE_TOLERANCE, LIMIT_SNAP_TOLERANCE

    slack = 1.0 + LIMIT_CHECK_RELATIVE_TOLERANCE
    found: list[str] = []
    space = planner.space
    checks = (
        ("position below", -trajectory.q, -space.lower + LIMIT_SNAP_TOLERANCE),
        ("position above", trajectory.q, space.upper + LIMIT_SNAP_TOLERANCE),
        ("velocity", np.abs(trajectory.qd), planner.velocity * slack),
        ("acceleration", np.abs(trajectory.qdd), planner.acceleration * slack),
    )
    for what, values, bound in checks:
        over = values > bound
        found.extend(
            f"{space.joint_names[j]} {what} limit at t = "
            f"{trajectory.t[int(np.argmax(over[:, j]))]:.3f} s"
            for j in np.flatnonzero(over.any(axis=0)).tolist()
        )
    return found


def html_name(scenario: Input) -> str:
    """File name of the HTML export: the scenario name as a slug, e.g. ``window.html``."""
    slug = re.sub(r"[^a-z0-9]+", "_", scenario.name.lower()).strip("_")
    return f"{slug or 'plan'}.html"


def write_outputs(scenario: Input, output: KindOutput, out_dir: Path, *, quick: bool) -> list[str]:
    """``trajectory.csv`` and, unless quick, the clearance plot and the meshcat HTML."""
    from lynxplan.scenarios.outputs import write_trajectory_csv

    if output.payload is None:  # unsolved: report.json only
        return []
    trajectory, robot = output.payload["trajectory"], output.payload["robot"]
    tool = robot.fk(np.asarray(trajectory.q))[:, :3, 3]
    write_trajectory_csv(
        out_dir / "trajectory.csv", trajectory.t, trajectory.q, trajectory.qd, trajectory.qdd, tool
    )
    written = ["trajectory.csv"]
    if quick:
        return written
    if scenario.outputs.plots:
        from lynxplan.planning.plots import plot_clearance

        closest = output.payload["closest"]
        plot_clearance(
            trajectory,
            output.payload["clearances"],
            out_dir / "clearance.png",
            closest=(closest.link, closest.obstacle),
            length_unit="mm" if scenario.units.length == "m" else scenario.units.length,
        )
        written.append("clearance.png")
    if scenario.outputs.html:
        from lynxplan.viz import export_html

        export_html(
            robot,
            trajectory.q,
            trajectory.t,
            out_dir / html_name(scenario),
            path=tool,
            motion=["free"] * len(tool),
            obstacles=output.payload["planner"].world.obstacles,
        )
        written.append(html_name(scenario))
    return written
