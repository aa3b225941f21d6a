"""Multi-segment plans: the OK task, sampling at any rate, per-segment reports, errors."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.arm.kinematics import forward_kinematics
from lynxplan.exceptions import InputError, PathNotFollowableError
from lynxplan.trajectory import (
    LspbTiming,
    SegmentSpec,
    build_plan,
    line_segment,
    ok_task_configurations,
    ok_task_plan,
    segment_reports,
)


@pytest.fixture(scope="module")
def ok_plan():
    return ok_task_plan()


@pytest.fixture(scope="module")
def ok_samples(ok_plan):
    return ok_plan.sample()


def test_ok_task_is_13_segments_of_2_s(ok_plan) -> None:
    assert len(ok_plan.segments) == 13
    assert ok_plan.duration == pytest.approx(26.0)
    assert [s.kind for s in ok_plan.segments].count("line") == 7
    np.testing.assert_allclose(ok_plan.start_times[:3], [0, 2, 4], atol=1e-12)


def test_samples_at_1khz_pass_through_every_waypoint(ok_plan, ok_samples) -> None:
    assert ok_samples.t.shape == (26001,)
    waypoints = ok_task_configurations()
    for i in range(14):
        k = int(np.argmin(np.abs(ok_samples.t - 2.0 * i)))
        np.testing.assert_allclose(ok_samples.q[k], waypoints[i], atol=1e-9)
        np.testing.assert_allclose(ok_samples.qd[k], 0.0, atol=1e-6)  # rest-to-rest segments
    np.testing.assert_allclose(ok_samples.tool, forward_kinematics(ok_samples.q), atol=0)
    # Continuous joint motion: no jump larger than max speed x period.
    jump = np.abs(np.diff(ok_samples.q, axis=0)).max()
    assert jump <= np.abs(ok_samples.qd).max() * 1e-3 + 1e-12


def test_report_rate_of_10_hz(ok_plan) -> None:
    samples = ok_plan.sample(10.0)
    assert samples.t.shape == (261,)
    np.testing.assert_allclose(samples.t[-1], 26.0, atol=1e-12)


def test_segment_reports_on_the_ok_task(ok_plan, ok_samples) -> None:
    reports = segment_reports(ok_plan, ok_samples)
    assert len(reports) == 13
    for report in reports:
        assert report.limit_violation_samples == 0, report
        assert report.branch_switches == 0
        if report.kind == "line":
            assert report.max_line_deviation <= 1e-9
            assert report.max_orientation_residual < 1e-9
        mask = ok_samples.segment == report.segment
        assert report.max_joint_speed == pytest.approx(np.abs(ok_samples.qd[mask]).max())
        k = np.flatnonzero(ok_samples.t == report.max_joint_speed_time)[0]
        assert abs(ok_samples.qd[k, report.max_joint_speed_joint]) == report.max_joint_speed
    # The last segment (I3 -> home) moves q2 by 90 deg in T = 1.5 s: pi/2 / 1.5 rad/s.
    assert reports[-1].max_joint_speed == pytest.approx(np.pi / 2 / 1.5, rel=1e-9)
    assert reports[-1].max_joint_speed_joint == 1


def test_full_so3_mode_reports_the_roll_violation() -> None:
    plan = ok_task_plan(mode="slerp")
    reports = segment_reports(plan, plan.sample(100.0))
    assert reports[0].limit_violation_joints == (4,)
    assert reports[0].limit_violation_samples > 0


def test_pose_targets_are_solved_by_ik() -> None:
    q = ok_task_configurations()
    specs = [
        SegmentSpec("free", target_pose=forward_kinematics(q[1]), timing=LspbTiming(1.0, 0.3)),
        SegmentSpec("line", target_pose=forward_kinematics(q[2])),
    ]
    plan = build_plan(q[0], specs)
    np.testing.assert_allclose(plan.segments[0].q_end, q[1], atol=1e-9)
    np.testing.assert_allclose(plan.segments[1].q_end, q[2], atol=1e-9)


def test_errors(ok_plan) -> None:
    q = ok_task_configurations()
    with pytest.raises(InputError, match="a plan needs at least one segment"):
        build_plan(q[0], [])
    with pytest.raises(InputError, match="segment 0: give exactly one of target_q and target_pose"):
        build_plan(q[0], [SegmentSpec("free")])
    with pytest.raises(InputError, match="segment 0: unknown kind 'jump'"):
        build_plan(q[0], [SegmentSpec("jump", target_q=q[1])])  # type: ignore[arg-type]
    with pytest.raises(InputError, match="sample rate = 0 is out of range"):
        ok_plan.sample(0.0)
    far = np.eye(4)
    far[:3, 3] = [0, 2.0, 0]
    with pytest.raises(PathNotFollowableError, match=r"segment 0 \(free\) leaves the arm.s reach"):
        build_plan(q[0], [SegmentSpec("free", target_pose=far)])


def test_line_targets_are_checked_once() -> None:
    # A line's poses are FK results or the caller's checked pose: the plan builds the same
    # segment as line_segment, which checks them, and still rejects a bad mode or pose.
    q = ok_task_configurations()
    plan = build_plan(q[0], [SegmentSpec("line", target_q=q[1], timing=LspbTiming(2.0, 0.5))])
    direct = line_segment(
        forward_kinematics(q[0]), forward_kinematics(q[1]), q[0], LspbTiming(2.0, 0.5)
    )
    np.testing.assert_array_equal(plan.segments[0].grid.q, direct.grid.q)
    with pytest.raises(InputError, match="unknown orientation mode 'spline'"):
        build_plan(q[0], [SegmentSpec("line", target_q=q[1], mode="spline")])
    skewed = forward_kinematics(q[1])
    skewed[:3, :3] *= 1.1
    with pytest.raises(InputError, match=r"target_pose"):
        build_plan(q[0], [SegmentSpec("line", target_pose=skewed)])
