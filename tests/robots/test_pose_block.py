"""The vectorised full-pose kernel (``pose_block``) against the scalar one (``pose_kernel``).

Both must give the same slots: the same validity, the same within-limits flags, the same
"solved" verdict, angles equal to 1e-9 rad (1e-6 next to a double root) and errors no larger
on every target: random poses,
poses next to the yaw axis and next to a fold of the elbow, poses out of reach, approaches along
the yaw axis, and random family URDFs (exact, and only close to the family). The vector path must
also carry the load: few poses may fall back to the scalar solver.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lynxplan import constants
from lynxplan._arrays import kernel_input
from lynxplan.constants import REACH_TOLERANCE
from lynxplan.robots import Robot, load_robot
from lynxplan.robots.ik import family_solver, pose_kernel
from lynxplan.robots.ik.pose_block import pose_block_kernel
from lynxplan.robots.results import BranchSlots
from lynxplan.robots.targets import make_target
from tests.robots.test_pose_kernel import _near_axis_poses
from tests.robots.urdf_factory import tilted_urdf, write_random_family_urdfs


def _both(robot: Robot, poses: np.ndarray, reference: np.ndarray) -> tuple[tuple, tuple, int]:  # type: ignore[type-arg]
    family, chain = robot.family, robot.chain
    assert family is not None
    slots = 4 if family.tool_on_roll_axis else 4 * family_solver.POSE_ROLLS
    results = []
    fallbacks = 0
    for kernel in (pose_kernel.pose_kernel, pose_block_kernel):
        out = BranchSlots.empty(len(poses), slots)
        solved = np.empty(len(poses), dtype=np.bool_)
        distance = np.empty(len(poses))
        count = kernel(
            family.packed,
            chain.placements,
            chain.axes,
            kernel_input(poses),
            kernel_input(reference),
            out,
            solved,
            distance,
        )
        # each target's smallest position error over its slots, the empty slots skipped
        smallest = np.fmin.reduce(out.position_error, axis=1)
        assert np.array_equal(distance, smallest, equal_nan=True)
        fallbacks = count if count is not None else fallbacks
        results.append((*out, solved))
    return results[0], results[1], fallbacks


def _assert_same(scalar: tuple, block: tuple) -> None:  # type: ignore[type-arg]
    q_s, valid_s, within_s, perr_s, oerr_s, solved_s = scalar
    q_b, valid_b, within_b, perr_b, oerr_b, solved_b = block
    assert np.array_equal(solved_s, solved_b)
    assert np.array_equal(valid_s, valid_b)
    assert np.array_equal(within_s, within_b)
    # equal angles; next to a double root (a fold of the elbow) Newton stops at ~1e-11 and the
    # angles along the fold are only fixed to ~ sqrt(error): there 1e-6 rad
    loose = np.maximum(perr_s, perr_b) > 1e-13
    gap = np.abs(q_s - q_b).max(axis=-1)
    assert np.all(gap[valid_s & ~loose] <= 1e-9)
    assert np.all(gap[valid_s & loose] <= 1e-6)
    assert np.all(np.isnan(q_b[~valid_b]))
    # no worse than the scalar solver's (whose polish may stop above 1e-12 next to a fold)
    assert np.all(perr_b[valid_b] <= np.maximum(perr_s[valid_b], 1e-14) + 1e-12)
    assert np.all(oerr_b[valid_b] <= np.maximum(oerr_s[valid_b], 1e-14) + 1e-12)


def _mixed_poses(robot: Robot, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    q = robot.random_configurations(2000, seed=seed)
    fold = q[:200].copy()  # elbows next to their folds (built-in angle of the SO-101: -1.28849)
    fold[:, 2] = -1.28849203 + rng.normal(0.0, 1e-3, 200)
    poses = robot.fk(np.concatenate((q, fold)))
    far = poses[:100].copy()
    far[:, :3, 3] *= 3.0  # out of reach
    vertical = robot.fk(q[:50])  # the approach along the yaw axis: the yaw left to the position
    assert robot.family is not None
    k = np.array(robot.family.yaw_axis)
    for pose in vertical:
        a = pose[:3, :3] @ np.array(robot.family.approach_in_tool)
        axis = np.cross(a, -k)
        angle = np.arctan2(np.linalg.norm(axis), a @ -k)
        if np.linalg.norm(axis) > 1e-12:
            from scipy.spatial.transform import Rotation

            turn = Rotation.from_rotvec(axis / np.linalg.norm(axis) * angle).as_matrix()
            pose[:3, :3] = turn @ pose[:3, :3]
    near = _near_axis_poses(robot, 200, seed + 1)
    return np.ascontiguousarray(np.concatenate((poses, far, vertical, near)))


@pytest.mark.parametrize("name", ["so101", "so100"])
def test_block_kernel_equals_scalar_kernel(name: str) -> None:
    robot = load_robot(name)
    poses = _mixed_poses(robot, seed=21)
    references = [robot._default_reference, robot.random_configurations(len(poses), seed=4)]
    for reference in references:
        scalar, block, _ = _both(robot, poses, np.ascontiguousarray(reference))
        _assert_same(scalar, block)


def test_block_kernel_equals_scalar_kernel_on_random_family_urdfs(tmp_path: Path) -> None:
    """Exact family models (no polish) and the same tilted (polished); tools on and off the
    roll axis."""
    for path in write_random_family_urdfs(tmp_path, 6, seed=7):
        for urdf in (path, tilted_urdf(path)):
            robot = load_robot(urdf, tool="tool")
            assert robot.family is not None
            assert robot.family.exact == (urdf == path)
            poses = _mixed_poses(robot, seed=5)
            scalar, block, _ = _both(robot, poses, robot._default_reference)
            _assert_same(scalar, block)


def test_parallel_pitch_steps_are_the_normal_equations_steps(tmp_path: Path) -> None:
    """Where the pitch axes are parallel (of either sign) the polish takes its Gauss-Newton
    steps from the family's structure (``newton_parallel``): the same steps as the normal
    equations' (``newton_ldl``), on random family URDFs with the roll axis tilted (a model
    only close to the family whose pitch axes stay parallel, as the SO-101) and on the SO-101,
    from starts ~1e-5 off random configurations; the block kernel, which then takes them,
    still equals the scalar one. A tilted pitch axis takes the normal equations."""
    import numba

    from lynxplan.robots.ik.block_layout import chain_tuple
    from lynxplan.robots.ik.block_newton import (
        newton_ldl,
        newton_parallel,
        offsets,
        parallel_pitches,
    )

    @numba.njit(cache=False)
    def steps(ch, t, q):  # type: ignore[no-untyped-def]
        s, c = np.sin(q), np.cos(q)
        sn, cs = offsets(ch, (s[0], s[1], s[2], s[3], s[4]), (c[0], c[1], c[2], c[3], c[4]))
        qq = (q[0], q[1], q[2], q[3], q[4])
        return newton_parallel(ch, t, qq, sn, cs), newton_ldl(ch, t, qq, sn, cs)

    rng = np.random.default_rng(21)
    worst: list[float] = []
    paths = write_random_family_urdfs(tmp_path, 6, seed=11)
    robots = [load_robot(tilted_urdf(path, joint="j5"), tool="tool") for path in paths]
    for robot in [*robots, load_robot("so101")]:
        assert robot.family is not None and not robot.family.exact
        ch = chain_tuple(robot.chain.placements, robot.chain.axes)
        assert parallel_pitches(ch)
        q = robot.random_configurations(100, seed=3)
        poses = robot.fk(q)
        for n in range(q.shape[0]):
            t = tuple(poses[n, :3].reshape(-1))
            mine, normal = steps(ch, t, q[n] + rng.normal(scale=1e-5, size=5))
            x, y = np.array(mine[:5]), np.array(normal[:5])
            worst.append(np.abs(x - y).max() / np.abs(y).max())  # relative to the step
            assert mine[6] == normal[6]  # the same pose error
        if robot.name != "so101":
            scalar, block, _ = _both(robot, _mixed_poses(robot, seed=5), robot._default_reference)
            _assert_same(scalar, block)
    # the same steps but for rounding, which the normal equations raise to cond(J)^2 eps
    # where the arm is near a singularity (a few starts)
    assert np.median(worst) <= 1e-12
    assert np.quantile(worst, 0.99) <= 1e-9
    assert max(worst) <= 1e-6
    tilted = load_robot(tilted_urdf(paths[0]), tool="tool")
    assert not parallel_pitches(chain_tuple(tilted.chain.placements, tilted.chain.axes))


def test_vector_path_carries_the_load() -> None:
    """On random reachable SO-101 poses at most 1 % fall back to the scalar solver (~0.15 % with
    the second vector polish of the candidates next to a fold): a vector path that stopped taking
    its candidates would pass the equality tests above while losing its speed."""
    robot = load_robot("so101")
    poses = np.ascontiguousarray(robot.fk(robot.random_configurations(5000, seed=8)))
    _, _, fallbacks = _both(robot, poses, robot._default_reference)
    assert fallbacks <= 0.01 * len(poses)


def test_block_errors_are_pinocchio_fk_at_the_returned_angles() -> None:
    """The vector path carries the sines and cosines of the polish through its steps and
    through the snaps to the joint limits (Taylor series) instead of computing them afresh:
    every branch's reported errors must still be those of Pinocchio's FK at its returned
    angles, also where a branch lies just beyond a limit (within and past the snap
    tolerance; a pose left with no exact branch gets its nearest orientations)."""
    import pinocchio as pin

    robot = load_robot("so101")
    rng = np.random.default_rng(17)
    q = robot.random_configurations(1200, seed=17)
    lower, upper = robot.limits.lower, robot.limits.upper
    q[:300, 2] = lower[2] + rng.uniform(-3e-4, 1e-4, 300)
    q[300:600, 1] = upper[1] + rng.uniform(-1e-4, 3e-4, 300)
    q[600:800, 3] = lower[3] + rng.uniform(-3e-4, 1e-4, 200)
    poses = robot.fk(q)
    batch = robot.ik_batch(poses)
    assert batch.valid.any(axis=1).all()
    for n, b in zip(*np.nonzero(batch.valid), strict=True):
        placement = robot.frame_placement(batch.q[n, b])
        position = np.linalg.norm(placement[:3, 3] - poses[n, :3, 3])
        angle = np.linalg.norm(pin.log3(poses[n, :3, :3].T @ placement[:3, :3]))
        assert position <= 1e-9
        assert abs(position - batch.position_error[n, b]) <= 1e-14
        assert abs(angle - batch.orientation_error[n, b]) <= 1e-14 + 1e-9 * angle
    exact = batch.valid & (batch.orientation_error <= 1e-12)
    assert exact.any(axis=1).mean() > 0.9


def test_exact_branches_are_within_the_reach_tolerance() -> None:
    """``solve_poses`` returns the pose kernels' batch as it is when every target has exact
    branches: each reaches its target within REACH_TOLERANCE (so it is reachable, and no
    branch is dropped)."""

    assert constants.POSE_EXACT <= REACH_TOLERANCE
    robot = load_robot("so101")
    batch = robot.ik_batch(robot.fk(robot.random_configurations(300, seed=9)))
    assert batch.reachable.all()
    assert np.all(batch.position_error[batch.valid] <= REACH_TOLERANCE)
    assert np.array_equal(
        batch.distance, np.where(batch.valid, batch.position_error, np.inf).min(axis=1)
    )


def test_sparse_chain_gives_the_same_poses() -> None:
    """The kernel's chain (frames on the joint axes that make each link R(z, phi) R(x, beta)
    with no translation along z, ``chain_tuple``) against ``chain_fk``: random placements and
    random unit axes (not only the URDFs' x/y/z), and chains with parallel axes, exactly (no
    normal common to two axes: any is taken) and tilted by 1e-12 to 1e-4 rad (the common
    normal from a tiny cross product), as in the family's pitch joints."""
    from scipy.spatial.transform import Rotation

    from lynxplan.robots.chain import chain_fk
    from lynxplan.robots.ik.block_layout import chain_tuple
    from lynxplan.robots.ik.block_newton import chain_pose

    rng = np.random.default_rng(12)
    for case in range(40):
        placements = np.tile(np.eye(4), (6, 1, 1))
        placements[:, :3, :3] = Rotation.random(6, random_state=rng).as_matrix()
        placements[:, :3, 3] = rng.uniform(-0.2, 0.2, (6, 3))
        axes = rng.normal(size=(5, 3))
        axes /= np.linalg.norm(axes, axis=1)[:, None]
        axes[rng.uniform(size=5) < 0.4] = [0.0, 0.0, -1.0]
        if case >= 20:  # joints 2-4 about parallel axes, exactly or nearly
            tilt = 0.0 if case < 25 else 10.0 ** rng.uniform(-12, -4)
            for k in (2, 3):
                turn = Rotation.from_rotvec(tilt * Rotation.random(random_state=rng).as_rotvec())
                placements[k, :3, :3] = turn.as_matrix()
                axes[k] = axes[1]
        chain = chain_tuple(placements, axes)
        for q in rng.uniform(-np.pi, np.pi, (10, 5)):
            expected = np.empty((4, 4))
            chain_fk(placements, axes, q, expected, np.empty((4, 4)))
            got = np.array(chain_pose(chain, *q)).reshape(3, 4)
            assert np.abs(got - expected[:3]).max() < 1e-14


def test_full_poses_of_an_off_axis_tool_have_eight_slots() -> None:
    """Full poses: side x two rolls x elbow. Targets of the general kernel (out of reach,
    degenerate) are packed from its 24 root-search slots: every side whose branches use at
    most two rolls keeps them all, packed branches are the kernel's own, and the nearest
    solution is kept."""
    robot = load_robot("so101")
    poses = _mixed_poses(robot, seed=31)
    batch = robot.ik_batch(poses)
    assert batch.q.shape == (len(poses), 8, 5)
    assert batch.branch_names[:3] == (
        "front/roll-1/elbow-up",
        "front/roll-1/elbow-down",
        "front/roll-2/elbow-up",
    )
    target = make_target(poses)
    full = BranchSlots.empty(len(poses), 24)
    family_solver._kernel(robot.kinematics, target, robot._default_reference, full)
    packed = family_solver.pack_rolls(full, 2)
    rolls_used = full.valid.reshape(-1, 2, 6, 2).any(axis=3).sum(axis=2).max(axis=1)
    few = rolls_used <= 2
    assert np.array_equal(packed.valid[few].sum(axis=1), full.valid[few].sum(axis=1))
    for i in range(len(poses)):
        for q in packed.q[i][packed.valid[i]]:
            assert np.abs(full.q[i][full.valid[i]] - q).max(axis=1).min() == 0.0
    nearest = np.where(full.valid, full.position_error, np.inf).min(axis=1)
    assert np.array_equal(
        np.where(packed.valid, packed.position_error, np.inf).min(axis=1), nearest
    )


def _flips(robot: Robot, poses: np.ndarray) -> tuple[np.ndarray, ...]:
    """Per pose: |flip 1's roll + flip 0's| (each computed from the orientation), the flip the
    screen picks, whether it marks the other, and both flips computed in full (candidate,
    fallback: 1/0), as the kernel computed them before the screen."""
    from lynxplan.robots.ik import block_closed_form as pb
    from lynxplan.robots.ik.block_layout import link_shape

    family = robot.family
    assert family is not None
    pr = tuple(float(v) for v in family.packed)
    shape = link_shape(family.packed)
    rows = []
    for pose in poses:
        t = tuple(float(v) for v in pose[:3, :4].reshape(-1))
        roll0, roll1 = pb.orientation_roll(pr, shape, t, 0), pb.orientation_roll(pr, shape, t, 1)
        one, later = pb.screen_flips(pr, shape, t, roll0)
        first = pb.flip_geometry(pr, shape, t, 0, False, roll0)
        # flip_geometry turns the roll it is given by pi for flip 1: given -roll1, it uses roll1
        other = pb.flip_geometry(pr, shape, t, 1, False, (-roll1[0], -roll1[1]))
        gap = max(abs(roll1[0] + roll0[0]), abs(roll1[1] + roll0[1]))
        rows.append((gap, one, later, first[1], first[2], other[1], other[2]))
    return tuple(np.array(column) for column in zip(*rows, strict=True))


def _assert_screen_sound(robot: Robot, poses: np.ndarray) -> np.ndarray:
    """The flip the screen leaves out is no candidate and sends no pose to the scalar solver
    that the computed flip does not (both flips in full, with flip 1's roll computed afresh);
    returns where the screen marked the other flip."""
    gap, one, later, cand0, fall0, cand1, fall1 = _flips(robot, poses)
    assert gap.max() <= 1e-14  # flip 1's roll is flip 0's turned by pi
    left_cand = np.where(one == 0, cand1, cand0).astype(bool)
    left_fall = np.where(one == 0, fall1, fall0).astype(bool)
    kept_fall = np.where(one == 0, fall0, fall1).astype(bool)
    free = ~later.astype(bool)
    assert not left_cand[free].any()
    assert not (left_fall & ~kept_fall)[free].any()
    return later.astype(bool)


def test_screen_leaves_out_only_flips_that_cannot_matter(tmp_path: Path) -> None:
    """A tool off the roll axis: ``screen_flips`` computes one flip, and the other only where it
    may matter; on the SO-101 (mixed poses: random, next to folds and the yaw axis, out of
    reach, approaches along the yaw axis, arbitrary orientations) and random off-axis family
    URDFs (exact and tilted). The other flip must be rare, or the screen saves nothing."""
    from scipy.spatial.transform import Rotation

    robot = load_robot("so101")
    poses = _mixed_poses(robot, seed=41)
    turned = poses[:500].copy()
    turned[:, :3, :3] = Rotation.random(500, random_state=2).as_matrix()
    later = _assert_screen_sound(robot, np.concatenate((poses, turned)))
    random = robot.fk(robot.random_configurations(2000, seed=42))
    assert _assert_screen_sound(robot, random).mean() <= 0.1  # measured: ~3 %
    assert later.any()  # the marked poses exist (and the equality tests cover them)
    for path in write_random_family_urdfs(tmp_path, 4, seed=11):
        for urdf in (path, tilted_urdf(path)):
            robot = load_robot(urdf, tool="tool")
            assert robot.family is not None
            if not robot.family.tool_on_roll_axis:
                _assert_screen_sound(robot, _mixed_poses(robot, seed=6)[:800])
