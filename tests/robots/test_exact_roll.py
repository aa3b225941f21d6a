"""The roll search on the exact chain of a model only close to the family (the SO-101).

Position + approach targets with the roll free: where the ideal roll equation is within the
model's deviation of zero, the exact chain may have roots the ideal one lacks (SO-101: two roots
0.3 rad apart where the ideal equation has an extremum at -1.5e-7). Checked: the exact equation
is zero at the rolls of known solutions, it stays inside the band the search assumes around the
ideal one, and FK -> IK round trips find the start configuration among the branches.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lynxplan.constants import EXACT_BAND
from lynxplan.robots import Robot, load_robot
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.exact_roll_equation import exact_roll_equation
from lynxplan.robots.ik.family_geometry import MODE_APPROACH
from lynxplan.robots.ik.roll_equation import SCRATCH_ROWS, prepare_roll_terms, roll_equation
from tests.robots.urdf_factory import tilted_urdf, write_random_family_urdfs

#: The start configuration is a branch when every joint agrees to this [rad], or to
#: DOUBLE_ROOT on a double root of the roll equation (1 in ~50,000 SO-101 targets).
SAME_BRANCH = 1e-7
DOUBLE_ROOT = 1e-4


def _problems(robot: Robot, q: np.ndarray, side: int, elbow: int) -> tuple[tuple, tuple]:  # type: ignore[type-arg]
    """The ideal and exact roll problems of the approach target reached at q."""
    family = robot.family
    assert family is not None
    prm = family.packed
    pose = robot.fk(q)
    target = pose.copy()
    target[:3, 2] = pose[:3, :3] @ robot.approach_in_tool
    g = np.zeros((SCRATCH_ROWS, 4))
    g[:3, 3] = target[:3, 2]
    prepare_roll_terms(prm, target, g)
    sigma = prm[F.SIGMA : F.SIGMA + 5]
    ideal = (prm, target, g, MODE_APPROACH, side, float(sigma[0] * q[0]), 0.0)
    chain = (prm, robot.chain.placements, robot.chain.axes, target, g, MODE_APPROACH, 0.0)
    scratch = (np.empty(5), np.empty((6, 5)), np.empty((2, 4, 4)), np.empty((6, 5)), np.empty(5))
    return ideal, (ideal, chain, elbow, *scratch)


def _start_found(robot: Robot, q: np.ndarray) -> np.ndarray:
    """Whether the start configuration is among the branches of its approach target: to
    SAME_BRANCH, or to DOUBLE_ROOT where the start is on a double root of the roll equation
    (there every roll that close solves the target to ~1e-15: the branch found and the start
    are then checked to be one solution, each reaching the target)."""
    poses = robot.fk(q)
    approach = np.einsum("nij,j->ni", poses[:, :3, :3], robot.approach_in_tool)
    batch = robot.ik_batch(positions=poses[:, :3, 3], approaches=approach)
    assert batch.reachable.all()
    d = np.abs(batch.q - q[:, None, :])
    gap = np.where(batch.valid[..., None], np.minimum(d, 2 * np.pi - d), np.inf).max(axis=2)
    found = gap.min(axis=1) < SAME_BRANCH
    for row in np.flatnonzero(~found & (gap.min(axis=1) < DOUBLE_ROOT)):
        slot = np.argmin(gap[row])
        assert batch.position_error[row, slot] <= 1e-12
        assert batch.orientation_error[row, slot] <= 1e-12
        # the whole segment between the two solves the target: one (double) solution
        for t in (0.25, 0.5, 0.75):
            between = robot.fk((1 - t) * q[row] + t * batch.q[row, slot])
            assert np.abs(between[:3, 3] - poses[row, :3, 3]).max() <= 1e-12
            reached = between[:3, :3] @ robot.approach_in_tool
            assert np.linalg.norm(np.cross(reached, approach[row])) <= 1e-12
        found[row] = True
    return np.asarray(found)


def test_exact_equation_is_zero_at_solutions(so101: Robot) -> None:
    """At the roll of a configuration the exact equation of one of its sides and elbows is zero
    (the target was made from it by Pinocchio-checked FK); the ideal one need not be."""
    family = so101.family
    assert family is not None and not family.exact
    sigma = family.packed[F.SIGMA + 4]
    for q in so101.random_configurations(40, seed=4):
        values = []
        for side in range(2):
            for elbow in range(2):
                _, exact = _problems(so101, q, side, elbow)
                values.append(abs(exact_roll_equation(exact, float(sigma * q[4]))))
        assert np.nanmin(values) < 1e-12


def test_exact_equation_stays_in_the_band(so101: Robot) -> None:
    """The search trusts the ideal equation's sign outside a band of EXACT_BAND deviations
    times 1 + d / rho around zero: there the exact equation has the same sign, and near zero
    the two differ by a small part of the band (the exact search covers the band)."""
    family = so101.family
    assert family is not None
    prm = family.packed
    rng = np.random.default_rng(8)
    lo, hi = sorted(prm[F.SIGMA + 4] * np.array([prm[F.LOWER + 4], prm[F.UPPER + 4]]))
    near, outside = [], 0
    for q in so101.random_configurations(600, seed=9):
        for side in range(2):
            for elbow in range(2):
                ideal, exact = _problems(so101, q, side, elbow)
                target, g = ideal[1], ideal[2]
                d = np.linalg.norm(target[:3, 3] - prm[F.C1 : F.C1 + 3])
                band = EXACT_BAND * prm[F.DEVIATION] * (1.0 + d / g[3, 0])
                for theta in rng.uniform(lo, hi, 4):
                    e = exact_roll_equation(exact, theta)
                    if not np.isfinite(e):
                        continue
                    f = roll_equation(ideal, theta)
                    if abs(f) >= band:
                        assert np.sign(e) == np.sign(f)
                        outside += 1
                    if abs(f) < 4 * band:
                        near.append(abs(e - f) / band)
    assert outside > 5_000 and len(near) > 200
    assert max(near) < 0.25


def test_approach_round_trips_find_the_start_branch(so101: Robot) -> None:
    """10,000 SO-101 approach targets, roll free: the start configuration is a branch. (This
    seed has flat stretches and near double roots: 7 starts were missed by the ideal search
    alone.)"""
    q = so101.random_configurations(10_000, seed=7)
    found = _start_found(so101, q)
    assert found.all(), q[~found][:3]


def test_approach_round_trips_on_random_near_family_urdfs(tmp_path: Path) -> None:
    """Random arms with off-axis tools, tilted 4e-6 rad off the family like the SO-101: the
    start configuration of every approach target is a branch."""
    paths = write_random_family_urdfs(tmp_path, 6, seed=31)
    tested = 0
    for path in paths:
        robot = load_robot(tilted_urdf(path), tool="tool")
        assert robot.family is not None and not robot.family.exact
        if robot.family.tool_on_roll_axis:
            continue
        q = robot.random_configurations(2_000, seed=tested)
        found = _start_found(robot, q)
        assert found.all(), (path.name, q[~found][:3])
        tested += 1
    assert tested >= 3


@pytest.mark.slow
def test_approach_round_trips_full_count(so101: Robot) -> None:
    for seed in range(20):
        q = so101.random_configurations(50_000, seed=100 + seed)
        found = _start_found(so101, q)
        assert found.all(), q[~found][:3]
