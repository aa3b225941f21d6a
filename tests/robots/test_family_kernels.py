"""The compiled pieces of the family solver against their plain references."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.robots import Robot
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.family_geometry import MODE_APPROACH, MODE_POSE
from lynxplan.robots.ik.family_polish import lu_factor, lu_solve
from lynxplan.robots.ik.roll_equation import (
    SCRATCH_ROWS,
    lateral_miss,
    prepare_roll_terms,
    reference_terms,
    roll_mismatch,
    roll_terms,
)

#: The angle-free roll equation equals the angle form to this (both are sines/components).
EQUATION_AGREEMENT = 1e-12
SOLVE_AGREEMENT = 1e-12


def _scratch(robot: Robot, pose: np.ndarray, mode: int) -> np.ndarray:
    """The kernel's scratch: G = Rt Rt0^T, the approach axis, the roll constants."""
    family = robot.family
    assert family is not None
    rt0 = family.packed[F.RT0 : F.RT0 + 9].reshape(3, 3)
    g = np.empty((SCRATCH_ROWS, 4))
    g[:3, :3] = pose[:3, :3] @ rt0.T
    g[:3, 3] = g[:3, :3] @ np.array(family.roll_axis) if mode == MODE_POSE else pose[:3, 2]
    prepare_roll_terms(family.packed, pose, g)
    return g


@pytest.mark.parametrize("mode", [MODE_POSE, MODE_APPROACH])
def test_roll_terms_match_the_angle_form(so101: Robot, mode: int) -> None:
    family = so101.family
    assert family is not None
    rng = np.random.default_rng(4)
    poses = so101.fk(so101.random_configurations(40, seed=9))
    # also unreachable points (the yaw clamped) and points near the yaw axis
    poses[:10, :3, 3] += rng.normal(scale=0.2, size=(10, 3))
    poses[10:15, :2, 3] = rng.normal(scale=0.01, size=(5, 2))
    if mode == MODE_APPROACH:
        poses[:, :3, 2] = poses[:, :3, :3] @ np.array(family.approach_in_tool)
    for pose in poses:
        g = _scratch(so101, pose, mode)
        for theta in np.linspace(-3.1, 3.1, 25):
            for side in (0, 1):
                problem = (family.packed, pose, g, mode, side, 0.2, 0.3)
                f, c, miss = roll_terms(problem, theta)
                assert abs(f - reference_terms(problem, theta)[0]) <= EQUATION_AGREEMENT
                assert miss >= 0.0
                assert abs(miss - lateral_miss(problem, theta)) <= 1e-15
                if mode == MODE_POSE:
                    assert abs(f * f + c * c - 1.0) <= EQUATION_AGREEMENT
                mismatch = roll_mismatch(problem, theta)
                assert 0.0 <= mismatch <= np.pi


def test_lu_solve_matches_numpy() -> None:
    rng = np.random.default_rng(2)
    for _ in range(50):
        a = rng.normal(size=(5, 5))
        b = rng.normal(size=5)
        expected = np.linalg.solve(a, b)
        lu = np.vstack((a, np.zeros((1, 5))))
        assert lu_factor(lu)
        x = np.empty(5)
        lu_solve(lu, b, x)
        np.testing.assert_allclose(x, expected, atol=SOLVE_AGREEMENT * np.abs(expected).max())


def test_lu_factor_reports_a_singular_matrix() -> None:
    assert not lu_factor(np.ones((6, 5)))
