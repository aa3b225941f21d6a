"""Valid ranges of every input quantity, and resource limits checked before any allocation.

Public entry points (``Arm.fk/ik/ik_batch/jacobian``, the 3-RRR IK/FK/workspace, trajectory
builders, collision checks, the CLI) call these checks first, so bad input ends in one
:class:`~lynxplan.exceptions.LynxplanInputError` that names the value, never in a numba typing
error, a wrapped angle, a NaN result, a hang or a MemoryError.

Valid ranges (SI units):

==========================  =====================================================================
quantity                    valid range
==========================  =====================================================================
joint / platform angle      finite, ``|q| <=`` :data:`MAX_ABS_ANGLE` (100 rad; never wrapped)
angle in degrees (CLI)      the same bound, about 5730 deg
position / length           finite, ``|x| <=`` :data:`MAX_ABS_LENGTH` (1 km)
size, step, cell, radius    finite, ``0 <`` value ``<=`` :data:`MAX_ABS_LENGTH`
duration (tt, ta, ...)      finite, ``0 <`` t ``<=`` :data:`MAX_DURATION` (one day)
sample rate                 finite, ``0 <`` rate ``<=`` :data:`MAX_SAMPLE_RATE` (1 MHz)
tolerance                   finite, ``>= 0`` (a NaN tolerance would silently disable a check)
rotation block              3x3, finite, orthonormal within 1e-3 (repaired), ``det = +1``
pose                        4x4, last row ``0 0 0 1``, rotation block as above
seed                        integer, ``0 <= seed < 2**63``
==========================  =====================================================================

Resource limits (:class:`ResourceLimits`): the number of elements (random samples, grid cells,
poses in a batch, trajectory samples) a computation may create is at most ``max_samples``
(default :data:`DEFAULT_MAX_SAMPLES`); a planning time limit is at most ``max_planning_time``.
``max_samples`` is raised with ``--max-samples N`` on the command line (any command, ``run``
included) and both with :func:`raised_limits` in Python (the way for the scenario layer to
apply a file's own limits).
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from lynxplan.constants import RIGIDITY_REPAIR_TOLERANCE
from lynxplan.exceptions import (
    InputError,
    NonFiniteInputError,
    NotRigidTransformError,
    OutOfRangeError,
    ResourceLimitError,
    ShapeError,
)

#: Largest accepted |angle|, in [rad]. Larger values are errors, not wrapped: nobody means 1e19 rad.
MAX_ABS_ANGLE = 100.0
#: Largest accepted |length| or |coordinate|, in [m].
MAX_ABS_LENGTH = 1000.0
#: Longest accepted duration, in [s].
MAX_DURATION = 86_400.0
#: Highest accepted sample rate, in [Hz].
MAX_SAMPLE_RATE = 1e6
#: Seeds are integers in ``[0, MAX_SEED)``.
MAX_SEED = 2**63
#: Default largest number of elements (samples, grid cells, poses) one computation may create.
DEFAULT_MAX_SAMPLES = 100_000_000
#: Default largest planning time limit, in [s].
DEFAULT_MAX_PLANNING_TIME = 600.0
#: How a user raises a resource limit (appended to every ResourceLimitError). The scenario layer
#: applies a file's own limit with :func:`raised_limits` around the run.
HOW_TO_RAISE = "raise the limit with --max-samples N (or raised_limits(max_samples=N) in Python)"


@dataclass(frozen=True)
class ResourceLimits:
    """Resource limits checked before any allocation.

    Attributes:
        max_samples: Most elements (samples, grid cells, poses, trajectory samples) one
            computation may create.
        max_planning_time: Longest accepted planning time limit, in [s].
    """

    max_samples: int = DEFAULT_MAX_SAMPLES
    max_planning_time: float = DEFAULT_MAX_PLANNING_TIME


_DEFAULT_LIMITS = ResourceLimits()
_LIMITS: ContextVar[ResourceLimits | None] = ContextVar("lynxplan_resource_limits", default=None)


def current_limits() -> ResourceLimits:
    """The resource limits in force (default, or those set by :func:`raised_limits`)."""
    return _LIMITS.get() or _DEFAULT_LIMITS


@contextmanager
def raised_limits(
    max_samples: int | None = None, max_planning_time: float | None = None
) -> Iterator[ResourceLimits]:
    """Change the resource limits inside a ``with`` block (values are checked first)."""
    changes: dict[str, Any] = {}
    if max_samples is not None:
        changes["max_samples"] = count("max_samples", max_samples, minimum=1, limit=None)
    if max_planning_time is not None:
        changes["max_planning_time"] = positive("max_planning_time", max_planning_time, "s")
    token = _LIMITS.set(replace(current_limits(), **changes))
    try:
        yield current_limits()
    finally:
        _LIMITS.reset(token)


# -- scalars ----------------------------------------------------------------------------------
def real(name: str, value: Any) -> float:
    """``value`` as a finite float; InputError naming ``name`` otherwise (bools are refused)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Real, np.number)):
        if isinstance(value, str):
            try:
                value = float(value)
            except ValueError:
                raise InputError(f"{name}: {value!r} is not a number") from None
        else:
            raise InputError(f"{name} must be a number. Got: {type(value).__name__} {value!r:.60}")
    try:
        result = float(value)
    except (OverflowError, ValueError):  # e.g. an int beyond the float range
        raise OutOfRangeError(name, value, "a finite number") from None
    if not math.isfinite(result):
        raise NonFiniteInputError(name, f"{name} = {result}")
    return result


def in_range(
    name: str, value: Any, low: float, high: float, unit: str = "", *, low_open: bool = False
) -> float:
    """Finite ``value`` with ``low <= value <= high`` (``low < value`` if ``low_open``)."""
    x = real(name, value)
    if x > high or x < low or (low_open and x == low):
        op = "<" if low_open else "<="
        u = f" {unit}" if unit else ""
        raise OutOfRangeError(name, x, f"finite, {low:g}{u} {op} {name} <= {high:g}{u}")
    return x


def angle(name: str, value: Any) -> float:
    """A finite angle with ``|value| <=`` :data:`MAX_ABS_ANGLE`, in [rad]."""
    return in_range(name, value, -MAX_ABS_ANGLE, MAX_ABS_ANGLE, "rad")


def angle_deg(name: str, value: Any) -> float:
    """A finite angle in degrees within :data:`MAX_ABS_ANGLE` (about 5730 deg); returns degrees."""
    bound = math.degrees(MAX_ABS_ANGLE)
    return in_range(name, value, -bound, bound, "deg")


def length(name: str, value: Any, unit_scale: float = 1.0, unit: str = "m") -> float:
    """A finite coordinate, ``|value * unit_scale| <=`` :data:`MAX_ABS_LENGTH`; returns value."""
    bound = MAX_ABS_LENGTH / unit_scale
    return in_range(name, value, -bound, bound, unit)


def positive(name: str, value: Any, unit: str = "", high: float = math.inf) -> float:
    """A finite value ``> 0`` (and ``<= high``)."""
    if math.isinf(high):
        x = real(name, value)
        if x <= 0:
            u = f" {unit}" if unit else ""
            raise OutOfRangeError(name, x, f"a finite number > 0{u}")
        return x
    return in_range(name, value, 0.0, high, unit, low_open=True)


def positive_length(name: str, value: Any, unit_scale: float = 1.0, unit: str = "m") -> float:
    """A size, step or cell: finite, ``0 < value * unit_scale <=`` :data:`MAX_ABS_LENGTH`."""
    return positive(name, value, unit, MAX_ABS_LENGTH / unit_scale)


def duration(name: str, value: Any) -> float:
    """A duration: finite, ``0 < t <=`` :data:`MAX_DURATION`, in [s]."""
    return positive(name, value, "s", MAX_DURATION)


def sample_rate(name: str, value: Any) -> float:
    """A sample rate: finite, ``0 < rate <=`` :data:`MAX_SAMPLE_RATE`, in [Hz]."""
    return positive(name, value, "Hz", MAX_SAMPLE_RATE)


def tolerance(name: str, value: Any, unit: str = "") -> float:
    """A tolerance: finite and ``>= 0`` (NaN would silently disable the check it bounds)."""
    x = real(name, value)
    if x < 0:
        raise OutOfRangeError(name, x, f"a finite number >= 0{' ' + unit if unit else ''}")
    return x


def count(name: str, value: Any, *, minimum: int = 1, limit: int | None = -1) -> int:
    """An integer count ``>= minimum``; ``limit=-1`` checks it against ``max_samples``."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (numbers.Integral, float)):
        raise InputError(f"{name} must be an integer. Got: {value!r:.60}")
    if isinstance(value, float) and not (math.isfinite(value) and value.is_integer()):
        raise InputError(f"{name} must be an integer. Got: {value!r}")
    n = int(value)
    if n < minimum:
        raise OutOfRangeError(name, n, f"an integer >= {minimum}")
    if limit == -1:
        check_size(name, n)
    elif limit is not None and n > limit:
        raise OutOfRangeError(name, n, f"an integer <= {limit}")
    return n


def seed(name: str, value: Any) -> int:
    """A random seed: an integer with ``0 <= seed <`` :data:`MAX_SEED`."""
    n = count(name, value, minimum=0, limit=None)
    if n >= MAX_SEED:
        raise OutOfRangeError(name, n, f"an integer with 0 <= {name} < 2**63")
    return n


# -- sizes --------------------------------------------------------------------------------------
def check_size(quantity: str, requested: float, bytes_per_element: float = 0.0) -> None:
    """Refuse a computation of ``requested`` elements beyond ``max_samples`` (before allocating).

    Raises:
        ResourceLimitError: naming the quantity, the size, the limit and how to raise it.
    """
    limit = current_limits().max_samples
    if not requested <= limit:  # also catches NaN
        memory = ""
        if bytes_per_element > 0 and math.isfinite(_as_float(requested)):
            memory = f" (about {_bytes(_as_float(requested) * bytes_per_element)} of memory)"
        raise ResourceLimitError(f"{quantity}{memory}", _as_float(requested), limit, HOW_TO_RAISE)


def grid_cells(quantity: str, extent: float, cell: float, dims: int) -> int:
    """Cells of a ``dims``-D grid of edge ``cell`` over ``extent`` (same unit), checked."""
    per_axis = extent / cell + 2.0
    total = per_axis**dims if per_axis < 1e100 else math.inf
    check_size(f"{quantity} ({per_axis:.3g} per axis for a {cell:.3g} cell)", total, 1.0)
    return math.ceil(per_axis)


def planning_time(name: str, value: Any) -> float:
    """A planning time limit: ``0 < t <= max_planning_time``, in [s]."""
    x = positive(name, value, "s")
    limit = current_limits().max_planning_time
    if x > limit:
        raise ResourceLimitError(
            f"{name} (planning time in s)",
            x,
            limit,
            "raise it with raised_limits(max_planning_time=S) in Python",
        )
    return x


def _as_float(n: float) -> float:
    """``float(n)``, infinity for integers beyond the float range."""
    try:
        return float(n)
    except OverflowError:
        return math.inf


def _bytes(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if n < 1000:
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} PB"


# -- arrays -------------------------------------------------------------------------------------
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
    k, code, detail = _pose_check_kernel(stack, MAX_ABS_LENGTH, approach_only).tolist()
    if code == _POSE_OK:
        return stack if array.ndim == 3 else stack[0]
    at = f"{name}[{int(k)}]" if array.ndim == 3 else name
    if code == _POSE_NON_FINITE:
        raise NonFiniteInputError(name, f"in {at}")
    if code == _POSE_FAR:
        raise OutOfRangeError(f"{at} translation", detail, f"|x| <= {MAX_ABS_LENGTH:g} m")
    if code == _POSE_BOTTOM_ROW:
        raise NotRigidTransformError(detail, 0.0, f"{at} (last row must be 0 0 0 1)")
    if code == _POSE_NOT_ORTHONORMAL:
        raise NotRigidTransformError(detail, RIGIDITY_REPAIR_TOLERANCE, at)
    raise InputError(
        f"{at}: rotation block has determinant {detail:.3g}: a reflection, not a rotation"
    )


_POSE_OK, _POSE_NON_FINITE, _POSE_FAR, _POSE_BOTTOM_ROW = 0, 1, 2, 3
_POSE_NOT_ORTHONORMAL, _POSE_REFLECTION = 4, 5


_COMPILED: dict[str, Any] = {}


def _pose_check_kernel(T: np.ndarray, max_length: float, approach_only: bool) -> np.ndarray:
    """:func:`_pose_check`, compiled by numba on first use (``import lynxplan.guards`` stays
    cheap for the CLI)."""
    kernel = _COMPILED.get("pose_check")
    if kernel is None:
        import numba

        kernel = _COMPILED["pose_check"] = numba.njit(cache=True, nogil=True)(_pose_check)
    result: np.ndarray = kernel(T, max_length, approach_only)
    return result


def _pose_check(T: np.ndarray, max_length: float, approach_only: bool) -> np.ndarray:
    """First bad pose of ``T`` (N, 4, 4): ``[index, code, detail]`` (code 0: all good)."""
    out = np.zeros(3)
    for k in range(T.shape[0]):
        t = T[k]
        for i in range(4):
            for j in range(4):
                if not math.isfinite(t[i, j]):
                    out[0], out[1] = k, _POSE_NON_FINITE
                    return out
        for i in range(3):
            if abs(t[i, 3]) > max_length:
                out[0], out[1], out[2] = k, _POSE_FAR, t[i, 3]
                return out
        bottom = max(abs(t[3, 0]), abs(t[3, 1]), abs(t[3, 2]), abs(t[3, 3] - 1.0))
        if bottom > 1e-9:
            out[0], out[1], out[2] = k, _POSE_BOTTOM_ROW, bottom
            return out
        if approach_only:
            norm2 = t[0, 2] ** 2 + t[1, 2] ** 2 + t[2, 2] ** 2
            if abs(norm2 - 1.0) > RIGIDITY_REPAIR_TOLERANCE:
                out[0], out[1], out[2] = k, _POSE_NOT_ORTHONORMAL, abs(norm2 - 1.0)
                return out
            continue
        deviation = 0.0
        for i in range(3):
            for j in range(3):
                dot = t[0, i] * t[0, j] + t[1, i] * t[1, j] + t[2, i] * t[2, j]
                deviation = max(deviation, abs(dot - (1.0 if i == j else 0.0)))
        if deviation > RIGIDITY_REPAIR_TOLERANCE:
            out[0], out[1], out[2] = k, _POSE_NOT_ORTHONORMAL, deviation
            return out
        det = (
            t[0, 0] * (t[1, 1] * t[2, 2] - t[1, 2] * t[2, 1])
            - t[0, 1] * (t[1, 0] * t[2, 2] - t[1, 2] * t[2, 0])
            + t[0, 2] * (t[1, 0] * t[2, 1] - t[1, 1] * t[2, 0])
        )
        if det < 0.0:
            out[0], out[1], out[2] = k, _POSE_REFLECTION, det
            return out
    return out
