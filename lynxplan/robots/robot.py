"""A robot arm loaded from URDF: one surface for every arm (FK, IK, Jacobian, tracking, limits).

IK picks its solver from the geometry: the closed form (with a roll root search for an off-axis
tool where the orientation does not give the roll: approach targets, poses out of reach) when
the chain is yaw-pitch-pitch-pitch-roll (the AL5, SO-100, SO-101), the numerical solver
otherwise.

Targets: a full pose (4x4; for a 5-joint arm solved in the least-squares sense: the position
exactly, the approach axis projected into the arm plane, the roll nearest), a position plus an
approach direction (the roll free or given), or a position plus an approach pitch (the angle from
straight down towards the outward direction of the arm plane; the AL5's q2 + q3 + q4).
"""

from __future__ import annotations

from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan._arrays import kernel_input
from lynxplan.constants import (
    LIMIT_SNAP_TOLERANCE,
    PINOCCHIO_AGREEMENT,
    REACH_TOLERANCE,
)
from lynxplan.exceptions import ShapeError, TargetError
from lynxplan.joint_limits import JointLimits
from lynxplan.robots import chain as _chain
from lynxplan.robots.family import FamilyParameters, recognise_family
from lynxplan.robots.hull_cache import geometry_model
from lynxplan.robots.ik import dispatch
from lynxplan.robots.ik.description import Kinematics
from lynxplan.robots.loading import BuiltinRobot, LoadedModel
from lynxplan.robots.results import (
    JointInfo,
    RobotIkBatch,
    RobotIkResult,
    RobotIkSolution,
    RobotInfo,
    TrackResult,
)
from lynxplan.robots.selection import (
    NEAREST,
    REPORT,
    by_report_rule,
    select_one,
)
from lynxplan.robots.targets import (
    KIND_APPROACH,
    KIND_PITCH,
    KIND_POSE,
    Target,
    as_array,
    make_target,
)
from lynxplan.robots.tracking import TRACK_JUMP_THRESHOLD, track

__all__ = [
    "KIND_APPROACH",
    "KIND_PITCH",
    "KIND_POSE",
    "REACH_TOLERANCE",
    "TRACK_JUMP_THRESHOLD",
    "Robot",
    "Target",
    "make_target",
]


class Robot:
    """A robot arm from URDF (see the module docstring).

    Attributes:
        name: Built-in name or URDF file name.
        urdf_path: The URDF.
        model: Pinocchio model of the arm chain (fixed base, locked joints removed).
        data: Pinocchio data of ``model``.
        tool_frame: Tool frame name; ``tool_frame_id`` its id.
        locked_joints: Joints off the chain (gripper jaw), with the value they are held at.
        limits: Joint position and velocity limits (``position`` (n, 2) [rad], ``velocity`` (n,)).
        family: Recognised family parameters, or None (then IK is numerical).
        family_reason: The family name, or why the chain is not in it.
        disabled_collisions: Link pairs not checked for self-collision (from the SRDF).
        nq: Number of joints.
        kinematics: What the IK solvers know of the arm (chain, family, limits): plain data.
    """

    def __init__(self, loaded: LoadedModel, builtin: BuiltinRobot | None = None) -> None:
        self.name = loaded.name
        self.urdf_path = Path(loaded.urdf)
        self.model = loaded.model
        self.data = self.model.createData()
        self.tool_frame = loaded.tool_frame
        self.tool_frame_id = loaded.tool_frame_id
        self.locked_joints = loaded.locked_joints
        self.package_dirs = loaded.package_dirs
        self.disabled_collisions = loaded.disabled_collisions
        self._urdf_xml = loaded.urdf_xml
        self.builtin = builtin
        #: The branch-selection rules ``ik`` offers (``select``): "nearest"; the AL5 also
        #: "report" (SPEC Part 1's rule).
        self.selection_rules = builtin.selection_rules if builtin is not None else (NEAREST,)
        self.nq = int(self.model.nq)
        position = np.column_stack((self.model.lowerPositionLimit, self.model.upperPositionLimit))
        velocity = np.array(self.model.velocityLimit, dtype=float)
        position.setflags(write=False)
        velocity.setflags(write=False)
        self.limits = JointLimits(position=position, velocity=velocity)
        self.joint_names = tuple(str(n) for n in list(self.model.names)[1:])
        self.chain = _chain.chain_from_model(self.model, self.tool_frame_id)
        family, reason = recognise_family(
            self.model,
            self.tool_frame_id,
            self.limits.lower,
            self.limits.upper,
            LIMIT_SNAP_TOLERANCE,
        )
        self.family: FamilyParameters | None = family
        self.family_reason = reason
        self.kinematics = Kinematics(self.chain, family, self.limits.lower, self.limits.upper)

    # -- description ------------------------------------------------------------------------
    @property
    def urdf_xml(self) -> str:
        """The URDF text as loaded, its locked joints made fixed (what the geometry models and
        peers built from this robot read)."""
        return str(self._urdf_xml)

    @property
    def ik_solver(self) -> str:
        """Name of the IK solver this robot uses."""
        return self.kinematics.solver_name

    def info(self) -> RobotInfo:
        """Joints, limits, family and its parameters, IK solver."""
        joints = tuple(
            JointInfo(n, float(lo), float(hi), float(v))
            for n, (lo, hi), v in zip(
                self.joint_names, self.limits.position, self.limits.velocity, strict=True
            )
        )
        return RobotInfo(
            self.name,
            str(self.urdf_path),
            self.tool_frame,
            joints,
            self.locked_joints,
            self.family_reason,
            self.family,
            self.ik_solver,
        )

    def __repr__(self) -> str:
        return f"Robot({self.name!r}, tool={self.tool_frame!r}, nq={self.nq})"

    # -- geometry models -----------------------------------------------------------------------
    @cached_property
    def collision_model(self) -> Any:
        """Pinocchio GeometryModel of the collision geometry lynxplan checks: the URDF's
        collision elements, meshes as their convex hulls (hull files cached on disk, see
        :mod:`lynxplan.robots.hull_cache`; the originals: :attr:`collision_mesh_model`)."""
        return geometry_model(self, "collision", hulls=True)

    @cached_property
    def collision_mesh_model(self) -> Any:
        """Pinocchio GeometryModel of the URDF's collision elements as written."""
        return geometry_model(self, "collision", hulls=False)

    @cached_property
    def visual_model(self) -> Any:
        """Pinocchio GeometryModel of the URDF's visual elements."""
        return geometry_model(self, "visual", hulls=False)

    def _mesh_dirs(self) -> tuple[str, ...]:
        return (*self.package_dirs, str(self.urdf_path.parent))

    # -- kinematics ----------------------------------------------------------------------------
    def _configurations(self, q: Any, name: str = "q") -> np.ndarray:
        return np.ascontiguousarray(as_array(q, name, (self.nq,)))

    def fk(self, q: Any) -> np.ndarray:
        """Tool pose. q: shape (n,) or (N, n) in [rad] -> (4, 4) or (N, 4, 4), in [m]."""
        configs = self._configurations(q)
        out = np.empty((configs.shape[0], 4, 4))
        _chain.chain_fk_batch(self.chain.placements, self.chain.axes, kernel_input(configs), out)
        return out[0] if np.ndim(q) == 1 else out

    def jacobian(self, q: Any) -> np.ndarray:
        """Geometric tool Jacobian, LOCAL_WORLD_ALIGNED (rows: linear [m/s], angular [rad/s]).

        q: shape (n,) or (N, n) in [rad] -> (6, n) or (N, 6, n).
        """
        configs = self._configurations(q)
        out = np.empty((configs.shape[0], 6, self.nq))
        _chain.chain_jacobian_batch(self.chain.placements, self.chain.axes, configs, out)
        return out[0] if np.ndim(q) == 1 else out

    def frame_placement(self, q: Any, frame: str | None = None) -> np.ndarray:
        """Pose of a frame computed by Pinocchio. q: shape (n,) [rad] -> (4, 4) [m]."""
        import pinocchio as pin

        from lynxplan.exceptions import ModelError

        config = self._configurations(q)[0]
        name = frame or self.tool_frame
        if not self.model.existFrame(name):
            raise ModelError(f"unknown frame {name!r}")
        frame_id = self.tool_frame_id if frame is None else self.model.getFrameId(name)
        pin.forwardKinematics(self.model, self.data, config)
        return np.array(pin.updateFramePlacement(self.model, self.data, frame_id).homogeneous)

    def approach(self, q: Any) -> np.ndarray:
        """Approach axis (the roll axis, towards the tool; the tool z axis for non-family arms).

        q: (n,) or (N, n) [rad] -> (3,) or (N, 3), unit vectors in the base frame.
        """
        poses = self.fk(q)
        return np.asarray(poses[..., :3, :3] @ self.approach_in_tool)

    @property
    def approach_in_tool(self) -> np.ndarray:
        """The approach axis in tool-frame coordinates, shape (3,)."""
        if self.family is None:
            return np.array([0.0, 0.0, 1.0])
        return np.array(self.family.approach_in_tool)

    # -- inverse kinematics --------------------------------------------------------------------
    @cached_property
    def _default_reference(self) -> np.ndarray:
        """Zeros clipped into the limits, shape (1, n), [rad] (the kernels only read it)."""
        return np.clip(np.zeros((1, self.nq)), self.limits.lower, self.limits.upper)

    def _reference(self, q_reference: Any, n: int) -> np.ndarray:
        if q_reference is None:
            return self._default_reference
        ref = np.ascontiguousarray(as_array(q_reference, "q_reference", (self.nq,)))
        if ref.shape[0] not in (1, n):
            raise ShapeError("q_reference", f"({self.nq},) or ({n}, {self.nq})", ref.shape)
        return ref

    def ik_batch(
        self,
        poses: Any = None,
        *,
        positions: Any = None,
        approaches: Any = None,
        pitches: Any = None,
        rolls: Any = None,
        q_reference: Any = None,
    ) -> RobotIkBatch:
        """Every IK branch of N targets. Never raises for unreachable targets.

        Args:
            poses: Full target poses, shape (N, 4, 4), [m]; or
            positions: Target tool points, shape (N, 3), [m], with
            approaches: approach directions, shape (N, 3) (any length > 0), or
            pitches: approach pitches, shape (N,), [rad] (from straight down, outwards).
            rolls: Roll joint angle, shape (N,) or scalar, [rad]; NaN/None: free.
            q_reference: (n,) or (N, n) [rad]: yaw on the base axis, roll when free and
                undetermined, first start of the numerical solver.

        Returns:
            A :class:`RobotIkBatch`: unreachable targets get their nearest solution,
            ``reachable`` False and the ``distance``. Its B branch slots (``branch_names``):
            4 (side x elbow) where the roll is given or the tool is on the roll axis; for an
            off-axis tool, 8 for full poses (side x 2 rolls x elbow: the orientation fixes the
            roll up to the flip of the yaw) and 24 for approach targets (side x 6 roots of the
            roll equation x elbow).
        """
        target = make_target(poses, positions, approaches, pitches, rolls)
        reference = self._reference(q_reference, target.poses.shape[0])
        return dispatch.solve(self.kinematics, target, reference)

    def ik(
        self,
        pose: Any = None,
        *,
        position: Any = None,
        approach: Any = None,
        pitch: float | None = None,
        roll: float | None = None,
        q_reference: Any = None,
        verify: bool = False,
        approach_only: bool = False,
        select: str = "nearest",
    ) -> RobotIkResult:
        """IK of one target: every branch, verified, one selected (by ``select``).

        Args:
            pose: Target tool pose, shape (4, 4), [m]; or ``position`` (3,) [m] with
                ``approach`` (3,) or ``pitch`` [rad]; ``roll`` [rad] fixes the roll joint.
            q_reference: Shape (n,), [rad]: configuration to stay near. Default: zeros.
            approach_only: ``lynxplan.arm.Arm.ik`` compatibility: ``pose`` is a position (column
                3) and an approach direction (column 2); the roll is ``roll``, else the roll of
                ``q_reference`` (else free).
            select: ``"nearest"`` (every robot: within the limits, nearest ``q_reference``) or
                a rule of the robot's own (``selection_rules``): the AL5's ``"report"``, the
                first branch within the limits with q2 >= 0 and q3 <= 0.
            verify: Also re-check each branch with Pinocchio's FK (adds ~5 us per branch). Every
                branch is always verified by the solver's FK of the exact chain (the same
                product of exponentials; equal to Pinocchio's to 1e-15 m in the tests).

        Raises:
            ShapeError, NonFiniteInputError, TargetError: malformed target, or a ``select``
                rule the robot does not offer.
        """
        if pose is not None and np.shape(pose) != (4, 4):
            raise ShapeError("pose", "(4, 4)", np.shape(pose))
        if select not in self.selection_rules:
            rules = ", ".join(repr(r) for r in self.selection_rules)
            raise TargetError(f"select: {self.name} offers {rules}. Got: {select!r:.40}")
        if (
            pose is not None
            and position is None
            and approach is None
            and pitch is None
            and roll is None
            and not approach_only
            and self.family is not None
        ):
            # the lean paths; a pose they cannot solve (NaN/inf, out of reach) goes on below
            one = dispatch.solve_pose_one(self.kinematics, pose, self._reference(q_reference, 1)[0])
            if one is not None:
                return self._finished(one, select, verify)
        if approach_only:
            if pose is None:
                raise TargetError("approach_only needs a pose (position and approach columns)")
            frame = np.asarray(pose, dtype=float)
            if roll is None and q_reference is not None:
                roll = float(np.asarray(q_reference, dtype=float).reshape(-1)[-1])
            pose, position, approach = None, frame[:3, 3], frame[:3, 2]
        target = make_target(
            pose,
            position,
            approach,
            None if pitch is None else [pitch],
            None if roll is None else [roll],
        )
        reference = self._reference(q_reference, 1)
        result = select_one(
            dispatch.solve(self.kinematics, target, reference), reference[0], self.ik_solver
        )
        return self._finished(result, select, verify)

    def _finished(self, result: RobotIkResult, select: str, verify: bool) -> RobotIkResult:
        """``result`` selected by the rule ``select`` (it comes selected by "nearest"),
        verified by Pinocchio's FK where ``verify``."""
        if select == REPORT:
            result = by_report_rule(result)
        return self._verified(result) if verify else result

    def _verified(self, result: RobotIkResult) -> RobotIkResult:
        """``result``, once Pinocchio's FK of each branch agrees with the solver's own FK.

        Raises:
            IkFailedError: a branch where they disagree by more than PINOCCHIO_AGREEMENT (1e-12 m).
        """
        from lynxplan.exceptions import IkFailedError

        solutions: tuple[RobotIkSolution, ...] = result.solutions
        for s in solutions:
            placement = self.frame_placement(s.q)
            own = self.fk(s.q)
            gap = float(np.abs(placement[:3] - own[:3]).max())
            if gap > PINOCCHIO_AGREEMENT:
                raise IkFailedError(s.position_error, f"Pinocchio FK disagrees by {gap:.3g} m")
        return result

    def ik_track(
        self,
        poses: Any = None,
        q0: Any = None,
        *,
        positions: Any = None,
        approaches: Any = None,
        pitches: Any = None,
        rolls: Any = None,
        jump_threshold: float = TRACK_JUMP_THRESHOLD,
    ) -> TrackResult:
        """IK along a sequence of targets, each step on the branch nearest the previous step.

        Args:
            poses / positions + approaches / pitches, rolls: N targets as in :meth:`ik_batch`.
            q0: Configuration before the first target, shape (n,), [rad]. Default: zeros.
            jump_threshold: A step changing some joint by more than this [rad] is flagged.

        Returns:
            A :class:`TrackResult`: the configurations, the branch per step, the flagged jumps
            (index, size) and the unsolved indices; never a silent branch flip.
        """
        target = make_target(poses, positions, approaches, pitches, rolls)
        start = self._reference(q0, 1)[0]
        return track(self.kinematics, target, start, q0 is not None, jump_threshold)

    # -- workspace -----------------------------------------------------------------------------
    def workspace(self, samples: int = 100_000, seed: int = 0) -> np.ndarray:
        """Tool points of uniformly random configurations within the limits.

        Returns: shape (samples, 3), in [m].
        """
        rng = np.random.default_rng(seed)
        q = rng.uniform(self.limits.lower, self.limits.upper, size=(int(samples), self.nq))
        return np.array(self.fk(q)[:, :3, 3])

    def random_configurations(self, count: int, seed: int = 0) -> np.ndarray:
        """Uniformly random configurations within the limits, shape (count, n), in [rad]."""
        rng = np.random.default_rng(seed)
        return rng.uniform(self.limits.lower, self.limits.upper, size=(int(count), self.nq))
