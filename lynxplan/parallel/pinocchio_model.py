"""Pinocchio model of the closed-loop 3-RRR: three RR legs from the base plus the platform.

The kinematic tree is leg A (actuated joint, elbow) carrying the platform through its platform
joint, and legs B and C (actuated joint, elbow) ending at free distal tips. The two remaining
loops are closed by :class:`pinocchio.PointAnchorConstraintModel` constraints that require the
distal tips of legs B and C to coincide with platform joints B and C. All revolute axes are the
base z axis. Lengths in [m], angles in [rad]. Used to verify the closed-form IK (closure residual)
and to cross-check the FK by solving the closure constraints numerically.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lynxplan.parallel.geometry import LEG_NAMES, PLATFORM_PHASES, ParallelGeometry
from lynxplan.parallel.ik import elbows, platform_joints


@dataclass(frozen=True)
class ClosedLoopModel:
    """A Pinocchio model of the 3-RRR with its loop-closure constraints.

    Attributes:
        model: The kinematic tree (7 revolute joints), a ``pinocchio.Model``.
        constraints: The two point-anchor closure constraints (legs B and C).
        actuated: Indices in ``q`` of the actuated joints of legs A, B, C, shape (3,).
        passive: Indices in ``q`` of the passive joints (elbows and platform joint), shape (4,).
        geometry: The robot dimensions the model was built from.
    """

    model: Any
    constraints: tuple[Any, ...]
    actuated: np.ndarray
    passive: np.ndarray
    geometry: ParallelGeometry

    def index(self, joint: str) -> int:
        """Index in ``q`` of the joint named ``joint`` (e.g. ``"theta_A"``, ``"platform"``)."""
        return int(self.model.joints[self.model.getJointId(joint)].idx_q)


def _placement(x: float, y: float) -> Any:
    import pinocchio as pin

    return pin.SE3(np.eye(3), np.array([x, y, 0.0]))


def build_closed_loop_model(geometry: ParallelGeometry | None = None) -> ClosedLoopModel:
    """Build the Pinocchio tree and the closure constraints of the 3-RRR."""
    import pinocchio as pin

    geometry = geometry or ParallelGeometry()
    model = pin.Model()
    model.name = "three_rrr"
    s, el, rp = geometry.proximal, geometry.distal, geometry.platform_circumradius
    # Platform frame: origin at platform joint A, x axis at the platform orientation alpha. Its
    # centre and joints B, C are fixed vectors there (SPEC Part 4: joint i at c - rp u_i).
    unit = np.array([[math.cos(p), math.sin(p)] for p in PLATFORM_PHASES])
    inertia = pin.Inertia(0.1, np.zeros(3), np.eye(3) * 1e-3)
    elbow_ids = []
    platform_id = 0
    for i, name in enumerate(LEG_NAMES):
        bx, by = geometry.base_joints[i]
        theta = model.addJoint(0, pin.JointModelRZ(), _placement(bx, by), f"theta_{name}")
        model.appendBodyToJoint(theta, inertia, pin.SE3.Identity())
        elbow = model.addJoint(theta, pin.JointModelRZ(), _placement(s, 0.0), f"elbow_{name}")
        model.appendBodyToJoint(elbow, inertia, pin.SE3.Identity())
        model.addFrame(pin.Frame(f"tip_{name}", elbow, _placement(el, 0.0), pin.FrameType.OP_FRAME))
        elbow_ids.append(elbow)
        if i == 0:
            platform_id = model.addJoint(elbow, pin.JointModelRZ(), _placement(el, 0.0), "platform")
            model.appendBodyToJoint(platform_id, inertia, pin.SE3.Identity())
            cx, cy = rp * unit[0]
            model.addFrame(
                pin.Frame(
                    "platform_centre", platform_id, _placement(cx, cy), pin.FrameType.OP_FRAME
                )
            )
    constraints = []
    for i in (1, 2):
        joint_offset = rp * (unit[0] - unit[i])
        constraint = pin.PointAnchorConstraintModel(
            model, elbow_ids[i], _placement(el, 0.0), platform_id, _placement(*joint_offset)
        )
        constraint.name = f"closure_{LEG_NAMES[i]}"
        constraints.append(constraint)
    closed = ClosedLoopModel(
        model, tuple(constraints), np.empty(0, int), np.empty(0, int), geometry
    )
    actuated = np.array([closed.index(f"theta_{n}") for n in LEG_NAMES])
    passive = np.array([closed.index(j) for j in ("elbow_A", "platform", "elbow_B", "elbow_C")])
    return ClosedLoopModel(model, tuple(constraints), actuated, passive, geometry)


def configuration_from_pose(
    closed: ClosedLoopModel, pose: np.ndarray, theta: np.ndarray
) -> np.ndarray:
    """Joint configuration ``q`` (7,) of the tree for a pose (3,) in [m, m, rad] and the actuated
    angles ``theta`` (3,) in [rad] of one of its working modes (passive angles by geometry)."""
    pose = np.asarray(pose, dtype=float)
    theta = np.asarray(theta, dtype=float)
    joint = platform_joints(pose, closed.geometry)
    elbow = elbows(theta, closed.geometry)
    distal = np.arctan2(joint[:, 1] - elbow[:, 1], joint[:, 0] - elbow[:, 0])
    q = np.zeros(closed.model.nq)
    for i, name in enumerate(LEG_NAMES):
        q[closed.index(f"theta_{name}")] = theta[i]
        q[closed.index(f"elbow_{name}")] = distal[i] - theta[i]
    q[closed.index("platform")] = pose[2] - distal[0]
    return q


def closure_errors(closed: ClosedLoopModel, q: np.ndarray, data: Any = None) -> np.ndarray:
    """Position error of each closure constraint, shape (2, 3), in [m] (constraint frame)."""
    import pinocchio as pin

    data = data if data is not None else closed.model.createData()
    pin.forwardKinematics(closed.model, data, np.asarray(q, dtype=float))
    errors = []
    for constraint in closed.constraints:
        cdata = constraint.createData()
        constraint.calc(closed.model, data, cdata)
        errors.append(np.array(cdata.constraint_position_error))
    return np.array(errors)


def closure_residual(closed: ClosedLoopModel, q: np.ndarray) -> float:
    """Largest distance between a distal tip and its platform joint, in [m]."""
    return float(np.max(np.linalg.norm(closure_errors(closed, q), axis=1)))


def platform_pose(closed: ClosedLoopModel, q: np.ndarray) -> np.ndarray:
    """Platform pose ``(xc, yc, alpha)`` (3,) in [m, m, rad] of the tree configuration ``q``."""
    import pinocchio as pin

    data = closed.model.createData()
    pin.framesForwardKinematics(closed.model, data, np.asarray(q, dtype=float))
    placement = data.oMf[closed.model.getFrameId("platform_centre")]
    rotation = placement.rotation
    return np.array(
        [
            placement.translation[0],
            placement.translation[1],
            math.atan2(rotation[1, 0], rotation[0, 0]),
        ]
    )


def solve_closure(
    closed: ClosedLoopModel,
    theta: np.ndarray,
    q0: np.ndarray,
    *,
    tolerance: float = 1e-13,
    max_iterations: int = 50,
) -> tuple[np.ndarray, bool]:
    """Solve the closure constraints for the passive joints with the actuated joints at ``theta``.

    Gauss-Newton on the constraint position errors with the constraint Jacobians' passive columns
    (a numerical FK, independent of the closed-form one).

    Args:
        closed: The model.
        theta: Actuated angles, shape (3,), in [rad].
        q0: Initial configuration, shape (7,) (its actuated entries are replaced by ``theta``).
        tolerance: Stop when the largest closure error is below this, in [m].
        max_iterations: Iteration limit.

    Returns:
        The configuration (7,) and whether it converged.
    """
    import pinocchio as pin

    model = closed.model
    data = model.createData()
    q = np.array(q0, dtype=float)
    q[closed.actuated] = theta
    cdatas = [c.createData() for c in closed.constraints]
    for _ in range(max_iterations):
        pin.computeJointJacobians(model, data, q)
        rows, jac = [], []
        for constraint, cdata in zip(closed.constraints, cdatas, strict=True):
            constraint.calc(model, data, cdata)
            rows.append(np.array(cdata.constraint_position_error)[:2])
            jac.append(np.array(constraint.jacobian(model, data, cdata))[:2, closed.passive])
        error = np.concatenate(rows)
        if np.max(np.abs(error)) < tolerance:
            return q, True
        step = np.linalg.lstsq(np.vstack(jac), error, rcond=None)[0]
        q[closed.passive] -= step
    pin.forwardKinematics(model, data, q)
    return q, closure_residual(closed, q) < tolerance * 10
