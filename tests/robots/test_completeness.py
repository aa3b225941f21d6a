"""Branch completeness: every solution a dense multi-start numerical search finds is a branch."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lynxplan.robots import Robot, load_robot
from lynxplan.robots.ik.numerical import NumericalArm, NumericalResult, numerical_ik_kernel

STARTS = 400
TARGETS = 12


def _dense_search(robot: Robot, pose: np.ndarray, approach_only: bool) -> np.ndarray:
    """Levenberg-Marquardt from STARTS random configurations, each on its own; converged ones."""
    rng = np.random.default_rng(1)
    starts = rng.uniform(robot.limits.lower, robot.limits.upper, size=(STARTS, robot.nq))
    targets = np.repeat(pose[None], STARTS, axis=0)
    arm = NumericalArm(
        robot.chain.placements,
        robot.chain.axes,
        robot.limits.lower.copy(),
        robot.limits.upper.copy(),
        np.array([0.0, 0.0, 1.0]),
    )
    result = NumericalResult.empty(STARTS, robot.nq)
    numerical_ik_kernel(arm, targets, approach_only, starts, np.empty((0, robot.nq)), result)
    return result.q[result.success]


@pytest.mark.parametrize("name", ["so101", "so100", "al5"])
def test_full_pose_branches_are_complete(name: str) -> None:
    robot = load_robot(name)
    found_total = 0
    for q0 in robot.random_configurations(TARGETS, seed=17):
        pose = robot.fk(q0)
        result = robot.ik(pose)
        exact = [s.q for s in result.solutions if s.within_limits and s.orientation_error < 1e-9]
        for q in _dense_search(robot, pose, approach_only=False):
            gaps = [np.abs(q - b).max() for b in exact]
            assert gaps, (q0, q)
            assert min(gaps) < 1e-6, (q0, q)
            found_total += 1
    assert found_total > TARGETS * 10  # the search did converge, many times


def test_approach_branches_are_complete_off_axis_tool(tmp_path: Path) -> None:
    """Position + approach with the roll free: every root of an off-axis tool's roll equation.

    The arm is a random yaw-pitch^3-roll URDF whose tool z axis is the roll axis, so the
    numerical search (which matches the tool z axis) solves the same problem.
    """
    from tests.robots.urdf_factory import random_family_urdf

    checked = 0
    rng = np.random.default_rng(8)
    for k in range(4):
        path = tmp_path / f"arm{k}.urdf"
        path.write_text(random_family_urdf(rng, off_axis_tool=True, approach_is_z=True))
        robot = load_robot(path, tool="tool")
        assert robot.family is not None
        assert not robot.family.tool_on_roll_axis
        np.testing.assert_allclose(robot.approach_in_tool, [0, 0, 1], atol=1e-12)
        for q0 in robot.random_configurations(TARGETS // 2, seed=23):
            pose = robot.fk(q0)
            result = robot.ik(position=pose[:3, 3], approach=pose[:3, 2])
            exact = [
                s.q for s in result.solutions if s.within_limits and s.orientation_error < 1e-9
            ]
            for q in _dense_search(robot, pose, approach_only=True):
                gaps = [np.abs(q - b).max() for b in exact]
                assert gaps, (q0, q)
                assert min(gaps) < 1e-6, (q0, q)
                checked += 1
    assert checked > 50
