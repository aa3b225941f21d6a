"""Planning goals for a URDF robot (the SO-101): a position + approach goal reached exactly, every
IK branch a candidate, checked with Pinocchio's FK."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import lynxplan
from lynxplan.collision.obstacles import axis_aligned_box
from lynxplan.exceptions import GoalUnreachableError, PlanningError
from lynxplan.planning import Planner
from lynxplan.planning.problem import ApproachGoal

TARGET = np.array([0.2, 0.12, 0.05])


@pytest.fixture(scope="module")
def so101():
    return lynxplan.load_robot("so101")


def test_approach_goal_of_the_so101_is_reached(so101) -> None:
    table = axis_aligned_box("table", np.array([-0.05, -0.3, -0.03]), np.array([0.5, 0.6, 0.02]))
    start = so101.ik(position=[0.2, -0.12, 0.05], approach=[0, 0, -1], roll=-1.57).q
    planner = Planner(so101, [table])
    trajectory = planner.solve(start, ApproachGoal(TARGET, np.array([0.0, 0.0, -1.0])), seed=1)
    assert trajectory.verification.collision_free
    data = so101.model.createData()
    pin.framesForwardKinematics(so101.model, data, trajectory.q[-1])
    placement = data.oMf[so101.tool_frame_id]
    assert np.linalg.norm(placement.translation - TARGET) <= 1e-9
    approach = placement.rotation @ so101.approach_in_tool
    assert np.arccos(np.clip(-approach[2], -1, 1)) <= 1e-5


def test_unreachable_goal_of_the_so101_is_refused(so101) -> None:
    start = so101.ik(position=[0.2, -0.12, 0.05], approach=[0, 0, -1], roll=-1.57).q
    far = ApproachGoal(np.array([0.9, 0.0, 0.05]), np.array([0.0, 0.0, -1.0]))
    with pytest.raises((GoalUnreachableError, PlanningError), match="out of reach"):
        Planner(so101, []).solve(start, far, seed=0)
