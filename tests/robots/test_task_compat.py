"""The ``Arm.ik`` keywords the task kind uses work on every Robot (so it can switch)."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.exceptions import TargetError
from lynxplan.robots import load_robot


@pytest.mark.parametrize("name", ["al5", "so100", "so101"])
def test_approach_only_pose_and_reference(name: str) -> None:
    robot = load_robot(name)
    q = robot.random_configurations(1, seed=9)[0]
    pose = robot.fk(q)
    target = pose.copy()
    target[:3, 2] = pose[:3, :3] @ robot.approach_in_tool  # the approach in column 2
    target[:3, :2] = 0.0  # ignored
    result = robot.ik(target, q_reference=q, approach_only=True)
    np.testing.assert_allclose(result.q, q, atol=1e-9)
    assert robot.limits.position.shape == (5, 2)
    assert robot.limits.velocity.shape == (5,)
    assert robot.urdf_path.is_file()
    if name == "al5":  # the report's rule is the AL5's own (tests/robots/test_al5_selection.py)
        assert robot.ik(pose, select="report").solutions
        return
    with pytest.raises(TargetError, match=f"{name} offers 'nearest'"):
        robot.ik(pose, select="report")
