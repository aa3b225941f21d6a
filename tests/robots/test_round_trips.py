"""FK -> IK round trips for the built-in robots, checked against Pinocchio's FK."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.robots import Robot

#: Round trips per robot run in CI; the full 1e6 run in the slow test and in the benchmark.
CI_COUNT = 7_000
FULL_COUNT = 1_000_000
POSITION_TOLERANCE = 1e-9
PINOCCHIO_AGREEMENT = 1e-12


def _wrapped_gap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    d = np.abs(a - b)
    return np.minimum(d, 2 * np.pi - d % (2 * np.pi))


def round_trip(robot: Robot, count: int, seed: int, chunk: int = 50_000) -> None:
    for start in range(0, count, chunk):
        q = robot.random_configurations(min(chunk, count - start), seed=seed + start)
        poses = robot.fk(q)
        batch = robot.ik_batch(poses)
        assert batch.reachable.all()
        # every returned branch reaches the target position
        errors = np.where(batch.valid, batch.position_error, 0.0)
        assert errors.max() <= POSITION_TOLERANCE
        # the configuration we started from is among the branches
        gap = np.where(batch.valid[..., None], _wrapped_gap(batch.q, q[:, None, :]), np.inf)
        found = gap.max(axis=2).min(axis=1)
        assert found.max() < 1e-7, q[np.argmax(found)]


def test_round_trip_ci_count(builtin: Robot) -> None:
    round_trip(builtin, CI_COUNT, seed=11)


@pytest.mark.slow
def test_round_trip_full_count(builtin: Robot) -> None:
    round_trip(builtin, FULL_COUNT, seed=12)


def test_branches_verified_by_pinocchio(builtin: Robot) -> None:
    q = builtin.random_configurations(60, seed=3)
    for pose in builtin.fk(q):
        result = builtin.ik(pose)
        assert result.reachable
        for solution in result.solutions:
            placement = builtin.frame_placement(solution.q)
            np.testing.assert_allclose(
                placement[:3], builtin.fk(solution.q)[:3], atol=PINOCCHIO_AGREEMENT
            )
            assert np.linalg.norm(placement[:3, 3] - pose[:3, 3]) <= POSITION_TOLERANCE


def test_own_fk_and_jacobian_match_pinocchio(builtin: Robot) -> None:
    import pinocchio as pin

    for q in builtin.random_configurations(20, seed=5):
        np.testing.assert_allclose(builtin.fk(q), builtin.frame_placement(q), atol=1e-14)
        expected = pin.computeFrameJacobian(
            builtin.model,
            builtin.data,
            q,
            builtin.tool_frame_id,
            pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
        )
        np.testing.assert_allclose(builtin.jacobian(q), expected, atol=1e-12)


def test_approach_targets_round_trip(builtin: Robot) -> None:
    q = builtin.random_configurations(2_000, seed=21)
    poses = builtin.fk(q)
    approach = np.einsum("nij,j->ni", poses[:, :3, :3], builtin.approach_in_tool)
    # roll given: the start configuration is a branch
    batch = builtin.ik_batch(positions=poses[:, :3, 3], approaches=approach, rolls=q[:, 4])
    gap = np.where(batch.valid[..., None], _wrapped_gap(batch.q, q[:, None, :]), np.inf)
    assert gap.max(axis=2).min(axis=1).max() < 1e-7
    assert np.where(batch.valid, batch.position_error, 0).max() <= POSITION_TOLERANCE
    # roll free: every branch reaches the position; the approach is exact on some branch, and
    # the start configuration is a branch
    free = builtin.ik_batch(positions=poses[:, :3, 3], approaches=approach)
    assert free.reachable.all()
    assert np.where(free.valid, free.orientation_error, np.inf).min(axis=1).max() < 1e-9
    # (a tool on the roll axis leaves the roll to the reference)
    assert builtin.family is not None
    joints = 4 if builtin.family.tool_on_roll_axis else 5
    gap = _wrapped_gap(free.q[..., :joints], q[:, None, :joints])
    gap = np.where(free.valid[..., None], gap, np.inf)
    assert gap.max(axis=2).min(axis=1).max() < 1e-7


def test_pitch_targets_round_trip(builtin: Robot) -> None:
    q = builtin.random_configurations(2_000, seed=31)
    poses = builtin.fk(q)
    approach = np.einsum("nij,j->ni", poses[:, :3, :3], builtin.approach_in_tool)
    family = builtin.family
    assert family is not None
    # pitch from straight down (-k) towards the outward arm direction h(q1)
    k = np.array(family.yaw_axis)
    h0 = np.array(family.pitch_axis)
    h0 = np.cross(k, h0)
    angle = family.signs[0] * q[:, 0]
    h = np.cos(angle)[:, None] * h0 + np.sin(angle)[:, None] * np.cross(k, h0)
    pitch = np.arctan2(np.einsum("ni,ni->n", approach, h), -approach @ k)
    batch = builtin.ik_batch(positions=poses[:, :3, 3], pitches=pitch, rolls=q[:, 4])
    gap = np.where(batch.valid[..., None], _wrapped_gap(batch.q, q[:, None, :]), np.inf)
    assert gap.max(axis=2).min(axis=1).max() < 1e-7


def test_al5_pitch_is_q234() -> None:
    from lynxplan.robots import load_robot

    al5 = load_robot("al5")
    q = np.radians([120.0, 60.0, -45.0, 45.0, 10.0])
    result = al5.ik(position=al5.fk(q)[:3, 3], pitch=q[1] + q[2] + q[3], roll=q[4], q_reference=q)
    np.testing.assert_allclose(result.q, q, atol=1e-12)


def test_al5_matches_arm_module() -> None:
    """The AL5 as a Robot is solved by the family's closed form, ``lynxplan.arm`` by its own
    kernels: the same branches in the same slots (elbow up: the elbow above the
    shoulder-wrist line), the same angles to 1e-9 rad."""
    from lynxplan.arm.model import load_arm
    from lynxplan.robots import load_robot

    al5, arm = load_robot("al5"), load_arm()
    q = al5.random_configurations(2000, seed=8)
    poses = arm.fk(q)
    for ours, theirs in (
        (al5.ik_batch(poses), arm.ik_batch(poses)),
        (
            al5.ik_batch(positions=poses[:, :3, 3], approaches=poses[:, :3, 2]),
            arm.ik_batch(poses, approach_only=True),
        ),
    ):
        assert ours.valid.all()
        np.testing.assert_array_equal(ours.within_limits, theirs.within_limits)
        np.testing.assert_allclose(ours.q, theirs.q, rtol=0, atol=1e-9)
