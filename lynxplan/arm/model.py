"""The 5-DOF arm as a Pinocchio model built from its URDF, with closed-form kinematics and IK.

:func:`load_arm` returns the default AL5-class arm. The URDF's joint placements are checked
against the DH structure of SPEC Part 1 and its lengths (a2, a3, d5) are read from it, so an arm
of the same structure with other dimensions works through the same closed forms.
"""

from __future__ import annotations

from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np

from lynxplan import guards
from lynxplan._arrays import kernel_input
from lynxplan.arm.configuration import as_configurations
from lynxplan.arm.geometry import TOOL_FRAME
from lynxplan.arm.ik_result import SOLVER, IkResult, IkSolution
from lynxplan.arm.urdf import native_stderr_captured, read_geometry, read_limits
from lynxplan.constants import (
    LIMIT_SNAP_TOLERANCE,
    RIGIDITY_REPAIR_TOLERANCE,
    STRICT_ORIENTATION_TOLERANCE,
)
from lynxplan.exceptions import (
    InputError,
    ModelError,
    NonFiniteInputError,
    NotRigidTransformError,
    OrientationNotReachableError,
    ShapeError,
    UnreachablePoseError,
)
from lynxplan.shipped import DEFAULT_URDF_NAME, default_urdf_path

__all__ = [
    "DEFAULT_URDF_NAME",
    "Arm",
    "IkResult",
    "IkSolution",
    "default_urdf_path",
    "load_arm",
    "native_stderr_captured",
]

if TYPE_CHECKING:
    from types import ModuleType

    from lynxplan.arm.ik import IkBatch

_IK_MODULE: ModuleType | None = None


def _ik() -> ModuleType:
    """:mod:`lynxplan.arm.ik`, imported on first use (numba: FK-only commands start faster)."""
    global _IK_MODULE
    if _IK_MODULE is None:
        from lynxplan.arm import ik

        _IK_MODULE = ik
    return _IK_MODULE


# The default IK reference, writable like every kernel input (kernel_input); never written.
_ZEROS = np.zeros(5)
_BOTTOM_ROW = np.array([0.0, 0.0, 0.0, 1.0])


Selection = Literal["nearest", "report"]


class Arm:
    """The 5-DOF arm: Pinocchio model + closed-form kinematics + analytic IK.

    Attributes:
        urdf_path: The URDF the model was built from.
        model: Pinocchio kinematic model (5 revolute joints).
        geometry: DH lengths read from the URDF.
        limits: Position and velocity limits read from the URDF.
        tool_frame_id: Pinocchio frame id of the tool (pen tip, DH frame 5).
    """

    def __init__(self, urdf_path: str | Path | None = None) -> None:
        import pinocchio as pin

        self.urdf_path = Path(urdf_path) if urdf_path is not None else default_urdf_path()
        if not self.urdf_path.is_file():
            raise ModelError(f"URDF file not found: {self.urdf_path}")
        with native_stderr_captured() as noise:
            try:
                self.model = pin.buildModelFromUrdf(str(self.urdf_path))
            except (RuntimeError, ValueError) as exc:
                detail = " ".join(noise().split())[:200]
                extra = f" (parser: {detail})" if detail else ""
                raise ModelError(f"cannot load URDF {self.urdf_path}: {exc}{extra}") from exc
        self.data = self.model.createData()
        self.geometry = read_geometry(self.model)
        self.limits = read_limits(self.model)
        self.tool_frame_id = self.model.getFrameId(TOOL_FRAME)
        # Packed parameters of the single-pose IK kernel: a2, a3, d5, snap tolerance, limits
        # (writable, as every kernel input: one compiled signature, see kernel_input).
        g = self.geometry
        self._ik_params = np.concatenate(
            ([g.a2, g.a3, g.d5, LIMIT_SNAP_TOLERANCE], self.limits.lower, self.limits.upper)
        )

    # -- geometry models (collision and visual), built on first use ------------------------------
    @cached_property
    def collision_model(self) -> Any:
        """Pinocchio GeometryModel of the URDF's collision elements."""
        from lynxplan.mesh_paths import urdf_geometry_model

        return urdf_geometry_model(self.model, self.urdf_path, (), "collision")

    @cached_property
    def visual_model(self) -> Any:
        """Pinocchio GeometryModel of the URDF's visual elements."""
        from lynxplan.mesh_paths import urdf_geometry_model

        return urdf_geometry_model(self.model, self.urdf_path, (), "visual")

    # -- kinematics -------------------------------------------------------------------------------
    def fk(self, q: np.ndarray) -> np.ndarray:
        """Tool pose (closed form). q: shape (5,) or (N, 5) in [rad] -> (4, 4) or (N, 4, 4), [m].

        Raises:
            LynxplanInputError: q of another shape or dtype, NaN/Inf, |q| > 100 rad, a batch
                beyond the resource limit (see :mod:`lynxplan.guards`).
        """
        from lynxplan.arm.kinematics import forward_kinematics

        return forward_kinematics(guards.configurations("q", q), self.geometry)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Geometric tool Jacobian, LOCAL_WORLD_ALIGNED: (5,) or (N, 5) -> (6, 5) or (N, 6, 5).

        Raises:
            LynxplanInputError: as :meth:`fk`.
        """
        from lynxplan.arm.kinematics import tool_jacobian

        return tool_jacobian(guards.configurations("q", q), self.geometry)

    def frame_placement(self, q: np.ndarray, frame: str = TOOL_FRAME) -> np.ndarray:
        """Pose of a URDF frame from Pinocchio. q: shape (5,) in [rad] -> (4, 4) in [m].

        Frames: ``"tool"``, ``"dh_frame_1"`` ... ``"dh_frame_4"``, and every URDF link/joint.
        """
        import pinocchio as pin

        config = as_configurations(guards.configurations("q", q))[0]
        frame_id = self._frame_id(frame)
        pin.forwardKinematics(self.model, self.data, config)
        return np.array(pin.updateFramePlacement(self.model, self.data, frame_id).homogeneous)

    def frame_jacobian(self, q: np.ndarray, frame: str = TOOL_FRAME) -> np.ndarray:
        """Pinocchio frame Jacobian, LOCAL_WORLD_ALIGNED. q: (5,) in [rad] -> (6, 5)."""
        import pinocchio as pin

        config = as_configurations(guards.configurations("q", q))[0]
        return np.array(
            pin.computeFrameJacobian(
                self.model,
                self.data,
                config,
                self._frame_id(frame),
                pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
            )
        )

    def _frame_id(self, frame: str) -> int:
        if not self.model.existFrame(frame):
            names = ", ".join(f.name for f in self.model.frames if f.name != "universe")
            raise ModelError(f"unknown frame {frame!r}; frames: {names}")
        return int(self.model.getFrameId(frame))

    # -- inverse kinematics -----------------------------------------------------------------------
    #: The branch-selection rules ``ik`` offers (as ``Robot.selection_rules``).
    selection_rules = ("nearest", "report")

    def ik_batch(
        self,
        T: np.ndarray,
        *,
        q_reference: np.ndarray | None = None,
        approach_only: bool = False,
        limit_tolerance: float = LIMIT_SNAP_TOLERANCE,
    ) -> IkBatch:
        """All-branch IK of many poses; see :func:`lynxplan.arm.ik.solve_ik_batch`.

        Raises:
            LynxplanInputError: T not of shape (4, 4) or (N, 4, 4) real numbers, NaN/Inf,
                translations beyond 1 km, a bottom row other than 0 0 0 1, rotation blocks that
                are reflections or not orthonormal (within 1e-3), q_reference out of range,
                a batch beyond the resource limit (see :mod:`lynxplan.guards`).
        """
        poses = guards.poses("T", T, approach_only=approach_only)
        if q_reference is not None:
            q_reference = guards.angles("q_reference", q_reference)
        return _ik().solve_ik_batch(  # type: ignore[no-any-return]
            poses,
            geometry=self.geometry,
            limits=self.limits,
            q_reference=q_reference,
            approach_only=approach_only,
            limit_tolerance=guards.tolerance("limit_tolerance", limit_tolerance, "rad"),
        )

    def ik(
        self,
        T: np.ndarray,
        *,
        q_reference: np.ndarray | None = None,
        select: Selection = "nearest",
        strict: bool = False,
        orientation_tolerance: float = STRICT_ORIENTATION_TOLERANCE,
        approach_only: bool = False,
        limit_tolerance: float = LIMIT_SNAP_TOLERANCE,
    ) -> IkResult:
        """IK of one pose: every branch, checked by FK, one selected.

        Args:
            T: Target tool pose, shape (4, 4), translation in [m].
            q_reference: Shape (5,), in [rad]: the configuration to stay near (``"nearest"``);
                also q1 on the base axis and q5 for ``approach_only``. Default: zeros.
            select: ``"nearest"`` (within limits, nearest to ``q_reference``) or ``"report"``
                (the report's rule: the first within-limit branch with q2 >= 0 and q3 <= 0).
            strict: Raise if the orientation cannot be reached within ``orientation_tolerance``.
            orientation_tolerance: Accepted orientation residual in strict mode, in [rad].
            approach_only: 5-D target: only column 2 (the approach axis) of the rotation counts.
            limit_tolerance: Angles this far outside a limit, in [rad], are snapped onto it.

        Raises:
            LynxplanInputError (ShapeError, NonFiniteInputError, NotRigidTransformError,
                OutOfRangeError): bad input, see :mod:`lynxplan.guards`.
            UnreachablePoseError: the wrist centre is out of reach (carries the distance).
            OrientationNotReachableError: strict mode and a residual above the tolerance.
        """
        pose = guards.poses("T", T, batch=False, approach_only=approach_only)
        if select not in ("nearest", "report"):
            raise InputError(f"select must be 'nearest' or 'report'. Got: {select!r:.60}")
        orientation_tolerance = guards.tolerance(
            "orientation_tolerance", orientation_tolerance, "rad"
        )
        limit_tolerance = guards.tolerance("limit_tolerance", limit_tolerance, "rad")
        if q_reference is None:
            reference = _ZEROS
        else:
            reference = guards.float_array("q_reference", q_reference)
            if reference.shape != (5,):
                raise ShapeError("q_reference", "(5,)", reference.shape)
            reference = guards.angles("q_reference", reference)
        rows, scalars = np.empty((4, 8)), np.empty(5)
        flags = (1 if approach_only else 0) | (2 if select == "report" else 0)
        params = self._ik_params
        if limit_tolerance != LIMIT_SNAP_TOLERANCE:
            params = params.copy()
            params[3] = limit_tolerance
        ik = _ik()
        ik.ik_single_kernel(
            kernel_input(pose),
            kernel_input(reference),
            params,
            flags,
            rows,
            scalars,
        )
        residual, status, miss, deviation, selected = scalars.tolist()
        if int(status) == ik.IkStatus.NOT_RIGID and np.abs(pose[3] - _BOTTOM_ROW).max() > 1e-9:
            raise NotRigidTransformError(
                float(np.abs(pose[3] - _BOTTOM_ROW).max()), 0.0, "pose (last row must be 0 0 0 1)"
            )
        _raise_for_status(int(status), miss, deviation)
        if strict and residual > orientation_tolerance:
            raise OrientationNotReachableError(residual, orientation_tolerance)
        q = rows[:, :5]
        q.setflags(write=False)
        values = rows[:, 5:].tolist()
        names = ik.BRANCH_NAMES
        solutions = (
            IkSolution(q[0], names[0], values[0][0] > 0.5, values[0][1], values[0][2]),
            IkSolution(q[1], names[1], values[1][0] > 0.5, values[1][1], values[1][2]),
            IkSolution(q[2], names[2], values[2][0] > 0.5, values[2][1], values[2][2]),
            IkSolution(q[3], names[3], values[3][0] > 0.5, values[3][1], values[3][2]),
        )
        return IkResult(
            solutions,
            None if selected < 0 else int(selected),
            reachable=True,  # else UnreachablePoseError above
            distance=min(row[1] for row in values),
            orientation_residual=residual,
            solver=SOLVER,
        )


def _raise_for_status(status: int, miss: float, deviation: float) -> None:
    ik_status = _ik().IkStatus
    if status == ik_status.NON_FINITE:
        raise NonFiniteInputError("T")
    if status == ik_status.NOT_RIGID:
        raise NotRigidTransformError(deviation, RIGIDITY_REPAIR_TOLERANCE)
    if status == ik_status.OUT_OF_REACH:
        raise UnreachablePoseError(miss)


_DEFAULT_ARM: Arm | None = None


def load_arm(urdf_path: str | Path | None = None) -> Arm:
    """The arm built from ``urdf_path`` (default: the shipped AL5 URDF, loaded once and shared)."""
    global _DEFAULT_ARM
    if urdf_path is not None:
        return Arm(urdf_path)
    if _DEFAULT_ARM is None:
        _DEFAULT_ARM = Arm()
    return _DEFAULT_ARM
