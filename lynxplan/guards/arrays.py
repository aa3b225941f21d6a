"""Checks of array inputs: real float64 arrays, finite values, joint angles in range,
configurations, planar poses, rotations and 4x4 tool poses (the error names the first bad
element)."""

from __future__ import annotations

from typing import Any

import numpy as np

from lynxplan.constants import RIGIDITY_REPAIR_TOLERANCE
from lynxplan.exceptions import (
    InputError,
    NonFiniteInputError,
    NotRigidTransformError,
    OutOfRangeError,
    ShapeError,
)
from lynxplan.guards.limits import check_size
from lynxplan.guards.pose_kernel import (
    POSE_BOTTOM_ROW,
    POSE_FAR,
    POSE_NON_FINITE,
    POSE_NOT_ORTHONORMAL,
    POSE_OK,
    pose_check_kernel,
)
from lynxplan.guards.scalars import MAX_ABS_ANGLE, MAX_ABS_LENGTH


def float_array(name: str, value: Any) -> np.ndarray:
    """``value`` as a float64 array; InputError for strings, ragged lists, complex or objects."""
    if isinstance(value, np.ndarray):
        if value.dtype.kind not in "biuf":
            raise InputError(f"{name} must be an array of real numbers. Got dtype {value.dtype}")
        return np.asarray(value, dtype=np.float64)
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError) as exc:
        reason = " ".join(str(exc).split())
        if "inhomogeneous" in reason or "sequence" in reason:
            reason = "a ragged nested list: rows of different lengths"
        reason = reason[:80]
        raise InputError(f"{name} must be an array of real numbers ({reason})") from None
    return array


def _as_float64(name: str, value: Any) -> np.ndarray:
    """:func:`float_array`, without a copy or a call when ``value`` is a float64 array already."""
    if isinstance(value, np.ndarray) and value.dtype == np.float64:
        return value
    return float_array(name, value)


def _first_bad(array: np.ndarray, bad: np.ndarray) -> str:
    index = tuple(int(i) for i in np.argwhere(bad)[0])
    where = "" if array.ndim == 0 else str(list(index))
    return f"{where} = {float(array[index])}"


def finite_array(name: str, value: Any) -> np.ndarray:
    """A float64 array without NaN/Inf; the error names the first bad element."""
    array = float_array(name, value)
    bad = ~np.isfinite(array)
    if bad.any():
        raise NonFiniteInputError(name, f"{name}{_first_bad(array, bad)}")
    return array


def angles(name: str, value: Any) -> np.ndarray:
    """Joint angles of any shape: finite, ``|q| <=`` :data:`MAX_ABS_ANGLE`, in [rad]."""
    array = _as_float64(name, value)
    # Fast path, one pass: NaN makes the maximum NaN and the comparison False.
    if array.size == 0 or np.abs(array).max() <= MAX_ABS_ANGLE:
        return array
    finite_array(name, array)
    bad = np.abs(array) > MAX_ABS_ANGLE
    if bad.any():
        index = tuple(int(i) for i in np.argwhere(bad)[0])
        where = "" if array.ndim == 0 else str(list(index))
        raise OutOfRangeError(
            f"{name}{where}", float(array[index]), f"finite, |angle| <= {MAX_ABS_ANGLE:g} rad"
        )
    return array


def configurations(name: str, value: Any, dof: int = 5) -> np.ndarray:
    """Shape ``(dof,)`` or ``(N, dof)`` joint angles in range, as a C-contiguous float64 array."""
    array = _as_float64(name, value)
    if array.ndim not in (1, 2) or array.shape[-1] != dof:
        raise ShapeError(name, f"({dof},) or (N, {dof})", array.shape)
    if array.ndim == 2:
        check_size(f"{name}: configurations in one batch", array.shape[0])
    angles(name, array)
    return array if array.flags.c_contiguous else np.ascontiguousarray(array)


def planar_poses(name: str, value: Any) -> np.ndarray:
    """Planar poses ``(x, y, alpha)``, shape (3,) or (N, 3), in [m, m, rad]: positions within
    :data:`MAX_ABS_LENGTH`, angles within :data:`MAX_ABS_ANGLE`; a C-contiguous float64 array."""
    array = float_array(name, value)
    if array.ndim not in (1, 2) or array.shape[-1] != 3:
        raise ShapeError(name, "(3,) or (N, 3)", array.shape)
    check_size(f"{name}: poses in one batch", array.shape[0] if array.ndim == 2 else 1)
    stack = finite_array(name, array).reshape(-1, 3)
    far = np.abs(stack[:, :2]) > MAX_ABS_LENGTH
    if far.any():
        k, i = (int(v) for v in np.argwhere(far)[0])
        where = f"[{k}]" if array.ndim == 2 else ""
        raise OutOfRangeError(
            f"{name}{where} {'xy'[i]}", float(stack[k, i]), f"|{'xy'[i]}| <= {MAX_ABS_LENGTH:g} m"
        )
    angles(f"{name} alpha", stack[:, 2] if array.ndim == 2 else stack[0, 2])
    return np.ascontiguousarray(array)


def rotation(name: str, value: Any) -> np.ndarray:
    """A rotation matrix: 3x3, finite, orthonormal within the repair tolerance, ``det = +1``."""
    R = finite_array(name, value)
    if R.shape != (3, 3):
        raise ShapeError(name, "(3, 3)", R.shape)
    _check_rotation_block(name, R)
    return R


def _check_rotation_block(name: str, R: np.ndarray) -> None:
    deviation = float(np.abs(R.T @ R - np.eye(3)).max())
    if deviation > RIGIDITY_REPAIR_TOLERANCE:
        raise NotRigidTransformError(deviation, RIGIDITY_REPAIR_TOLERANCE, name)
    det = float(np.linalg.det(R))
    if det < 0:
        raise InputError(
            f"{name}: rotation block has determinant {det:.3g}: a reflection, not a rotation"
        )


def poses(name: str, value: Any, *, batch: bool = True, approach_only: bool = False) -> np.ndarray:
    """Tool poses, shape (4, 4) or (N, 4, 4) (``batch=False``: only (4, 4)), checked: finite,
    positions within :data:`MAX_ABS_LENGTH`, last row ``0 0 0 1``, rotation blocks proper.

    With ``approach_only`` only column 2 of each rotation block (the approach axis) is checked:
    a unit vector within the repair tolerance; columns 0 and 1 are ignored.

    Returns:
        A C-contiguous float64 array of the input's shape.
    """
    return poses_with_deviation(name, value, batch=batch, approach_only=approach_only)[0]


def poses_with_deviation(
    name: str, value: Any, *, batch: bool = True, approach_only: bool = False
) -> tuple[np.ndarray, float]:
    """:func:`poses`, and the largest deviation of their rotation blocks from orthonormal
    (``max |R^T R - I|``, within the repair tolerance; 0 with ``approach_only``), found by the
    same pass."""
    array = _as_float64(name, value)
    if array.shape == (3, 3) or (batch and array.ndim == 3 and array.shape[1:] == (3, 3)):
        raise ShapeError(
            name,
            "(4, 4) (a 3x3 rotation is not a pose: add the translation and 0 0 0 1)",
            array.shape,
        )
    ok_shape = array.shape == (4, 4) or (batch and array.ndim == 3 and array.shape[1:] == (4, 4))
    if not ok_shape:
        raise ShapeError(name, "(4, 4) or (N, 4, 4)" if batch else "(4, 4)", array.shape)
    stack = array.reshape(-1, 4, 4)
    if not stack.flags.c_contiguous:
        stack = np.ascontiguousarray(stack)
    if stack.shape[0] > 1:
        check_size(f"{name}: poses in one batch", stack.shape[0])
    checked = stack.view()  # read-only: one compiled kernel for writable and read-only input
    checked.flags.writeable = False
    k, code, detail = pose_check_kernel(checked, MAX_ABS_LENGTH, approach_only).tolist()
    if code == POSE_OK:
        return (stack if array.ndim == 3 else stack[0]), detail
    at = f"{name}[{int(k)}]" if array.ndim == 3 else name
    if code == POSE_NON_FINITE:
        raise NonFiniteInputError(name, f"in {at}")
    if code == POSE_FAR:
        raise OutOfRangeError(f"{at} translation", detail, f"|x| <= {MAX_ABS_LENGTH:g} m")
    if code == POSE_BOTTOM_ROW:
        raise NotRigidTransformError(detail, 0.0, f"{at} (last row must be 0 0 0 1)")
    if code == POSE_NOT_ORTHONORMAL:
        raise NotRigidTransformError(detail, RIGIDITY_REPAIR_TOLERANCE, at)
    raise InputError(
        f"{at}: rotation block has determinant {detail:.3g}: a reflection, not a rotation"
    )
