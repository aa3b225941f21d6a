"""The dispatch table (``robots/ik/dispatch``): which solver runs for which target, and that
each route gives the same branches as the others where two can solve the same targets."""

from __future__ import annotations

import numpy as np

from lynxplan.robots import Robot, load_robot
from lynxplan.robots.ik import dispatch
from lynxplan.robots.targets import make_target

#: Branch angles of the scalar and the vectorised closed form agree to this [rad].
SAME_BRANCH = 1e-9


def _poses(name: str, count: int) -> tuple[Robot, np.ndarray]:
    robot = load_robot(name)
    q = robot.random_configurations(count, seed=4)
    return robot, np.array(robot.fk(q))


def test_route_names_the_solver_of_each_row_of_the_table() -> None:
    so101, poses = _poses("so101", dispatch.BLOCK_FROM)
    al5 = load_robot("al5")
    approach = poses[:, :3, 2]
    cases = [
        (so101, make_target(poses, None, None, None, None), dispatch.BLOCK),
        (so101, make_target(poses[:3], None, None, None, None), dispatch.SCALAR),
        (so101, make_target(None, poses[:, :3, 3], approach, None, None), dispatch.ROLL_SEARCH),
        (so101, make_target(None, poses[:, :3, 3], None, np.zeros(32), None), dispatch.ROLL_SEARCH),
        (al5, make_target(poses, None, None, None, None), dispatch.BLOCK),
        (al5, make_target(None, poses[:, :3, 3], None, np.zeros(32), None), dispatch.ROLL_SEARCH),
    ]
    for robot, target, expected in cases:
        assert dispatch.route(robot.kinematics, target) == expected


def test_block_threshold_is_one_block_of_the_vectorised_solver() -> None:
    from lynxplan.robots.ik.block_layout import BLOCK

    assert dispatch.BLOCK_FROM == BLOCK


def test_scalar_and_block_routes_give_the_same_branches() -> None:
    """The same full poses through the scalar route (in pieces under a block) and the block
    route: the same branch sets, angles within SAME_BRANCH."""
    robot, poses = _poses("so101", 2 * dispatch.BLOCK_FROM)
    whole = robot.ik_batch(poses)
    step = dispatch.BLOCK_FROM - 1
    pieces = [robot.ik_batch(poses[i : i + step]) for i in range(0, len(poses), step)]
    valid = np.concatenate([p.valid for p in pieces])
    q = np.concatenate([p.q for p in pieces])
    assert np.array_equal(valid, whole.valid)
    np.testing.assert_allclose(q[valid], whole.q[valid], rtol=0, atol=SAME_BRANCH)
    assert whole.reachable.all()
