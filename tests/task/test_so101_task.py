"""The SO-101 writing task (``scenarios/so101_writing.yaml``): a URDF robot through the task kind,
its strokes checked with Pinocchio's FK, its clearance against coal on the original meshes."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from lynxplan.collision import clearance_profile
from lynxplan.scenarios import load_scenario
from lynxplan.task.run import execute
from lynxplan.task.setup import resolve

SO101_TASK = Path(__file__).resolve().parents[2] / "scenarios" / "so101_writing.yaml"
#: Straight-line tolerance [m] and coal distance agreement [m].
LINE_TOL = 1e-9
DISTANCE_TOL = 1e-7


@pytest.fixture(scope="module")
def run():
    scenario = load_scenario(SO101_TASK).scenario
    return execute(scenario, resolve(scenario), compare=False)


def test_strokes_are_straight_and_the_pen_points_down_by_pinocchio_fk(run) -> None:
    robot, samples = run.setup.arm, run.samples
    data = robot.model.createData()
    lines = [i for i, s in enumerate(run.setup.plan.segments) if s.kind == "line"]
    assert len(lines) == 13
    for i in lines:
        segment = run.setup.plan.segments[i]
        p0, p1 = segment.T_start[:3, 3], segment.T_end[:3, 3]
        direction = (p1 - p0) / np.linalg.norm(p1 - p0)
        for q in samples.q[samples.segment == i][::25]:
            pin.framesForwardKinematics(robot.model, data, q)
            placement = data.oMf[robot.tool_frame_id]
            rel = placement.translation - p0
            assert np.linalg.norm(rel - (rel @ direction) * direction) <= LINE_TOL
            approach = placement.rotation @ robot.approach_in_tool
            assert approach[2] == pytest.approx(-1.0, abs=1e-9)  # pen straight down


def test_writing_happens_on_the_table(run) -> None:
    waypoints = run.setup.waypoints
    tool = run.setup.kinematics.tool_poses(np.array([waypoints[n] for n in ("O1", "K3", "K5")]))
    np.testing.assert_allclose(tool[:, 2, 3], 0.030, atol=1e-9)  # z = 30 mm


def test_clearance_is_exact_on_hulls_and_safe_for_the_meshes(run) -> None:
    assert run.collision.collision_free
    assert run.world.pair_is_self.any()  # the arm's own links are checked too
    samples, world = run.samples, run.world
    worst = run.collision.min_clearance
    # Independent: the branch-and-bound profile over every sample of the worst segment.
    segment = samples.segment == int(samples.segment[np.argmin(np.abs(samples.t - worst.time))])
    profile = clearance_profile(world, samples.q[segment])
    assert profile.min() == pytest.approx(worst.clearance, abs=DISTANCE_TOL)
    # The original (non-convex) mesh is never nearer than its hull: coal on the STL itself.
    import coal

    robot = run.setup.arm
    k = int(np.argmin(np.abs(samples.t - worst.time)))
    data, geometry_data = robot.model.createData(), pin.GeometryData(robot.collision_mesh_model)
    pin.forwardKinematics(robot.model, data, samples.q[k])
    pin.updateGeometryPlacements(robot.model, data, robot.collision_mesh_model, geometry_data)
    names = [g.name for g in robot.collision_mesh_model.geometryObjects]
    obstacle = next(o for o in run.setup.obstacles if o.name == worst.obstacle)
    mesh_pose = geometry_data.oMg[names.index(worst.geometry)]
    mesh_distance = coal.distance(
        robot.collision_mesh_model.geometryObjects[names.index(worst.geometry)].geometry,
        coal.Transform3s(mesh_pose.rotation, mesh_pose.translation),
        coal.Box(*obstacle.size),
        coal.Transform3s(np.eye(3), obstacle.centre),
        coal.DistanceRequest(),
        coal.DistanceResult(),
    )
    assert worst.clearance <= mesh_distance + DISTANCE_TOL
    assert worst.clearance >= 0.015  # the scenario's expectation, measured 20.2 mm


def test_a_planned_pen_up_move_of_the_so101(tmp_path) -> None:
    import yaml

    from lynxplan.scenarios import run_scenario

    data = yaml.safe_load(SO101_TASK.read_text())
    for segment in data["segments"]:
        if segment["to"] == "K1_up":
            segment["motion"] = "plan"  # between the letters: planned, verified with coal
    result = run_scenario(data, tmp_path / "out", quick=True)
    assert result.ok, result.failed_expectations
    assert result.metrics["collision_free"] is True
    assert result.metrics["min_clearance"] >= 0.015
