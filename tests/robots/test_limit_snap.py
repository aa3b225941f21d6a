"""A branch just outside a joint limit: snapped onto the limit where the snapped angles still
reach the target (rounding), kept as it is and outside the limits where the snap would move the
tool off it. A snap never drops an exact branch nor makes a reachable target unreachable (both
happened: the SO-101 called 3 % of full poses and 5 % of approach targets from configurations
3e-5 rad past a limit unreachable)."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.robots import Robot, load_robot


def _past_a_limit(robot: Robot, count: int, by: float, seed: int) -> np.ndarray:
    """Configurations (count, 5) [rad] with one joint (of the first four: the roll's snap of an
    on-axis tool moves nothing) ``by`` [rad] past one of its limits."""
    rng = np.random.default_rng(seed)
    lo, hi = robot.limits.lower, robot.limits.upper
    q = rng.uniform(lo, hi, (count, 5))
    joint = rng.integers(0, 4, count)
    upper = rng.integers(0, 2, count) == 1
    q[np.arange(count), joint] = np.where(upper, hi[joint] + by, lo[joint] - by)
    return q


def _found(batch: object, q: np.ndarray) -> np.ndarray:
    """Per target: the configuration q is one of the valid branches (to 1e-9 rad)."""
    gap = np.abs(batch.q - q[:, None, :]) % (2 * np.pi)  # type: ignore[attr-defined]
    gap = np.minimum(gap, 2 * np.pi - gap)
    valid = batch.valid[..., None]  # type: ignore[attr-defined]
    return np.asarray(np.where(valid, gap, np.inf).max(axis=2).min(axis=1) < 1e-9)


def test_the_al5_keeps_a_branch_just_past_a_limit_outside_it() -> None:
    """q3 6e-6 rad below its limit: four exact branches, the start configuration among them as
    it is (outside the limits; the snapped one misses the pose by 1.5 um), single pose and
    vectorised batch alike."""
    robot = load_robot("al5")
    q = np.array([0.5, 0.5, -2.618, 0.5, 0.2])
    assert q[2] < robot.limits.lower[2]
    pose = robot.fk(q)
    result = robot.ik(pose)
    assert len(result.solutions) == 4 and result.selected is None
    start = [s for s in result.solutions if np.abs(s.q - q).max() < 1e-9]
    assert len(start) == 1 and not start[0].within_limits
    assert max(s.position_error for s in result.solutions) < 1e-12
    batch = robot.ik_batch(np.repeat(pose[None], 40, axis=0))  # the vectorised solver
    assert batch.valid.all() and not batch.within_limits.any()
    np.testing.assert_array_equal(batch.q[0], batch.q[-1])
    assert _found(batch, np.repeat(q[None], 40, axis=0)).all()


@pytest.mark.parametrize("name", ["so101", "so100", "al5"])
def test_configurations_just_past_a_limit_are_found_and_reachable(name: str) -> None:
    robot = load_robot(name)
    q = _past_a_limit(robot, 400, 3e-5, seed=3)
    poses = robot.fk(q)
    batch = robot.ik_batch(poses)
    assert batch.reachable.all() and _found(batch, q).all()
    # the start configuration's branch is outside the limits (it is)
    approach = np.einsum("nij,j->ni", poses[:, :3, :3], robot.approach_in_tool)
    target = robot.ik_batch(positions=poses[:, :3, 3], approaches=approach)
    assert target.reachable.all() and float(target.distance.max()) < 1e-12


def test_a_rounding_past_a_limit_is_still_snapped_onto_it() -> None:
    """1e-12 rad past a limit: the snapped branch still reaches the pose, within the limits."""
    robot = load_robot("so101")
    q = _past_a_limit(robot, 200, 1e-12, seed=4)
    batch = robot.ik_batch(robot.fk(q))
    gap = np.abs(batch.q - q[:, None, :]).max(axis=2)
    nearest = np.argmin(np.where(batch.valid, gap, np.inf), axis=1)
    rows = np.arange(len(q))
    assert (gap[rows, nearest] < 1e-9).all()
    assert batch.within_limits[rows, nearest].all()
