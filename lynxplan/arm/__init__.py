"""The 5-DOF arm: URDF model, closed-form kinematics, analytic IK, workspace."""

from lynxplan.arm.geometry import ArmGeometry, JointLimits
from lynxplan.arm.ik import BRANCH_NAMES, IkBatch, IkStatus, select_continuous, solve_ik_batch
from lynxplan.arm.kinematics import forward_kinematics, tool_jacobian
from lynxplan.arm.model import Arm, IkResult, IkSolution, load_arm

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
