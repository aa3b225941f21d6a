"""Full poses solved through the orientation (``pose_kernel``) against the roll root search.

The closed form from the orientation must give exactly the exact branches the general kernel
(roll root search, Newton polish, near-axis rescue) gives, on random poses, poses near the yaw
axis and random family URDFs; the single-pose path must agree with the batch.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lynxplan.robots import Robot, load_robot
from lynxplan.robots.ik import family_solver
from lynxplan.robots.results import BranchSlots
from lynxplan.robots.targets import make_target
from tests.robots.urdf_factory import write_random_family_urdfs

#: Exact branches: reach the pose to these [m], [rad] (the completeness test's criterion).
EXACT = 1e-9


def _general(robot: Robot, poses: np.ndarray) -> list[np.ndarray]:
    """The exact branches of each pose from the general kernel (root search + rescue)."""
    target = make_target(poses)
    n, slots = poses.shape[0], 4 * family_solver.fk_.MAX_ROOTS
    assert robot.family is not None
    if robot.family.tool_on_roll_axis:
        slots = 4
    out = BranchSlots.empty(n, slots)
    family_solver._kernel(robot.kinematics, target, robot._default_reference, out)
    family_solver.rescue_near_axis(robot.kinematics, target, out)
    q, valid, _, perr, oerr = out
    exact = valid & (perr <= EXACT) & (oerr <= EXACT)
    return [q[i][exact[i]] for i in range(n)]


def _same_sets(a: np.ndarray, b: np.ndarray) -> bool:
    if len(a) != len(b):
        return False
    return all(np.abs(b - x).max(axis=1).min() < 1e-7 for x in a)


def _near_axis_poses(robot: Robot, count: int, seed: int) -> np.ndarray:
    """Poses whose tool point is within 4 cm of the yaw axis (where the yaw is sensitive)."""
    assert robot.family is not None
    q = robot.random_configurations(100 * count, seed=seed)
    poses = robot.fk(q)
    k = np.array(robot.family.yaw_axis)
    d = poses[:, :3, 3] - robot.family.packed[0:3]
    rho = np.linalg.norm(d - np.outer(d @ k, k), axis=1)
    return np.ascontiguousarray(poses[rho < 0.04][:count])


@pytest.mark.parametrize("name", ["so101", "so100"])
def test_orientation_closed_form_matches_root_search(name: str) -> None:
    robot = load_robot(name)
    poses = np.concatenate(
        (robot.fk(robot.random_configurations(1500, seed=11)), _near_axis_poses(robot, 400, 12))
    )
    batch = robot.ik_batch(poses)
    general = _general(robot, poses)
    for i, pose in enumerate(poses):
        ours = batch.q[i][
            batch.valid[i]
            & (batch.position_error[i] <= EXACT)
            & (batch.orientation_error[i] <= EXACT)
        ]
        assert len(ours) > 0, i  # every pose here comes from FK: reachable
        assert _same_sets(ours, general[i]), (i, ours, general[i])
        if i % 50 == 0:  # the single-pose path gives the same branches, one selected
            one = robot.ik(pose)
            assert _same_sets(np.array([s.q for s in one.solutions]), ours)
            assert one.selected is not None and one.reachable


def test_random_off_axis_urdfs_match_root_search(tmp_path: Path) -> None:
    for path in write_random_family_urdfs(tmp_path, 9, seed=99):
        robot = load_robot(path, tool="tool")
        assert robot.family is not None
        poses = robot.fk(robot.random_configurations(200, seed=3))
        batch = robot.ik_batch(poses)
        general = _general(robot, poses)
        for i in range(len(poses)):
            ours = batch.q[i][batch.valid[i] & (batch.orientation_error[i] <= EXACT)]
            assert _same_sets(ours, general[i]), (path.name, i)


def test_out_of_reach_pose_falls_back_to_the_nearest() -> None:
    robot = load_robot("so101")
    pose = robot.fk(robot.random_configurations(1, seed=5)[0])
    pose[:3, 3] *= 4.0  # far out of reach: no exact branch, the root search's nearest
    one = robot.ik(pose)
    assert not one.reachable and one.distance > 0.1
    assert one.solutions
    batch = robot.ik_batch(pose[None])
    assert not batch.reachable[0]
    assert batch.distance[0] == pytest.approx(one.distance, abs=1e-12)


def test_poses_next_to_a_fold_of_the_elbow_round_trip() -> None:
    """The SO-101's elbow folds near q3 = -1.28849 rad (its built-in link angles): there the
    two elbow branches are ~1e-5 rad apart on the exact chain and Newton converges linearly.
    The start configuration must still come back to 1e-7 rad (found by the 1e6 round trips)."""
    robot = load_robot("so101")
    base = np.array([-0.5369933, 0.83660157, -1.28849203, 0.46747002, 1.75448164])
    starts = [base]
    for shift in (-1e-3, -1e-4, -1e-5, 1e-5, 1e-4, 1e-3):
        q = base.copy()
        q[2] += shift
        q[3] -= shift  # keep the pitch sum
        starts.append(q)
    q0 = np.array(starts)
    batch = robot.ik_batch(robot.fk(q0))
    assert batch.reachable.all()
    gap = np.where(batch.valid[..., None], np.abs(batch.q - q0[:, None, :]), np.inf)
    assert gap.max(axis=2).min(axis=1).max() < 1e-7
    assert np.where(batch.valid, batch.position_error, 0.0).max() <= 1e-12


def test_al5_single_pose_path_matches_the_batch() -> None:
    """Robot('al5').ik goes through Arm.ik; the same branches and selection as the batch."""
    from lynxplan.robots.selection import select_one

    robot = load_robot("al5")
    poses = robot.fk(robot.random_configurations(100, seed=8))
    far = poses[0].copy()
    far[:3, 3] *= 5.0  # out of reach: the general path's nearest solution
    for pose in [*poses, far]:
        one = robot.ik(pose)
        batch = robot.ik_batch(pose[None])
        other = select_one(batch, robot._default_reference[0], robot.ik_solver)
        assert one.selected == other.selected and one.reachable == other.reachable
        np.testing.assert_allclose(
            [s.q for s in one.solutions], [s.q for s in other.solutions], atol=0
        )
        assert one.distance == pytest.approx(other.distance, abs=1e-15)


@pytest.mark.parametrize("name", ["so101", "al5"])
def test_full_pose_targets_must_be_rigid(name: str) -> None:
    """A scaled rotation or a wrong last row is refused with the guards' error (single and
    batch, naming the pose); a rotation a little off orthonormal is repaired, then solved."""
    from lynxplan.exceptions import NonFiniteInputError, NotRigidTransformError

    robot = load_robot(name)
    pose = robot.fk(robot.random_configurations(1, seed=21)[0])
    scaled = pose.copy()
    scaled[:3, :3] *= 2.0
    bottom = pose.copy()
    bottom[3] = [0.0, 0.0, 0.1, 1.0]
    for bad in (scaled, bottom):
        with pytest.raises(NotRigidTransformError):
            robot.ik(bad)
        with pytest.raises(NotRigidTransformError, match=r"pose\[1\]"):
            robot.ik_batch(np.stack((pose, bad)))
    with pytest.raises(NonFiniteInputError):
        robot.ik(np.where(np.eye(4, dtype=bool), np.nan, pose))
    nudged = pose.copy()
    nudged[0, 0] += 1e-7  # within the repair tolerance: the nearest rotation is solved
    result = robot.ik(nudged)
    assert result.solutions and result.orientation_residual < 1e-6


def test_a_batch_with_one_pose_off_orthonormal_is_repaired_there_only() -> None:
    """The guards report the largest deviation from orthonormal (the same as numpy's
    ``max |R^T R - I|``); a batch is repaired only where a pose is off, and its solutions are
    the batch's without that pose."""
    from lynxplan.guards.arrays import poses_with_deviation
    from lynxplan.robots.targets import _rigid_poses

    robot = load_robot("so101")
    poses = robot.fk(robot.random_configurations(100, seed=22))
    nudged = poses.copy()
    nudged[37, 0, 0] += 1e-7
    _, deviation = poses_with_deviation("pose", nudged)
    rotations = nudged[:, :3, :3]
    gram = np.einsum("nji,njk->nik", rotations, rotations) - np.eye(3)
    assert deviation == pytest.approx(np.abs(gram).max(), rel=1e-12)
    repaired = _rigid_poses(nudged)
    assert np.array_equal(np.delete(repaired, 37, 0), np.delete(poses, 37, 0))
    r = repaired[37, :3, :3]
    assert np.abs(r.T @ r - np.eye(3)).max() < 1e-15
    assert np.abs(r - poses[37, :3, :3]).max() < 1e-7
