"""The URDF handed to the IK peers carries the robot's tool frame as a link, placed exactly."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from lynxplan.bench.robots import urdf_with_tool
from lynxplan.robots import Robot, load_robot

#: Pinocchio FK of the written link against the robot's FK [m] and rotation entries.
FK_TOLERANCE = 1e-12


def _written_tool_poses(robot: Robot, text: str, folder: Path, q: np.ndarray) -> np.ndarray:
    """Pinocchio FK of the written URDF's tool link at the robot's joint angles ``q`` (N, n);
    joints the robot locked stay at its locked angles."""
    path = folder / "with_tool.urdf"
    path.write_text(text)
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    frame = model.getFrameId(robot.tool_frame, pin.FrameType.BODY)
    assert frame < len(model.frames), f"no link {robot.tool_frame} in the written URDF"
    locked = dict(robot.locked_joints)
    poses = []
    for qi in q:
        full = np.zeros(model.nq)
        for j in range(1, model.njoints):
            name = str(model.names[j])
            arm = robot.joint_names.index(name) if name in robot.joint_names else None
            full[model.idx_qs[j]] = qi[arm] if arm is not None else locked[name]
        pin.framesForwardKinematics(model, data, full)
        poses.append(data.oMf[frame].homogeneous)
    return np.array(poses)


@pytest.mark.parametrize(("name", "tool"), [("so100", None), ("so101", "wrist_roll")])
def test_added_tool_link_matches_the_robot_fk(name: str, tool: str | None, tmp_path: Path) -> None:
    """SO-100: lynxplan's own tool between the jaws; SO-101: a tool named after a joint."""
    robot = load_robot(name, tool=tool)
    text = urdf_with_tool(robot)
    assert text is not None
    q = robot.random_configurations(200, seed=5)
    np.testing.assert_allclose(
        _written_tool_poses(robot, text, tmp_path, q), robot.fk(q), rtol=0, atol=FK_TOLERANCE
    )


def test_a_urdf_with_the_tool_link_is_handed_over_unchanged() -> None:
    assert urdf_with_tool(load_robot("so101")) is None
