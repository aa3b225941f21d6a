"""IK of the planar 3-RRR: SPEC reference pose, geometric consistency, batches, error paths."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lynxplan.exceptions import (
    InputError,
    LegUnreachableError,
    NonFiniteInputError,
    ShapeError,
)
from lynxplan.parallel.geometry import ParallelGeometry, pose_from_mm_deg, pose_to_mm_deg
from lynxplan.parallel.ik import (
    WORKING_MODES,
    elbows,
    mode_index,
    platform_joints,
    solve_ik,
    solve_ik_batch,
)

GEOMETRY = ParallelGeometry()
#: SPEC Part 4 reference, pose (260, 180, 30 deg), 4-decimal printout of the report.
REFERENCE_THETA = {
    0: (58.0030, -19.8598),
    1: (159.7404, 84.1763),
    2: (-64.4231, -158.6103),
}
SPEC_ATOL_DEG = 1e-4
GEOMETRY_ATOL_M = 1e-12


def test_working_modes_are_in_report_order() -> None:
    assert WORKING_MODES == ("+++", "++-", "+-+", "+--", "-++", "-+-", "--+", "---")


def test_reference_pose_reproduces_spec_angles() -> None:
    theta = np.degrees(solve_ik(pose_from_mm_deg(260, 180, 30)))
    for m, label in enumerate(WORKING_MODES):
        for leg, sign in enumerate(label):
            expected = REFERENCE_THETA[leg][0 if sign == "+" else 1]
            assert theta[m, leg] == pytest.approx(expected, abs=SPEC_ATOL_DEG)


def test_default_geometry_matches_spec() -> None:
    base = GEOMETRY.base_joints * 1e3
    expected = [[0, 0], [math.sqrt(3) * 290, 0], [math.sqrt(3) / 2 * 290, 435]]
    np.testing.assert_allclose(base, expected, atol=1e-9)
    assert GEOMETRY.leg_reach == pytest.approx((0.040, 0.300))
    np.testing.assert_allclose(pose_to_mm_deg(pose_from_mm_deg(260, 180, 30)), [260, 180, 30])


poses_strategy = st.tuples(
    st.floats(0.10, 0.40), st.floats(0.02, 0.30), st.floats(-math.pi, math.pi)
)


@settings(max_examples=200, deadline=None)
@given(poses_strategy)
def test_every_mode_closes_every_leg(pose: tuple[float, float, float]) -> None:
    result = solve_ik_batch(np.array(pose))
    if not result.reachable.all():
        assert np.isnan(result.angles).any()
        return
    joints = platform_joints(np.array(pose))
    for m in range(8):
        elbow = elbows(result.angles[0, m])
        np.testing.assert_allclose(
            np.linalg.norm(joints - elbow, axis=1), GEOMETRY.distal, atol=GEOMETRY_ATOL_M
        )
        # The acos sign is the side of the elbow: cross(d_i, E_i - B_i) > 0 for "+".
        d = joints - GEOMETRY.base_joints
        arm = elbow - GEOMETRY.base_joints
        cross = d[:, 0] * arm[:, 1] - d[:, 1] * arm[:, 0]
        signs = "".join("+" if c > 0 else "-" for c in cross)
        assert signs == WORKING_MODES[m]


def test_batch_matches_single_and_marks_unreachable() -> None:
    poses = np.array([[0.26, 0.18, 0.5], [2.0, 0.0, 0.0], [0.2, 0.1, -0.3]])
    result = solve_ik_batch(poses)
    assert result.angles.shape == (3, 8, 3)
    np.testing.assert_array_equal(result.angles[0], solve_ik(poses[0]))
    np.testing.assert_array_equal(result.angles[2], solve_ik(poses[2]))
    assert np.isnan(result.angles[1]).any()
    assert result.reason(0) == ""
    assert "leg B" in result.reason(1)
    assert "leg C" in result.reason(1)
    np.testing.assert_allclose(
        result.leg_distance[1],
        np.linalg.norm(platform_joints(poses[1]) - GEOMETRY.base_joints, axis=1),
    )


def test_unreachable_leg_names_leg_and_range() -> None:
    # Platform joint A at (10, 5) mm, 11.18 mm from base joint A; legs B and C reach.
    pose = pose_from_mm_deg(10 + 130 * math.cos(math.radians(30)), 5 + 65, 0)
    match = r"leg A .*distance of 11\.1803 mm, outside the range \[40\.0000, 300\.0000\] mm"
    with pytest.raises(LegUnreachableError, match=match) as info:
        solve_ik(pose)
    assert info.value.leg == "A"
    assert info.value.distance < info.value.min_distance


def test_folded_and_stretched_legs_are_reachable_limits() -> None:
    # Leg A exactly stretched along x: platform joint A at (300 mm, 0).
    rp = GEOMETRY.platform_circumradius
    pose = np.array([0.300 + rp * math.cos(math.radians(30)), rp * math.sin(math.radians(30)), 0.0])
    result = solve_ik_batch(pose)
    assert result.reachable[0, 0]
    assert result.angles[0, 0, 0] == pytest.approx(result.angles[0, 4, 0], abs=1e-6)


@pytest.mark.parametrize(
    ("poses", "error", "match"),
    [
        (np.zeros(4), ShapeError, r"poses must have shape \(3,\) or \(N, 3\)\. Got: \(4,\)"),
        (np.zeros((2, 2)), ShapeError, r"Got: \(2, 2\)"),
        (np.array([0.1, np.nan, 0.0]), NonFiniteInputError, "poses contains NaN"),
    ],
)
def test_batch_input_errors(poses: np.ndarray, error: type[Exception], match: str) -> None:
    with pytest.raises(error, match=match):
        solve_ik_batch(poses)


def test_single_pose_shape_error() -> None:
    with pytest.raises(ShapeError, match=r"pose must have shape \(3,\)"):
        solve_ik(np.zeros((1, 3)))


def test_geometry_validation() -> None:
    with pytest.raises(InputError, match=r"ParallelGeometry\.distal must be a positive length"):
        ParallelGeometry(distal=-0.1)
    with pytest.raises(InputError, match=r"proximal must be a positive length\. Got: nan"):
        ParallelGeometry(proximal=float("nan"))


def test_mode_index() -> None:
    assert mode_index("+-+") == 2
    assert mode_index(7) == 7
    with pytest.raises(InputError, match=r"unknown working mode 'x'; valid modes: \+\+\+"):
        mode_index("x")
    with pytest.raises(InputError, match=r"integer in 0\.\.7\. Got: 8"):
        mode_index(8)


def test_other_geometry_is_used() -> None:
    geometry = ParallelGeometry(proximal=0.2, distal=0.15)
    pose = pose_from_mm_deg(260, 180, 30)
    theta = solve_ik(pose, geometry)
    elbow = elbows(theta[3], geometry)
    np.testing.assert_allclose(
        np.linalg.norm(platform_joints(pose, geometry) - elbow, axis=1), 0.15, atol=GEOMETRY_ATOL_M
    )
