"""Analytic IK: round trips over a million configurations, SPEC examples, special cases, errors."""

from __future__ import annotations

import numpy as np
import pytest
from arm_reference import INCH, random_configurations, rotation_angle
from hypothesis import given, settings
from hypothesis import strategies as st

from lynxplan.arm import BRANCH_NAMES, IkStatus, forward_kinematics, solve_ik_batch
from lynxplan.exceptions import (
    NonFiniteInputError,
    NoSolutionWithinLimitsError,
    NotRigidTransformError,
    OrientationNotReachableError,
    OutOfRangeError,
    ShapeError,
    UnreachablePoseError,
)

POSE_TOLERANCE = 1e-9  # [m] and [rad]: FK of every branch reproduces the target
PRINTOUT_TOLERANCE = np.radians(0.02)  # poses typed with 4 decimals


def rotate_about(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues rotation matrix."""
    axis = axis / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def assert_branches_reproduce(q_all: np.ndarray, targets: np.ndarray) -> None:
    """FK of every branch (N, 4, 5) reproduces its target pose (N, 4, 4)."""
    reached = forward_kinematics(q_all.reshape(-1, 5)).reshape(-1, 4, 4, 4)
    position = np.linalg.norm(reached[..., :3, 3] - targets[:, None, :3, 3], axis=-1)
    angle = rotation_angle(targets[:, None, :3, :3], reached[..., :3, :3])
    assert position.max() <= POSE_TOLERANCE, position.max()
    assert angle.max() <= POSE_TOLERANCE, angle.max()


def test_round_trip_million_configurations(arm) -> None:
    rng = np.random.default_rng(2024)
    for _ in range(5):  # 5 chunks of 200,000 configurations
        q = random_configurations(rng, 200_000, arm.limits.lower, arm.limits.upper)
        targets = forward_kinematics(q)
        batch = arm.ik_batch(targets, limit_tolerance=0.0)
        assert (batch.status == IkStatus.OK).all()
        assert batch.orientation_error.max() <= POSE_TOLERANCE
        assert_branches_reproduce(batch.q, targets)
        # The original configuration is among the within-limit branches (away from the
        # stretched elbow, where q3 is ill-conditioned: d q3 ~ sqrt(eps)).
        distance = np.abs(batch.q - q[:, None, :]).max(axis=2)
        distance[~batch.within_limits] = np.inf
        regular = np.abs(np.sin(q[:, 2])) > 1e-3
        assert distance.min(axis=1)[regular].max() <= 1e-7


@pytest.mark.parametrize("q", [(3, 2, -0.2, 1, 0), (0.2, 2.5, -2, 1, 0), (0.2, 0.3, -0.8, 0.23, 0)])
def test_report_round_trip_examples(arm, q: tuple[float, ...]) -> None:
    target = arm.fk(np.array(q))
    result = arm.ik(target)
    for solution in result.solutions:
        assert solution.position_error <= POSE_TOLERANCE
        assert solution.orientation_error <= POSE_TOLERANCE
    np.testing.assert_allclose(result.q, q, atol=1e-12)
    assert result.solutions[result.selected].within_limits


@pytest.mark.parametrize(
    ("name", "pose", "expected_deg"),
    [
        (
            "O2",
            [
                [-0.3196, 0.9455, -0.0621, -2.8966],
                [0.9281, 0.3256, 0.1804, 8.4123],
                [0.1908, 0, -0.9816, 0.5472],
            ],
            (109, 79, -93, 25, 0),
        ),
        (
            "K4",
            [
                [0.1769, 0.9816, 0.0715, 2.0132],
                [0.9101, -0.1908, 0.3677, 10.3571],
                [0.3746, 0, -0.9272, 1.3752],
            ],
            (79, 70, -77, 29, 0),
        ),
        (
            "I3",
            [[0, 0.5, 0.866, 6.1163], [0, -0.866, 0.5, 3.5312], [1, 0, 0, 12.1369]],
            (30, 90, -30, 30, 0),
        ),
    ],
)
def test_printed_report_poses(arm, name: str, pose: list, expected_deg: tuple) -> None:
    T = np.vstack([np.array(pose, dtype=float), [0, 0, 0, 1]])
    T[:3, 3] *= INCH
    result = arm.ik(T, select="report")
    np.testing.assert_allclose(
        np.degrees(result.q), expected_deg, atol=np.degrees(PRINTOUT_TOLERANCE)
    )
    assert result.orientation_residual < 1e-3  # 4-decimal rounding only


def test_every_branch_flagged_and_named(arm) -> None:
    result = arm.ik(arm.fk(np.radians([120, 60, -45, 45, 0])))
    assert tuple(s.branch for s in result.solutions) == BRANCH_NAMES
    assert [s.within_limits for s in result.solutions] == [True, False, False, False]
    # Back branches differ by a half turn of the base and of the roll.
    assert np.isclose(result.solutions[2].q[0] + np.pi, result.solutions[0].q[0])


def test_back_branch_within_limits_when_leaning_back(arm) -> None:
    q = np.radians([10, 120, -20, 100, 170])  # tool behind the base: r < 0
    result = arm.ik(arm.fk(q))
    np.testing.assert_allclose(result.q, q, atol=1e-12)
    assert result.solutions[result.selected].branch.startswith("back")


def test_nearest_selection_follows_reference(arm) -> None:
    q = np.radians([90, 40, -100, 80, 20])
    T = arm.fk(q)
    result = arm.ik(T)
    elbow_down = next(s for s in result.solutions if s.branch == "front/elbow-down")
    if elbow_down.within_limits:
        chosen = arm.ik(T, q_reference=elbow_down.q)
        np.testing.assert_allclose(chosen.q, elbow_down.q)
    np.testing.assert_allclose(arm.ik(T, q_reference=q).q, q, atol=1e-12)


def test_report_rule_selects_q2_nonnegative_q3_nonpositive(arm) -> None:
    result = arm.ik(arm.fk(np.radians([45, 30, -60, 90, 10])), select="report")
    assert result.q[1] >= 0
    assert result.q[2] <= 0


def test_no_solution_within_limits(arm) -> None:
    result = arm.ik(arm.fk(np.radians([-30, 60, -45, 45, 0])))  # q1 = -30 deg is outside
    assert result.selected is None
    with pytest.raises(NoSolutionWithinLimitsError, match="no branch is within the joint limits"):
        _ = result.q


def test_limit_snapping_accepts_printout_rounding(arm) -> None:
    q = np.radians([100, 50, -60, 40, 0])
    q_outside = q.copy()
    q_outside[4] = np.radians(-0.002)  # the report's q5 = -0.002 deg
    T = arm.fk(q_outside)
    assert arm.ik(T).q[4] == 0.0  # snapped onto the limit
    assert arm.ik(T, limit_tolerance=0.0).selected is None


def test_base_axis_keeps_reference_q1(arm) -> None:
    T = np.eye(4)
    T[:3, :3] = np.diag([1.0, -1.0, -1.0])  # approach straight down
    T[:3, 3] = [0.0, 0.0, 0.05]
    reference = np.radians([70, 0, 0, 0, 0])
    result = arm.ik(T, q_reference=reference)
    for solution in result.solutions[:2]:
        assert np.isclose(solution.q[0], reference[0])
    assert max(s.position_error for s in result.solutions) <= POSE_TOLERANCE
    assert max(s.orientation_error for s in result.solutions) <= POSE_TOLERANCE


def test_base_axis_faces_leaning_approach(arm) -> None:
    q = np.radians([60, 100, -40, 120, 30])  # place the tool point on the base axis:
    T = arm.fk(q)
    T[:2, 3] = 0.0  # move it onto the axis, keep the orientation (approach leans along q1)
    result = arm.ik(T)
    assert result.orientation_residual <= POSE_TOLERANCE
    assert min(s.position_error for s in result.solutions) <= POSE_TOLERANCE


def test_stretched_elbow(arm) -> None:
    q = np.radians([80, 30, 0, 50, 10])  # q3 = 0: elbow fully stretched
    result = arm.ik(arm.fk(q))
    up, down = result.solutions[0].q, result.solutions[1].q
    np.testing.assert_allclose(up, down, atol=1e-7)
    np.testing.assert_allclose(result.q, q, atol=1e-7)
    assert max(s.position_error for s in result.solutions) <= POSE_TOLERANCE


@pytest.mark.parametrize("q1_deg", [120.0, 45.0, 10.0, 170.0])
def test_straight_arm_is_exactly_straight(arm, q1_deg: float) -> None:
    # the last digits of the elbow cosine decide up to 1e-7 rad there: both elbows are the same
    # straight branch (q3 = 0 exactly), so a path from the home pose keeps its branch
    q = np.array([np.radians(q1_deg), 0.0, 0.0, 0.0, 0.0])
    batch = solve_ik_batch(arm.fk(q))
    assert batch.q[0, 0, 2] == 0.0 and batch.q[0, 1, 2] == 0.0
    np.testing.assert_array_equal(batch.q[0, 0], batch.q[0, 1])
    np.testing.assert_allclose(batch.q[0, 0], q, atol=1e-12)
    assert batch.within_limits[0, 0] and batch.within_limits[0, 1]


def test_folded_elbow(arm) -> None:
    q = np.array([1.0, 0.5, -np.pi, 0.4, 0.2])  # elbow folded back onto the upper arm
    result = arm.ik(arm.fk(q))
    assert max(s.position_error for s in result.solutions) <= POSE_TOLERANCE
    assert not any(s.within_limits for s in result.solutions)  # q3 = -180 deg is outside


def test_just_beyond_reach_is_clamped(arm) -> None:
    T = arm.fk(np.radians([90, 30, 0, 60, 0]))
    radial = np.array([T[0, 3], T[1, 3], 0.0])
    T[:3, 3] += 1e-7 * radial / np.linalg.norm(radial)  # 0.1 um beyond the stretched reach
    result = arm.ik(T)
    assert result.solutions[0].position_error <= 2e-7


def test_out_of_reach_reports_distance(arm) -> None:
    T = arm.fk(np.radians([90, 30, 0, 60, 0]))
    shoulder_to_wrist = T[:3, 3] - arm.geometry.d5 * T[:3, 2]
    T[:3, 3] += 0.001 * shoulder_to_wrist / np.linalg.norm(shoulder_to_wrist)
    with pytest.raises(UnreachablePoseError, match=r"misses the arm's reach by 1 mm") as info:
        arm.ik(T)
    assert np.isclose(info.value.distance, 0.001, atol=1e-12)
    batch = arm.ik_batch(T)
    assert batch.status[0] == IkStatus.OUT_OF_REACH
    assert np.isnan(batch.q).all()


def test_orientation_projection_and_strict_mode(arm) -> None:
    T = arm.fk(np.radians([70, 60, -90, 60, 40]))
    tilted = T.copy()
    radial = np.array([T[0, 3], T[1, 3], 0.0])
    tilted[:3, :3] = rotate_about(radial, 0.05) @ T[:3, :3]  # approach leaves the arm plane
    result = arm.ik(tilted)
    assert result.orientation_residual > 0.01
    for solution in result.solutions:
        assert solution.position_error <= POSE_TOLERANCE  # the position stays exact
        assert np.isclose(solution.orientation_error, result.orientation_residual, atol=1e-12)
    with pytest.raises(OrientationNotReachableError, match="exceeds the strict tolerance"):
        arm.ik(tilted, strict=True)
    assert arm.ik(T, strict=True).orientation_residual <= 1e-12


def test_position_and_approach_target(arm) -> None:
    q = np.radians([70, 60, -90, 60, 40])
    T = arm.fk(q)
    T5 = T.copy()
    T5[:3, 0] = T5[:3, 1] = 0.0  # only the approach axis is given
    result = arm.ik(T5, approach_only=True, q_reference=np.radians([0, 0, 0, 0, 25]))
    assert result.orientation_residual <= POSE_TOLERANCE
    np.testing.assert_allclose(result.q[:4], q[:4], atol=1e-12)
    assert np.isclose(result.q[4], np.radians(25))


def test_nearly_rigid_rotation_is_repaired(arm) -> None:
    T = arm.fk(np.radians([100, 50, -60, 40, 20]))
    T[:3, :3] *= 1.0002  # R^T R - I = 4e-4 on the diagonal
    result = arm.ik(T)
    assert result.solutions[0].position_error <= POSE_TOLERANCE


def test_non_rigid_rotation_is_rejected(arm) -> None:
    T = arm.fk(np.radians([100, 50, -60, 40, 20]))
    T[0, 0] += 0.05
    with pytest.raises(NotRigidTransformError, match="not a rigid transform"):
        arm.ik(T)
    T = arm.fk(np.radians([100, 50, -60, 40, 20]))
    T[3, 0] = 1.0
    with pytest.raises(NotRigidTransformError, match="not a rigid transform"):
        arm.ik(T)


def test_nan_pose_is_rejected(arm) -> None:
    T = arm.fk(np.zeros(5))
    T[1, 3] = np.nan
    with pytest.raises(NonFiniteInputError, match="T contains NaN"):
        arm.ik(T)
    assert solve_ik_batch(T).status[0] == IkStatus.NON_FINITE


@pytest.mark.parametrize("bad", [np.eye(3), np.zeros((2, 4, 3))])
def test_wrong_pose_shape_is_rejected(arm, bad: np.ndarray) -> None:
    with pytest.raises(ShapeError, match="T must have shape"):
        arm.ik(bad)


def test_bad_reference_is_rejected(arm) -> None:
    with pytest.raises(ShapeError, match=r"q_reference must have shape \(5,\)"):
        arm.ik(np.eye(4), q_reference=np.zeros(3))


def test_batch_results_are_read_only(arm) -> None:
    batch = arm.ik_batch(arm.fk(np.zeros((2, 5))))
    with pytest.raises(ValueError, match="read-only"):
        batch.q[0, 0, 0] = 1.0


@settings(max_examples=300, deadline=None)
@given(st.lists(st.floats(-np.pi, np.pi, allow_subnormal=False), min_size=5, max_size=5))
def test_round_trip_property_any_configuration(q_list: list[float]) -> None:
    """Any configuration, in limits or not: every branch reproduces the pose."""
    q = np.array(q_list)
    T = forward_kinematics(q)
    batch = solve_ik_batch(T, limit_tolerance=0.0)
    assert batch.status[0] == IkStatus.OK
    assert_branches_reproduce(batch.q, T[None])


def test_bottom_row_error_is_named(arm) -> None:
    T = arm.fk(np.radians([100, 50, -60, 40, 20]))
    T[3, 3] = 2.0
    with pytest.raises(NotRigidTransformError, match=r"last row must be 0 0 0 1\) .* off by 1"):
        arm.ik(T)


def test_huge_translation_is_out_of_reach_not_garbage(arm) -> None:
    T = arm.fk(np.zeros(5))
    T[0, 3] = 1e160
    with pytest.raises(OutOfRangeError, match=r"T translation = 1e\+160 is out of range"):
        arm.ik(T)  # beyond the documented range of positions (lynxplan.guards): bad input
    T[0, 3] = 999.0
    with pytest.raises(UnreachablePoseError, match="out of reach"):
        arm.ik(T)
    assert solve_ik_batch(T).status[0] == IkStatus.OUT_OF_REACH


def test_two_solutions_within_limits_nearest_and_report_rule_differ(arm) -> None:
    # On q1 = 0 the back branch (q1 = 180 deg) is within limits too.
    q = np.radians([0, 100, -40, 120, 0])
    result = arm.ik(arm.fk(q))
    within = [s for s in result.solutions if s.within_limits]
    assert len(within) == 2
    other = next(s for s in within if not np.allclose(s.q, q, atol=1e-9))
    np.testing.assert_allclose(arm.ik(arm.fk(q), q_reference=q).q, q, atol=1e-12)
    np.testing.assert_allclose(arm.ik(arm.fk(q), q_reference=other.q).q, other.q, atol=1e-12)
    report = arm.ik(arm.fk(q), q_reference=other.q, select="report").q
    assert report[1] >= 0
    assert report[2] <= 0
    np.testing.assert_allclose(report, q, atol=1e-12)  # the report's rule ignores the reference
