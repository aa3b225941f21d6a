"""Trajectories of a URDF robot (the SO-101): the approach pitch convention, straight lines checked
by Pinocchio's FK, branch continuity, and the AL5 default left unchanged."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import lynxplan
from lynxplan.exceptions import PathNotFollowableError
from lynxplan.trajectory import LspbTiming, line_segment
from lynxplan.trajectory.kinematics import Al5Kinematics, RobotKinematics
from lynxplan.trajectory.limits import MotionLimits

#: Straight-line deviation and joint-round-trip tolerances [m], [rad].
LINE_TOL = 1e-9
ROUND_TRIP_TOL = 1e-6


@pytest.fixture(scope="module")
def so101():
    robot = lynxplan.load_robot("so101")
    return robot, RobotKinematics(robot)


def _limits(robot) -> MotionLimits:
    return MotionLimits(robot.limits.position, robot.limits.velocity, 8.0, 60.0)


def test_pitch_of_a_configuration_round_trips_through_the_pitch_ik(so101) -> None:
    robot, kinematics = so101
    q = robot.random_configurations(200, seed=3)
    poses = robot.fk(q)
    pitch = np.array([kinematics.pitch(poses[k], q[k]) for k in range(len(q))])
    # Independent definition: the approach axis against the yaw axis and the outward direction
    # of the plane of the pitch joints (Pinocchio's placement of joint 2, axis z in the URDF).
    data = robot.model.createData()
    for k in range(0, len(q), 20):
        pin.forwardKinematics(robot.model, data, q[k])
        pitch_axis = data.oMi[2].rotation[:, 2].copy()
        up = np.array(robot.info().family_parameters.yaw_axis)
        outward = np.cross(pitch_axis, up)
        outward /= np.linalg.norm(outward)
        approach = poses[k, :3, :3] @ robot.approach_in_tool
        assert pitch[k] == pytest.approx(np.arctan2(approach @ outward, -approach @ up), abs=1e-12)
    batch = robot.ik_batch(positions=poses[:, :3, 3], pitches=pitch, rolls=q[:, 4])
    gap = np.nanmin(np.abs(batch.q - q[:, None, :]).max(axis=2), axis=1)
    assert gap.max() <= ROUND_TRIP_TOL


def test_so101_straight_line_is_straight_by_pinocchio_fk_and_continuous(so101) -> None:
    robot, kinematics = so101
    q_start = robot.ik(position=[0.17, 0.05, 0.03], approach=[0, 0, -1], roll=-1.57).q
    T0 = robot.fk(q_start)
    T1 = T0.copy()
    T1[:3, 3] = [0.24, -0.05, 0.03]
    segment = line_segment(
        T0, T1, q_start, LspbTiming(1.2, 0.3), limits=_limits(robot), kinematics=kinematics
    )
    samples = segment.sample(np.linspace(0.0, 1.2, 601))
    data = robot.model.createData()
    p0, p1 = T0[:3, 3], T1[:3, 3]
    direction = (p1 - p0) / np.linalg.norm(p1 - p0)
    for q in samples.q[::10]:
        pin.framesForwardKinematics(robot.model, data, q)
        placement = data.oMf[robot.tool_frame_id]
        rel = placement.translation - p0
        assert np.linalg.norm(rel - (rel @ direction) * direction) <= LINE_TOL
        approach = placement.rotation @ robot.approach_in_tool
        assert approach @ np.array([0.0, 0.0, -1.0]) == pytest.approx(1.0, abs=1e-9)
    assert np.allclose(samples.q[-1, :3], segment.q_end[:3], atol=1e-9)
    assert np.abs(np.diff(samples.q, axis=0)).max() < 0.02  # no branch jump between samples
    roll = samples.q[:, 4]  # from the start's roll to the end pose's, monotonic
    assert roll[0] == pytest.approx(-1.57, abs=1e-12)
    assert np.all(np.diff(roll) * np.sign(roll[-1] - roll[0]) >= -1e-12)
    # The sampled velocities are the time derivatives of the sampled positions.
    rate = np.gradient(samples.q, 1.2 / 600, axis=0)
    assert np.abs(rate[5:-5] - samples.qd[5:-5]).max() <= 2e-3


def test_line_out_of_reach_is_reported(so101) -> None:
    robot, kinematics = so101
    q_start = robot.ik(position=[0.17, 0.05, 0.03], approach=[0, 0, -1], roll=-1.57).q
    T0 = robot.fk(q_start)
    T1 = T0.copy()
    T1[:3, 3] = [0.60, 0.05, 0.03]  # beyond the 0.4 m reach
    with pytest.raises(PathNotFollowableError):
        line_segment(T0, T1, q_start, LspbTiming(1.2, 0.3), kinematics=kinematics)


def test_al5_kinematics_pitch_matches_the_robot_convention_on_the_al5() -> None:
    # The AL5's arm plane contains the base axis: with the tool point on the outward side of the
    # plane (towards q1), both conventions measure the same angle.
    robot = lynxplan.load_robot("al5")
    general, al5 = RobotKinematics(robot), Al5Kinematics()
    compared = 0
    for q in robot.random_configurations(100, seed=5):
        pose = al5.tool_poses(q[None])[0]
        np.testing.assert_allclose(robot.fk(q), pose, atol=1e-12)
        if np.array([np.cos(q[0]), np.sin(q[0])]) @ pose[:2, 3] > 1e-3:
            assert general.pitch(pose, q) == pytest.approx(al5.pitch(pose, q), abs=1e-9)
            compared += 1
    assert compared > 20
