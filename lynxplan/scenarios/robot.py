"""``robot:`` entries of scenarios -> loaded robots (at run time, never during validation)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from lynxplan.exceptions import LynxplanError, ScenarioValueError
from lynxplan.scenarios.base import RobotRef

#: Joints of the arms that follow paths (yaw, three pitches, roll).
PATH_JOINTS = 5


def load_robot_entry(entry: RobotRef) -> Any:
    """The robot a ``robot:`` entry names: the AL5 (``lynxplan.arm.Arm``: the shipped URDF, or a
    URDF of its joint structure) or any robot of :func:`lynxplan.load_robot`.

    Raises:
        ScenarioValueError: naming the ``robot`` key when the robot cannot be loaded.
    """
    from lynxplan.arm.model import load_arm

    key = ("robot", "urdf" if entry.urdf is not None else "name")
    value = entry.urdf if entry.urdf is not None else entry.name
    if entry.tool is None and entry.name in (None, "al5"):
        try:
            return load_arm(entry.urdf)
        except LynxplanError as exc:  # not the AL5's structure: a URDF robot, if a file at all
            if entry.urdf is None or not Path(entry.urdf).is_file():
                raise ScenarioValueError(key, str(exc), value) from exc
    import lynxplan

    try:
        return lynxplan.load_robot(value or "al5", tool=entry.tool)
    except LynxplanError as exc:
        raise ScenarioValueError(key, str(exc), value) from exc


def load_path_robot(entry: RobotRef) -> tuple[Any, Any]:
    """The robot of a ``task`` or ``trajectory`` scenario and its path kinematics
    (:mod:`lynxplan.trajectory.kinematics`): the AL5 with its closed-form kernels, or a robot of
    :func:`lynxplan.load_robot` whose chain is a 5-joint yaw-pitch-pitch-pitch-roll arm
    (SO-100, SO-101, ...).

    Raises:
        ScenarioValueError: naming the ``robot`` key when the robot cannot be loaded or used.
    """
    from lynxplan.arm.model import Arm
    from lynxplan.trajectory.kinematics import Al5Kinematics, RobotKinematics

    robot = load_robot_entry(entry)
    if isinstance(robot, Arm):
        # The shipped AL5: SPEC's lengths (inches times 0.0254; the URDF's decimals agree to an
        # ulp). A URDF variant: its own lengths.
        return robot, Al5Kinematics(None if entry.urdf is None else robot.geometry)
    key = ("robot", "urdf" if entry.urdf is not None else "name")
    value = entry.urdf if entry.urdf is not None else entry.name
    if robot.nq != PATH_JOINTS:
        raise ScenarioValueError(
            key,
            f"robot {robot.name} has {robot.nq} joints; task and trajectory scenarios need a "
            "5-joint yaw-pitch-pitch-pitch-roll arm (al5, so100, so101)",
            value,
        )
    try:
        return robot, RobotKinematics(robot)
    except LynxplanError as exc:
        raise ScenarioValueError(key, str(exc), value) from exc
