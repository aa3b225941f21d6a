"""Singularity measures of the 5-DOF arm for a chosen task (SPEC Part 5).

A *task* is a selection of rows of the extended tool Jacobian ``E(q)``, shape (8, 5):

- rows 0-2 ``vx, vy, vz``: tool-point linear velocity in base axes, in [m/rad];
- rows 3-5 ``wx, wy, wz``: angular velocity in base axes (Pinocchio LOCAL_WORLD_ALIGNED);
- row 6 ``pitch``: rate of the approach pitch ``q2 + q3 + q4`` (``y4 . w``), ``(0, 1, 1, 1, 0)``;
- row 7 ``roll``: rate of roll about the approach axis (``a . w``), ``(-cos q234, 0, 0, 0, 1)``.

Manipulability ``m(q) = sqrt(det(J J^T))`` of the task Jacobian ``J = E[rows]`` (units: product of
the rows' units), its gradient ``dm/dq = m tr(J^+ dJ/dq_j)`` from the closed-form derivative of
``E`` (checked in the tests against finite differences and Pinocchio's Jacobian time variation),
the condition number. The arm's singular configurations: :mod:`lynxplan.singularity.classify`.

Singular configurations (derived from the closed form, ``r`` = radial distance of the tool point
from the base axis, ``r_w`` that of the wrist centre):

- ``position`` (3 rows): the q1 column has length ``|r|`` and is the only one out of the arm
  plane, and the q2, q3, q4 columns are in-plane vectors normal to the lines from the shoulder,
  elbow and wrist centre to the tool point. Singular when the tool point is on the base axis, or
  when shoulder, elbow, wrist centre and tool point are collinear (``sin q3 = 0`` and
  ``cos q4 = 0``).
- ``position_pitch`` (4 rows) and ``position_pitch_roll`` (5 rows, the square task): with the
  pitch fixed the tool point moves like the wrist centre of the 2-link arm, so
  ``m = |r| a2 a3 |sin q3|``: tool point on the base axis, elbow stretched or folded.
- Other row selections: :func:`lynxplan.singularity.classify.singular_conditions` finds which
  of the conditions make ``m`` vanish by evaluating it on configurations that satisfy each
  condition.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from lynxplan.arm.geometry import ArmGeometry
from lynxplan.arm.kinematics import as_configurations
from lynxplan.exceptions import InputError
from lynxplan.singularity.jacobian_kernels import (
    extended_jacobian_derivative_kernel,
    extended_jacobian_kernel,
    gradient_kernel,
    manipulability_kernel,
    measures_kernel,
)
from lynxplan.singularity.tasks import NAMED_TASKS, ROW_NAMES, Task, make_task

_DEFAULT_GEOMETRY = ArmGeometry()


def _unbatch(array: np.ndarray, q: object) -> np.ndarray:
    return array[0] if np.ndim(q) == 1 else array  # type: ignore[arg-type]


def extended_jacobian(q: np.ndarray, geometry: ArmGeometry = _DEFAULT_GEOMETRY) -> np.ndarray:
    """Extended Jacobian (rows :data:`ROW_NAMES`).

    Args:
        q: Joint angles, shape (5,) or (N, 5), in [rad].
        geometry: Arm dimensions.

    Returns:
        Shape (8, 5) or (N, 8, 5); linear rows in [m/rad], angular rows unitless.
    """
    batch = as_configurations(q)
    out = np.empty((batch.shape[0], 8, 5))
    for n in range(batch.shape[0]):
        extended_jacobian_kernel(batch[n], geometry.a2, geometry.a3, geometry.d5, out[n])
    return _unbatch(out, q)


def task_jacobian(
    q: np.ndarray, task: str | Task | Sequence[str | int], geometry: ArmGeometry = _DEFAULT_GEOMETRY
) -> np.ndarray:
    """Task Jacobian ``E[rows]``: q (5,) or (N, 5) in [rad] -> (k, 5) or (N, k, 5)."""
    selected = make_task(task)
    return extended_jacobian(q, geometry)[..., list(selected.rows), :]


def task_jacobian_derivative(
    q: np.ndarray, task: str | Task | Sequence[str | int], geometry: ArmGeometry = _DEFAULT_GEOMETRY
) -> np.ndarray:
    """dJ/dq_j of the task Jacobian: q (5,) in [rad] -> shape (k, 5, 5), last index j."""
    selected = make_task(task)
    config = as_configurations(q)
    if config.shape[0] != 1 or np.ndim(q) != 1:
        raise InputError(f"q must be one configuration, shape (5,). Got: {np.shape(q)}")
    out = np.empty((8, 5, 5))
    extended_jacobian_derivative_kernel(config[0], geometry.a2, geometry.a3, geometry.d5, out)
    return out[list(selected.rows)]


def manipulability(
    q: np.ndarray, task: str | Task | Sequence[str | int], geometry: ArmGeometry = _DEFAULT_GEOMETRY
) -> float | np.ndarray:
    """Manipulability ``sqrt(det(J J^T))`` of the task.

    Args:
        q: Joint angles, shape (5,) or (N, 5), in [rad].
        task: Task name or row selection (see :func:`make_task`).
        geometry: Arm dimensions.

    Returns:
        A float, or shape (N,); units: product of the task rows' units (e.g. [m^3] for position).
    """
    m, _ = manipulability_and_gradient(q, task, geometry)
    return m


def manipulability_gradient(
    q: np.ndarray, task: str | Task | Sequence[str | int], geometry: ArmGeometry = _DEFAULT_GEOMETRY
) -> np.ndarray:
    """Gradient dm/dq, shape (5,) or (N, 5), in [m-units / rad] (zeros where m = 0)."""
    _, grad = manipulability_and_gradient(q, task, geometry)
    return grad


def manipulability_and_gradient(
    q: np.ndarray, task: str | Task | Sequence[str | int], geometry: ArmGeometry = _DEFAULT_GEOMETRY
) -> tuple[float | np.ndarray, np.ndarray]:
    """Manipulability (float or (N,)) and gradient ((5,) or (N, 5)) in one pass."""
    selected = make_task(task)
    batch = as_configurations(q)
    m = np.empty(batch.shape[0])
    grad = np.empty((batch.shape[0], 5))
    measures_kernel(batch, selected.rows_array, geometry.a2, geometry.a3, geometry.d5, m, grad)
    if np.ndim(q) == 1:
        return float(m[0]), grad[0]
    return m, grad


def singular_values(
    q: np.ndarray, task: str | Task | Sequence[str | int], geometry: ArmGeometry = _DEFAULT_GEOMETRY
) -> np.ndarray:
    """Singular values of the task Jacobian, descending: shape (k,) or (N, k)."""
    return np.linalg.svd(task_jacobian(q, task, geometry), compute_uv=False)


def condition_number(
    q: np.ndarray, task: str | Task | Sequence[str | int], geometry: ArmGeometry = _DEFAULT_GEOMETRY
) -> float | np.ndarray:
    """Condition number ``sigma_max / sigma_min`` of the task Jacobian (inf when singular).

    Mixed tasks (lengths and angles) compare [m/rad] with unitless rows: the figure depends on
    the length unit, SI here.
    """
    sv = singular_values(q, task, geometry)
    with np.errstate(divide="ignore"):
        ratio = np.where(sv[..., -1] > 0.0, sv[..., 0] / np.maximum(sv[..., -1], 1e-300), np.inf)
    return float(ratio) if np.ndim(q) == 1 else ratio


__all__ = [
    "NAMED_TASKS",
    "ROW_NAMES",
    "Task",
    "condition_number",
    "extended_jacobian",
    "extended_jacobian_derivative_kernel",
    "extended_jacobian_kernel",
    "gradient_kernel",
    "make_task",
    "manipulability",
    "manipulability_and_gradient",
    "manipulability_gradient",
    "manipulability_kernel",
    "measures_kernel",
    "singular_values",
    "task_jacobian",
    "task_jacobian_derivative",
]
