"""Scenario kind ``task``: the schema of an arm task (waypoints, segments, obstacles, expectations).

Example (``scenarios/ok_task.yaml`` is the full SPEC Part 3 task)::

    kind: task
    name: pick and place
    units: {length: in, angle: deg}          # lengths in|mm|m, angles deg|rad
    robot: {}                                # the shipped AL5; {name: so101}; {urdf: .., tool: ..}
    sample_rate: 1000                        # [Hz]
    timing: {tt: 2.0, ta: 0.5}               # default of every segment [s]; or: auto
    limits: {acceleration: 450, jerk: 3400}  # per joint (scalar or 5 values), angle unit / s^n
    obstacles:
      - {name: wall, type: box, min_corner: [-0.2, 8, -2], size: [0.4, 10, 3.5]}
      - {name: crate, type: box, centre: [5, 5, 0], size: [2, 2, 2], rpy: [0, 0, 30]}
      - {name: ball, type: sphere, centre: [0, 9, 6], radius: 1}
      - {name: post, type: cylinder, centre: [4, 8, 0], radius: 0.5, length: 6, axis: [0, 0, 1]}
    waypoints:
      A: {q: [104, 57, -59, 40, 0]}                     # joint angles
      B: {pose: [[-0.3196, 0.9455, -0.0621, -2.8966],   # 3 or 4 rows of a 4x4 pose (IK)
                 [0.9281, 0.3256, 0.1804, 8.4123],
                 [0.1908, 0, -0.9816, 0.5472]]}
      C: {position: [2, 10, 1.4], approach: [0, 0.34, -0.94]}   # 5-D target (IK)
    segments:
      - {from: A, to: B, motion: line, orientation: consistent}
      - {to: C, motion: free, timing: auto}   # from: defaults to the previous segment's end
      - {to: A, motion: plan}                 # planned around the obstacles (lynxplan.plan)
    writing_plane: {point: [0.5, 10.3, 1.26], tilt: 20, size: [10, 8]}   # drawn only
    outputs: {plots: true, html: true}
    expect:
      collision_free: true            # no contact at any sample nor between samples
      within_limits: true             # position, velocity and acceleration limits, every sample
      min_clearance: ">= 0.2 in"      # comparator, number, unit (default: the file's unit)
      max_duration: "<= 30 s"

Robots: the shipped AL5 (default; also any URDF of its joint structure, solved with its closed
form), ``{name: so100}`` / ``{name: so101}`` or ``{urdf: path, tool: frame}`` of any 5-joint
yaw-pitch-pitch-pitch-roll arm (closed-form / root-search IK of :func:`lynxplan.load_robot`, mesh
collision geometry as convex hulls). A waypoint's ``ik: report`` is the AL5's branch rule; other
robots take the branch nearest ``q_reference`` (default: zeros). ``scenarios/so101_writing.yaml``
is the SO-101 example.

Relative URDF paths are resolved from the current working directory.

Metrics: ``collision_free``, ``within_limits``, ``min_clearance`` [m], ``duration`` [s],
``path_deviation`` [m], ``joint_speed`` [rad/s] (peak), ``contacts``. Artifacts:
``trajectory.csv`` and, unless quick or switched off in ``outputs``, ``task_side.png``,
``task_top.png``, ``joints.png``, ``clearance.png`` and ``<name>.html``.
"""

from __future__ import annotations

from pathlib import Path

from lynxplan.scenarios.base import KindOutput
from lynxplan.task.schema import (
    BoxEntry,
    CylinderEntry,
    Input,
    LimitsEntry,
    ObstacleEntry,
    OutputsEntry,
    Scenario,
    SegmentEntry,
    SphereEntry,
    TimingEntry,
    WaypointEntry,
    WritingPlaneEntry,
)

#: The schema lives in :mod:`lynxplan.task.schema` (below the task runner, which reads it).
__all__ = [
    "NAME",
    "BoxEntry",
    "CylinderEntry",
    "Input",
    "LimitsEntry",
    "ObstacleEntry",
    "OutputsEntry",
    "Scenario",
    "SegmentEntry",
    "SphereEntry",
    "TimingEntry",
    "WaypointEntry",
    "WritingPlaneEntry",
    "run",
    "write_outputs",
]

NAME = "task"


def run(scenario: Input, *, quick: bool = False) -> KindOutput:
    """Resolve the scenario (IK of the waypoints, the plan), sample, check, compare (no files)."""
    from lynxplan.progress import progress_bar
    from lynxplan.task.report import summary, task_details, task_metrics, task_notes
    from lynxplan.task.run import execute
    from lynxplan.task.setup import resolve

    with progress_bar(f"task {scenario.name}".strip()) as progress:
        setup = resolve(scenario)
        result = execute(scenario, setup, progress, compare=scenario.compare and not quick)
        progress(5, 5)
    return KindOutput(
        task_metrics(result),
        summary(scenario, result),
        task_details(scenario, result),
        payload=result,
        stage_seconds=result.stage_seconds,
        notes=task_notes(result),
    )


def write_outputs(scenario: Input, output: KindOutput, out_dir: Path, *, quick: bool) -> list[str]:
    """``trajectory.csv`` and, unless quick, the plots and the meshcat HTML."""
    from lynxplan.scenarios.outputs import write_samples_csv
    from lynxplan.task.run import html_name

    result = output.payload
    samples = result.samples
    write_samples_csv(out_dir / "trajectory.csv", samples)
    written = ["trajectory.csv"]
    if quick:
        return written
    if scenario.outputs.plots:
        from lynxplan.scenarios.expect import parse_expectation
        from lynxplan.task.plots import write_plots

        required = None
        if "min_clearance" in scenario.expect:
            required = parse_expectation(
                "min_clearance", scenario.expect["min_clearance"], Input.metrics, scenario.units
            )
        written += write_plots(scenario, result, out_dir, required)
    if scenario.outputs.html:
        from lynxplan.task.html import write_html

        write_html(scenario, result, out_dir / html_name(scenario))
        written.append(html_name(scenario))
    return written
