"""``robot:`` entries of scenarios -> loaded robots (at run time, never during validation)."""

from __future__ import annotations

from typing import Any

from lynxplan.exceptions import ScenarioError
from lynxplan.scenarios.base import RobotRef

#: Built-in robot names the arm scenario kinds run today.
ARM_KINDS_ROBOTS = ("al5",)


def load_arm_robot(ref: RobotRef, origin: str = "<scenario>") -> Any:
    """The AL5-class arm a ``robot:`` entry names (the shipped AL5 by default).

    Raises:
        ScenarioError: for a robot name this kind cannot plan with.
    """
    from lynxplan.arm.model import load_arm

    if ref.urdf is not None:
        return load_arm(ref.urdf)
    if ref.name in (None, *ARM_KINDS_ROBOTS):
        return load_arm()
    raise ScenarioError(
        origin, "robot.name", f"unknown robot {ref.name!r}; valid: {', '.join(ARM_KINDS_ROBOTS)}"
    )
