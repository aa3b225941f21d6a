"""EAIK as a peer of ``lynxplan bench robots``: analytical IK by subproblem decomposition.

EAIK (``pip install eaik``, C++ with Python bindings; Ostermeier et al.) decomposes a chain of
at most six revolute joints into geometric subproblems and returns every solution of a pose. It
runs in lynxplan's own process (it installs next to lynxplan and pin 4), so it solves exactly the
poses of lynxplan's batch, in the same run.

The EAIK robot is built from the chain lynxplan loaded (the Pinocchio model, locked joints
removed, base and tool frame included), in EAIK's product-of-exponentials form at the zero
configuration: each joint's axis ``H`` (world frame) and the offsets ``P`` between points on
consecutive axes, base to first axis to ... to the tool point, with the tool's orientation
``R6T``. Its answers are judged by Pinocchio's FK of the same model (independent of EAIK and of
lynxplan's own FK): a pose is solved when one of EAIK's solutions reaches it within
:data:`POSITION_TOLERANCE` and :data:`ORIENTATION_TOLERANCE`. EAIK's own "least squares" flag is
not used: it marks some exact solutions too (SO-101, 2 of 2,000 poses, reached to 1e-13 m).
EAIK knows no joint limits; lynxplan's batch returns the branches within them, so a solved pose
here may have its solutions outside the limits.

EAIK's time is one core's: its batch call with one worker thread, in process CPU time (the
figure the ratio to lynxplan's batch uses).
"""

from __future__ import annotations

import time
from importlib import metadata
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from lynxplan.bench import Figure, median_seconds, meets, not_run, peer_missing

if TYPE_CHECKING:
    from lynxplan.robots import Robot

#: A pose is solved when an EAIK solution reaches it this closely (Pinocchio FK), [m] and [rad].
POSITION_TOLERANCE = 1e-9
ORIENTATION_TOLERANCE = 1e-9
SECTION = "robots"


class EaikAnswers(NamedTuple):
    """EAIK's answers to a set of poses, checked by Pinocchio's FK."""

    version: str
    """EAIK's version."""
    family: str
    """The kinematic family EAIK recognised, e.g. ``5R-SECOND_THIRD_FOURTH_PARALLEL``."""
    solutions: list[np.ndarray]
    """Per pose, EAIK's solutions, shape (k, n) [rad] (all of them, least-squares ones too)."""
    position_error: np.ndarray
    """Per pose, (N,): the smallest tool position error of its solutions [m] (inf: none)."""
    orientation_error: np.ndarray
    """Per pose, (N,): the smallest tool orientation error of its solutions [rad] (inf: none)."""
    solved: np.ndarray
    """Per pose, (N,): one solution is within both tolerances."""


class UnsupportedChainError(ValueError):
    """The chain is not one EAIK can take (a joint other than a 1-DOF revolute one, or more
    than six joints, or EAIK knows no decomposition of it)."""


def eaik_module() -> Any:
    """EAIK's bindings, or None when EAIK is not installed."""
    import importlib

    try:
        return importlib.import_module("eaik.pybindings.EAIK")
    except ImportError:
        return None


def chain_description(robot: Robot) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(H, P, R6T)`` of ``robot``'s chain at the zero configuration, in the world frame.

    ``H`` (n, 3): the joint axes; ``P`` (n + 1, 3): base to the first joint's origin, from each
    joint's origin to the next, and from the last to the tool point [m]; ``R6T`` (3, 3): the tool's
    orientation. Raises :class:`UnsupportedChainError` for a joint that is no 1-DOF revolute one.
    """
    import pinocchio as pin

    model = robot.model
    data = model.createData()
    for joint in list(model.joints)[1:]:
        kind = joint.shortname()
        if joint.nq != 1 or joint.nv != 1 or not kind.startswith("JointModelR"):
            raise UnsupportedChainError(f"joint type {kind} (EAIK takes 1-DOF revolute joints)")
    q = np.zeros(model.nq)
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    axes, origins = [], []
    for j in range(1, model.njoints):
        jacobian = pin.getJointJacobian(model, data, j, pin.ReferenceFrame.WORLD)
        axis = jacobian[3:, model.joints[j].idx_v]
        axes.append(axis / np.linalg.norm(axis))
        origins.append(np.array(data.oMi[j].translation))
    tool = data.oMf[robot.tool_frame_id]
    points = np.array([np.zeros(3), *origins, np.array(tool.translation)])
    return np.array(axes), np.diff(points, axis=0), np.array(tool.rotation)


def eaik_robot(robot: Robot) -> Any:
    """The EAIK robot of ``robot``'s chain (:func:`chain_description`).

    Raises:
        UnsupportedChainError: EAIK cannot take the chain, or knows no decomposition of it.
        ImportError: EAIK is not installed.
    """
    bindings = eaik_module()
    if bindings is None:
        raise ImportError("eaik is not installed")
    axes, offsets, tool = chain_description(robot)
    if len(axes) > 6:
        raise UnsupportedChainError(f"{len(axes)} joints (EAIK takes at most 6)")
    solver = bindings.Robot(axes.T.copy(), offsets.T.copy(), tool, [], True)
    family = str(solver.get_kinematic_family())
    # eaik 1.2.2 says it knows a decomposition of a 5R chain of an "Unknown Kinematic Class",
    # then prints a warning and returns no solution for each pose.
    if not solver.has_known_decomposition() or "unknown" in family.lower():
        raise UnsupportedChainError(f"no known subproblem decomposition ({family})")
    return solver


def solve(robot: Robot, poses: np.ndarray) -> EaikAnswers:
    """EAIK's answers to ``poses`` (N, 4, 4), each solution checked by Pinocchio's FK."""
    import pinocchio as pin

    solver = eaik_robot(robot)
    model, data, tool = robot.model, robot.model.createData(), robot.tool_frame_id
    solutions, position_error, orientation_error = [], [], []
    for target in poses:
        found = np.asarray(solver.calculate_IK(target).Q, dtype=float).reshape(-1, model.nq)
        errors = []  # (position, orientation) of each solution
        for q in found:
            pin.framesForwardKinematics(model, data, q)
            reached = data.oMf[tool]
            errors.append((
                float(np.linalg.norm(reached.translation - target[:3, 3])),
                float(np.linalg.norm(pin.log3(reached.rotation.T @ target[:3, :3]))),
            ))  # fmt: skip
        # The pose's answer: the solution nearest to it, each error in units of its tolerance.
        gap, turn = min(
            errors,
            key=lambda e: max(e[0] / POSITION_TOLERANCE, e[1] / ORIENTATION_TOLERANCE),
            default=(np.inf, np.inf),
        )
        solutions.append(found)
        position_error.append(gap)
        orientation_error.append(turn)
    positions, orientations = np.array(position_error), np.array(orientation_error)
    solved = (positions <= POSITION_TOLERANCE) & (orientations <= ORIENTATION_TOLERANCE)
    family = str(solver.get_kinematic_family())
    return EaikAnswers(metadata.version("eaik"), family, solutions, positions, orientations, solved)


def seconds_per_pose(robot: Robot, poses: np.ndarray) -> float:
    """EAIK's time per pose on one core: its batch call with one worker thread, median of five
    runs, in process CPU time [s]."""
    solver = eaik_robot(robot)
    batch = [np.ascontiguousarray(pose) for pose in poses]
    seconds = median_seconds(
        lambda: solver.calculate_IK_batched(batch, 1), repeats=5, clock=time.process_time
    )
    return seconds / len(batch)


def figures(robot: Robot, poses: np.ndarray, ours: float, target: str = "") -> list[Figure]:
    """EAIK's success, worst error and time on ``poses``, and lynxplan's speed-up over it
    (``ours``: lynxplan's batch time per pose [s]; ``target``: the speed-up's, or empty)."""
    name = robot.name
    if eaik_module() is None:
        return [peer_missing(SECTION, f"{name} eaik", "Python module eaik (pip install eaik)")]
    try:
        answers = solve(robot, poses)
        eaik = seconds_per_pose(robot, poses)
    except UnsupportedChainError as error:  # a fact about the chain, not a failure: 0 % solved
        label = f"{name} eaik {metadata.version('eaik')} success ({len(poses)} full poses)"
        return [Figure(SECTION, f"{label}: cannot solve this chain: {error}", 0.0, "%")]
    except Exception as error:  # an installed peer that fails: reported, the others still run
        return [not_run(SECTION, f"{name} eaik", f"peer failed: {type(error).__name__}: {error}")]
    label = f"{name} eaik {answers.version}"
    speed_up = eaik / ours
    worst = float(answers.position_error.max()) if len(poses) else np.nan
    return [
        Figure(
            SECTION,
            f"{label} success ({len(poses)} full poses, {answers.family}, Pinocchio FK)",
            100 * float(answers.solved.mean()),
            "%",
        ),
        Figure(SECTION, f"{label} worst position error", worst, "m"),
        Figure(SECTION, f"{label} time per pose (batch, 1 thread, CPU)", eaik * 1e6, "us"),
        Figure(
            SECTION,
            f"{name} lynxplan batch speed-up over eaik (same poses)",
            speed_up,
            "x",
            target,
            meets(speed_up, target) if target else None,
        ),
    ]
