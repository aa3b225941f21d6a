"""A branch named "elbow-up" has its elbow joint above the line from the shoulder to the wrist
(along the yaw axis), on every solver path: checked on Pinocchio's joint placements."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from lynxplan.robots import Robot, load_robot
from tests.robots.urdf_factory import write_random_family_urdfs

#: Branches whose elbow is closer than this to the shoulder-wrist line [m] have no clear side.
ON_THE_LINE = 1e-9


def _elbow_above(robot: Robot, q: np.ndarray) -> float:
    """Signed distance [m] of the elbow joint from the shoulder-wrist line in the arm plane,
    positive above (towards the yaw axis' direction), from Pinocchio's joint placements
    (joints 2, 3, 4; their offsets along the pitch axis dropped)."""
    data = robot.model.createData()
    pin.forwardKinematics(robot.model, data, q)
    shoulder, elbow, wrist = (np.array(data.oMi[j].translation) for j in (2, 3, 4))
    assert robot.family is not None
    up = np.array(robot.family.yaw_axis)  # in the base frame
    pin.computeJointJacobians(robot.model, data, q)
    pitch = np.array(pin.getJointJacobian(robot.model, data, 2, pin.WORLD))[3:, 1]  # its axis

    def in_plane(v: np.ndarray) -> np.ndarray:
        return v - (v @ pitch) * pitch

    line, arm = in_plane(wrist - shoulder), in_plane(elbow - shoulder)
    normal = up - (up @ line) / (line @ line) * line  # in the arm plane, towards "up"
    return float(arm @ normal / np.linalg.norm(normal))


def _check(robot: Robot, names: tuple[str, ...], q: np.ndarray, valid: np.ndarray) -> int:
    checked = 0
    for n, b in np.argwhere(valid):
        above = _elbow_above(robot, q[n, b])
        if abs(above) < ON_THE_LINE:
            continue
        assert names[b].endswith("elbow-up" if above > 0 else "elbow-down"), (n, names[b], above)
        checked += 1
    return checked


@pytest.mark.parametrize("count", [200, 10])  # the vectorised block path and the scalar one
def test_full_pose_batches(builtin: Robot, count: int) -> None:
    poses = builtin.fk(builtin.random_configurations(count, seed=5))
    batch = builtin.ik_batch(poses)
    assert _check(builtin, batch.branch_names, batch.q, batch.valid) >= 2 * count


def test_approach_targets_and_single_poses(builtin: Robot) -> None:
    poses = builtin.fk(builtin.random_configurations(40, seed=6))
    batch = builtin.ik_batch(positions=poses[:, :3, 3], approaches=poses[:, :3, 2])
    assert _check(builtin, batch.branch_names, batch.q, batch.valid) >= 80
    back = 0
    for pose in poses[:10]:
        result = builtin.ik(pose)
        for s in result.solutions:
            above = _elbow_above(builtin, s.q)
            if abs(above) >= ON_THE_LINE:
                assert s.branch.endswith("elbow-up" if above > 0 else "elbow-down")
            back += s.branch.startswith("back")
    assert back > 0  # the side where the two-link's sign and the label part


def test_random_family_arms(tmp_path: Path) -> None:
    for path in write_random_family_urdfs(tmp_path, 6, 11):
        robot = load_robot(path, tool="tool")
        poses = robot.fk(robot.random_configurations(40, seed=1))
        batch = robot.ik_batch(poses)
        assert _check(robot, batch.branch_names, batch.q, batch.valid) >= 40
