"""Straight-line segments: tool point on the line, orientation modes, limits, rates, errors."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.arm.ik import solve_ik_batch
from lynxplan.arm.kinematics import forward_kinematics
from lynxplan.exceptions import InputError, PathNotFollowableError, ShapeError
from lynxplan.trajectory import LspbTiming, MotionLimits, line_segment, ok_task_configurations
from lynxplan.trajectory.ok_task import OK_TASK_WAYPOINTS

LINE_TOL = 1e-9  # [m], the bound on the deviation from the line in consistent mode
REPORT = LspbTiming(2.0, 0.5)

Q = ok_task_configurations()
LETTER_LINES = [(i, i + 1) for i, row in enumerate(OK_TASK_WAYPOINTS) if row[2] == "line"]


def _distance_to_line(points: np.ndarray, p0: np.ndarray, p1: np.ndarray) -> np.ndarray:
    u = (p1 - p0) / np.linalg.norm(p1 - p0)
    rel = points - p0
    return np.linalg.norm(np.cross(rel, u), axis=1)


def test_the_ok_task_has_seven_straight_segments() -> None:
    names = [(OK_TASK_WAYPOINTS[i][0], OK_TASK_WAYPOINTS[j][0]) for i, j in LETTER_LINES]
    assert names == [
        ("O1", "O2"), ("O2", "O3"), ("O3", "O4"), ("O4", "O1"),
        ("K1", "K2"), ("K3", "K4"), ("K4", "K5"),
    ]  # fmt: skip


@pytest.mark.parametrize(("i", "j"), LETTER_LINES)
def test_consistent_mode_keeps_the_tool_on_the_line_and_joints_in_limits(i: int, j: int) -> None:
    T0, T1 = forward_kinematics(Q[i]), forward_kinematics(Q[j])
    segment = line_segment(T0, T1, Q[i], REPORT)
    samples = segment.sample(np.linspace(0, 2, 2001))
    tool = forward_kinematics(samples.q)[:, :3, 3]
    assert _distance_to_line(tool, T0[:3, 3], T1[:3, 3]).max() <= LINE_TOL
    limits = MotionLimits().position
    assert np.all(samples.q >= limits[:, 0] - 1e-12), "a joint dips below its lower limit"
    assert np.all(samples.q <= limits[:, 1] + 1e-12), "a joint exceeds its upper limit"
    # Ends at the next waypoint (the waypoints are exact FK, so the same branch reaches it).
    np.testing.assert_allclose(samples.q[-1], Q[j], atol=1e-9)
    np.testing.assert_allclose(samples.q[0], Q[i], atol=1e-9)
    assert np.all(samples.branch == samples.branch[0])
    assert samples.orientation_residual.max() < 1e-9


def test_consistent_mode_interpolates_pitch_and_roll_linearly_in_s() -> None:
    q_end = Q[1].copy()
    q_end[4] = 0.6  # give the roll something to do
    segment = line_segment(forward_kinematics(Q[0]), forward_kinematics(q_end), Q[0], REPORT)
    s = np.linspace(0, 1, 51)
    q = segment.joint_path(s)
    pitch = q[:, 1] + q[:, 2] + q[:, 3]
    expected = pitch[0] + s * (pitch[-1] - pitch[0])
    np.testing.assert_allclose(pitch, expected, atol=1e-12)
    np.testing.assert_allclose(q[:, 4], 0.6 * s, atol=1e-12)


def test_full_so3_modes_dip_the_roll_below_its_limit_on_the_letter_o() -> None:
    T0, T1 = forward_kinematics(Q[0]), forward_kinematics(Q[1])
    for mode in ("slerp", "lerp", "drive"):
        samples = line_segment(T0, T1, Q[0], REPORT, mode=mode).sample(np.linspace(0, 2, 401))
        assert samples.q[:, 4].min() < -1e-3, mode  # the trap the consistent mode avoids
        tool = forward_kinematics(samples.q)[:, :3, 3]
        assert _distance_to_line(tool, T0[:3, 3], T1[:3, 3]).max() <= LINE_TOL
        assert samples.orientation_residual.max() > 1e-5  # projected: honestly reported


@pytest.mark.parametrize("mode", ["slerp", "lerp", "drive"])
def test_orientation_modes_interpolate_between_the_end_poses(mode: str) -> None:
    T0 = forward_kinematics(np.array([1.0, 0.8, -1.2, 0.9, 0.3]))
    T1 = forward_kinematics(np.array([1.6, 0.6, -0.9, 1.2, 1.4]))
    segment = line_segment(T0, T1, [1.0, 0.8, -1.2, 0.9, 0.3], REPORT, mode=mode)
    poses = segment.targets(np.array([0.0, 0.5, 1.0]))
    np.testing.assert_allclose(poses[0], T0, atol=1e-12)
    np.testing.assert_allclose(poses[2], T1, atol=1e-12)
    # Every interpolated rotation is orthonormal.
    R = poses[1, :3, :3]
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    if mode == "slerp":  # geodesic midpoint: half the angle from both ends

        def angle(A: np.ndarray, B: np.ndarray) -> float:
            return float(np.arccos(np.clip((np.trace(A.T @ B) - 1) / 2, -1, 1)))

        total = angle(T0[:3, :3], T1[:3, :3])
        assert angle(T0[:3, :3], R) == pytest.approx(total / 2, abs=1e-9)
        assert angle(R, T1[:3, :3]) == pytest.approx(total / 2, abs=1e-9)
    if mode == "drive":  # Paul: the approach axis swings in one plane (about a fixed vector k)
        a = poses[:, :3, 2]
        assert abs(np.linalg.det(a)) < 1e-12


def test_sampled_rates_match_finite_differences_of_the_positions() -> None:
    segment = line_segment(forward_kinematics(Q[9]), forward_kinematics(Q[10]), Q[9], REPORT)
    t = np.linspace(0, 2, 20001)
    samples = segment.sample(t)
    # Central differences are exact to O(dt^2) except across the acceleration steps.
    steps = np.min(np.abs(t[:, None] - np.array([0.0, 0.5, 1.5, 2.0])), axis=1) > 1e-3
    qd = np.gradient(samples.q, t, axis=0)
    np.testing.assert_allclose(samples.qd[steps], qd[steps], atol=1e-7)
    qdd = np.gradient(samples.qd, t, axis=0)
    np.testing.assert_allclose(samples.qdd[steps], qdd[steps], atol=1e-4)


def test_auto_timed_line_stays_within_the_limits_on_its_samples() -> None:
    limits = MotionLimits(acceleration=4.0)
    segment = line_segment(forward_kinematics(Q[0]), forward_kinematics(Q[1]), Q[0], limits=limits)
    samples = segment.sample(np.linspace(0, segment.duration, 5001))
    ratio_v = np.abs(samples.qd).max(0) / limits.velocity
    ratio_a = np.abs(samples.qdd).max(0) / limits.acceleration
    assert max(ratio_v.max(), ratio_a.max()) <= 1 + 1e-3
    assert max(ratio_v.max(), ratio_a.max()) >= 0.99  # shortest: some limit is reached


def test_the_reports_straight_line_example() -> None:
    q0 = np.array([2 * np.pi / 3, 0, 0, 0, 0])
    q1 = np.radians([75.0, 30.0, -30.0, 0.0, 0.0])
    T0, T1 = forward_kinematics(q0), forward_kinematics(q1)
    segment = line_segment(T0, T1, q0, LspbTiming(3.0, 1.0))
    samples = segment.sample(np.linspace(0, 3, 3001))
    tool = forward_kinematics(samples.q)[:, :3, 3]
    assert _distance_to_line(tool, T0[:3, 3], T1[:3, 3]).max() <= LINE_TOL
    np.testing.assert_allclose(tool[-1], T1[:3, 3], atol=1e-12)


def test_errors() -> None:
    T0 = forward_kinematics(Q[0])
    with pytest.raises(InputError, match="unknown orientation mode 'spline'; valid modes"):
        line_segment(T0, T0, Q[0], REPORT, mode="spline")
    with pytest.raises(InputError, match=r"T_start is [\d.]+ mm from the tool point of q_start"):
        line_segment(forward_kinematics(Q[1]), T0, Q[0], REPORT)
    far = T0.copy()
    far[:3, 3] = [0.0, 1.0, 0.0]  # 1 m away: out of reach
    with pytest.raises(PathNotFollowableError, match=r"out of reach|leaves the arm's reach"):
        line_segment(T0, far, Q[0], REPORT)
    with pytest.raises(ShapeError, match=r"q_start must have shape \(5,\)"):
        line_segment(T0, T0, Q[0][:4], REPORT)
    with pytest.raises(ShapeError, match=r"T_end must have shape \(4, 4\)"):
        line_segment(T0, T0[:3], Q[0], REPORT)


def test_path_leaving_the_reach_names_where() -> None:
    # Pen pointing down; the line passes over the shoulder, where the wrist centre would come
    # closer to it than |a2 - a3| (the reach hole); both ends are reachable.
    T0, T1 = np.eye(4), np.eye(4)
    T0[:3, :3] = T1[:3, :3] = np.diag([1.0, -1.0, -1.0])
    T0[:3, 3], T1[:3, 3] = [0.15, 0.02, -0.0857], [-0.15, 0.02, -0.0857]
    ik = solve_ik_batch(T0)
    q0 = ik.q[0][ik.within_limits[0]][0]
    with pytest.raises(
        PathNotFollowableError, match=r"leaves the arm's reach at s = 0\.\d+"
    ) as info:
        line_segment(T0, T1, q0, REPORT)
    assert 0.3 < info.value.s < 0.7
    assert info.value.reach_miss > 0.0


def test_zero_length_line_is_stationary() -> None:
    T0 = forward_kinematics(Q[0])
    segment = line_segment(T0, T0, Q[0])  # auto-timed: the stationary timing
    samples = segment.sample(np.linspace(0, segment.duration, 5))
    np.testing.assert_allclose(samples.q, np.tile(Q[0], (5, 1)), atol=1e-12)
    np.testing.assert_allclose(samples.qd, 0.0, atol=1e-9)
