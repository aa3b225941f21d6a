"""Continuous IK in LeRobot units on random smooth streams of tool targets, some of which pass
out of reach: every frame within the limits, every joint step within the bound, the branch kept,
reachable False exactly where the target is out of reach."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.exceptions import InputError
from lynxplan.lerobot import lerobot_units
from lynxplan.lerobot.servo import DEFAULT_FPS, DEFAULT_MAX_VELOCITY
from lynxplan.lerobot.streams import STREAM_FRAMES, target_stream
from lynxplan.lerobot.track import REACHED_TOLERANCE, track_targets
from tests.lerobot.sample import SAMPLE_CALIBRATION

FRAMES = STREAM_FRAMES
#: A point this far from (0, 0, 0.1) m is out of the SO-101's reach (the farthest tool point of
#: 200,000 random configurations within the URDF limits is 0.48 m from it), in [m].
OUT_OF_REACH_RADIUS = 0.6
BOUND = DEFAULT_MAX_VELOCITY / DEFAULT_FPS
#: The streams' pitch (pi/2 - (q2 + q3 + q4)) ignores the SO-101 model's small built-in
#: angles, so the IK lands this near the generating path, in [rad] (the branch is the same).
PATH_ATOL = 1e-3


def stream(robot, seed: int, out_of_reach: bool):
    """Targets (tool point, approach pitch, roll) along a smooth joint path; optionally pushed
    radially far out of reach over frames 30..55 (smoothly in and back)."""
    s = target_stream(
        robot, seed, out_of_reach=out_of_reach, out_of_reach_radius=OUT_OF_REACH_RADIUS
    )
    assert s.q.shape == (FRAMES, robot.nq)
    return s.q, s.positions, s.pitches, s.rolls, s.pushed


@pytest.mark.parametrize("seed", range(6))
def test_streams_stay_continuous_and_within_limits(so101_calibrated, seed):
    robot = so101_calibrated
    units = lerobot_units(robot, SAMPLE_CALIBRATION)
    out_of_reach = seed % 2 == 1
    q_path, positions, pitches, rolls, far = stream(robot, seed, out_of_reach)
    start = units.to_action(q_path[0], 50.0)  # the arm's observation before the stream
    track = track_targets(
        robot, units, positions=positions, pitches=pitches, rolls=rolls, gripper=50.0, start=start
    )
    q = track.q
    assert np.all(np.isfinite(q))
    assert np.all(q >= robot.limits.lower - 1e-12) and np.all(q <= robot.limits.upper + 1e-12)
    steps = np.abs(np.diff(np.vstack((q_path[0], q)), axis=0))
    assert steps.max() <= BOUND * (1 + 1e-12)
    assert track.max_step == pytest.approx(steps.max(), abs=0)
    near = ~far
    if out_of_reach:
        assert far.sum() >= 8
        assert not track.reachable[far].any()
        assert np.all(track.distance[far] > 0.1)
        # before the push the arm follows its path exactly, branch kept
        np.testing.assert_allclose(q[:25], q_path[:25], atol=PATH_ATOL)
    else:
        # a reachable smooth stream from where the arm is: followed, no frame held back
        assert track.reachable.all() and not track.held.any()
        assert np.all(track.distance <= REACHED_TOLERANCE)
        np.testing.assert_allclose(q, q_path, atol=PATH_ATOL)
    # back in reach after the push (or all along): the target is reached again
    assert track.reachable[near][-10:].all()
    assert np.all(track.distance[-10:] <= REACHED_TOLERANCE)
    # LeRobot frames: degrees, gripper channel kept
    frames = track.frames()
    assert len(frames) == FRAMES and frames[0]["gripper.pos"] == 50.0
    np.testing.assert_allclose(units.to_joints(frames).q, q, atol=1e-12)


def test_a_far_first_target_is_a_ramp_not_a_jump(so101_calibrated):
    robot = so101_calibrated
    units = lerobot_units(robot)
    _, positions, pitches, rolls, _ = stream(robot, 11, False)
    track = track_targets(robot, units, positions=positions, pitches=pitches, rolls=rolls)
    steps = np.abs(np.diff(np.vstack((np.zeros(robot.nq), track.q)), axis=0))
    assert steps.max() <= BOUND * (1 + 1e-12)
    assert track.held[0] and track.reachable[0]  # reachable, but the bound holds the frame back
    assert track.distance[-1] <= REACHED_TOLERANCE


def test_bad_input(so101):
    units = lerobot_units(so101)
    with pytest.raises(InputError, match=r"needs poses \(N, 4, 4\) or positions"):
        track_targets(so101, units, pitches=[0.0])
    with pytest.raises(InputError, match=r"pitches: 2 targets expected .* Got: \(3,\)"):
        track_targets(so101, units, positions=np.zeros((2, 3)), pitches=np.zeros(3))
    with pytest.raises(InputError, match=r"fps = 0.*must be finite and > 0"):
        track_targets(so101, units, positions=np.zeros((2, 3)), pitches=np.zeros(2), fps=0)
    with pytest.raises(InputError, match=r"start is outside the robot's joint limits"):
        track_targets(
            so101, units, positions=np.zeros((1, 3)), pitches=[0.0], start=np.full(5, 3.0)
        )
