"""The 5-DOF arm: URDF model, closed-form kinematics, analytic IK, workspace.

Attributes load on first use, so ``from lynxplan.arm import load_arm`` does not compile or load
the numba kernels (FK-only commands start fast).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from lynxplan.arm.geometry import ArmGeometry, JointLimits
    from lynxplan.arm.ik import BRANCH_NAMES, IkBatch, IkStatus, select_continuous, solve_ik_batch
    from lynxplan.arm.kinematics import forward_kinematics, tool_jacobian
    from lynxplan.arm.model import Arm, IkResult, IkSolution, load_arm

#: Public name -> module that defines it.
_HOMES = {
    "ArmGeometry": "lynxplan.arm.geometry",
    "JointLimits": "lynxplan.arm.geometry",
    "BRANCH_NAMES": "lynxplan.arm.ik",
    "IkBatch": "lynxplan.arm.ik",
    "IkStatus": "lynxplan.arm.ik",
    "select_continuous": "lynxplan.arm.ik",
    "solve_ik_batch": "lynxplan.arm.ik",
    "forward_kinematics": "lynxplan.arm.kinematics",
    "tool_jacobian": "lynxplan.arm.kinematics",
    "Arm": "lynxplan.arm.model",
    "IkResult": "lynxplan.arm.model",
    "IkSolution": "lynxplan.arm.model",
    "load_arm": "lynxplan.arm.model",
}

__all__ = [
    "BRANCH_NAMES",
    "Arm",
    "ArmGeometry",
    "IkBatch",
    "IkResult",
    "IkSolution",
    "IkStatus",
    "JointLimits",
    "forward_kinematics",
    "load_arm",
    "select_continuous",
    "solve_ik_batch",
    "tool_jacobian",
]


def __getattr__(name: str) -> Any:
    if name in _HOMES:
        return getattr(importlib.import_module(_HOMES[name]), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
