"""Rotation helpers (scipy) against Pinocchio's quaternions, exp3 and slerp."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

from lynxplan.trajectory.rotations import (
    axis_angle_matrix,
    component_blend,
    drive_transforms,
    matrix_to_quaternion,
    quaternion_to_matrix,
    slerp,
)

ATOL = 1e-12


def _random_rotations(count: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.stack([pin.exp3(v) for v in rng.normal(size=(count, 3)) * 1.5])


def test_quaternion_round_trip_and_pinocchio_convention() -> None:
    rotations = _random_rotations(20)
    quaternions = matrix_to_quaternion(rotations)
    assert quaternions.shape == (20, 4)
    assert np.all(quaternions[:, 0] >= 0.0)
    np.testing.assert_allclose(quaternion_to_matrix(quaternions), rotations, atol=ATOL)
    for R, q in zip(rotations, quaternions, strict=True):
        reference = pin.Quaternion(R)
        expected = np.array([reference.w, reference.x, reference.y, reference.z])
        np.testing.assert_allclose(q, expected * np.sign(expected[0]), atol=ATOL)


def test_quaternion_to_matrix_normalises() -> None:
    q = matrix_to_quaternion(_random_rotations(1, seed=3))[0]
    np.testing.assert_allclose(quaternion_to_matrix(3.0 * q), quaternion_to_matrix(q), atol=ATOL)


def test_axis_angle_is_exp3() -> None:
    axis = np.array([1.0, -2.0, 0.5]) / np.linalg.norm([1.0, -2.0, 0.5])
    angles = np.linspace(-3.0, 3.0, 7)
    expected = np.stack([pin.exp3(axis * a) for a in angles])
    np.testing.assert_allclose(axis_angle_matrix(axis, angles), expected, atol=ATOL)


@pytest.mark.parametrize("seed", [1, 2, 5])
def test_slerp_matches_pinocchio_and_takes_the_short_way(seed: int) -> None:
    R0, R1 = _random_rotations(2, seed)
    q0, q1 = matrix_to_quaternion(np.stack([R0, R1]))
    s = np.linspace(0.0, 1.0, 9)
    path = quaternion_to_matrix(slerp(q0, -q1, s))  # the sign of q1 must not matter
    p0, p1 = pin.Quaternion(R0), pin.Quaternion(R1)
    for k, sk in enumerate(s):
        np.testing.assert_allclose(path[k], p0.slerp(sk, p1).matrix(), atol=1e-10)
    # Constant angular rate: equal angles between consecutive samples.
    steps = [np.linalg.norm(pin.log3(path[k].T @ path[k + 1])) for k in range(len(s) - 1)]
    np.testing.assert_allclose(steps, steps[0], atol=1e-10)


def test_component_blend_is_the_report_formula() -> None:
    q0 = np.array([1.0, 0.0, 0.0, 0.0])
    q1 = -np.array([0.6, 0.8, 0.0, 0.0])  # negated: the blend flips it to the short way
    np.testing.assert_allclose(component_blend(q0, q1, np.array([0.5])), [[0.8, 0.4, 0.0, 0.0]])


def test_drive_transform_ends_at_both_poses() -> None:
    T_a, T_b = np.eye(4), np.eye(4)
    T_a[:3, :3], T_b[:3, :3] = _random_rotations(2, seed=7)
    T_a[:3, 3], T_b[:3, 3] = [0.1, 0.2, 0.3], [0.2, -0.1, 0.25]
    poses = drive_transforms(T_a, T_b, np.array([0.0, 1.0]))
    np.testing.assert_allclose(poses[0], T_a, atol=ATOL)
    np.testing.assert_allclose(poses[1], T_b, atol=1e-10)
