"""The numerical fallback on UR5 and Panda (example_robot_data), every success FK-verified."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.robots import load_robot

CI_POSES = 400
SUCCESS_RATE = 0.995


@pytest.mark.parametrize(("name", "tool"), [("ur5", "tool0"), ("panda", "panda_hand_tcp")])
def test_fallback_success_rate(name: str, tool: str) -> None:
    from example_robot_data.robots_loader import getModelPath

    folder = {
        "ur5": "ur_description/urdf/ur5_robot.urdf",
        "panda": "panda_description/urdf/panda.urdf",
    }
    path = f"{getModelPath(folder[name])}/{folder[name]}"
    robot = load_robot(path, tool=tool)
    assert robot.family is None
    q = robot.random_configurations(CI_POSES, seed=4)
    poses = robot.fk(q)
    batch = robot.ik_batch(poses)
    success = batch.valid[:, 0]
    assert success.mean() >= SUCCESS_RATE
    for k in np.flatnonzero(success):
        placement = robot.frame_placement(batch.q[k, 0])
        assert np.linalg.norm(placement[:3, 3] - poses[k, :3, 3]) <= 1e-9
        assert np.abs(placement[:3, :3] - poses[k, :3, :3]).max() <= 1e-8
    assert not np.isnan(batch.q[success]).any()
