"""Singularity measures of the 5-DOF arm for a chosen task (SPEC Part 5).

A *task* is a selection of rows of the extended tool Jacobian ``E(q)``, shape (8, 5):

- rows 0-2 ``vx, vy, vz``: tool-point linear velocity in base axes, in [m/rad];
- rows 3-5 ``wx, wy, wz``: angular velocity in base axes (Pinocchio LOCAL_WORLD_ALIGNED);
- row 6 ``pitch``: rate of the approach pitch ``q2 + q3 + q4`` (``y4 . w``), ``(0, 1, 1, 1, 0)``;
- row 7 ``roll``: rate of roll about the approach axis (``a . w``), ``(-cos q234, 0, 0, 0, 1)``.

Manipulability ``m(q) = sqrt(det(J J^T))`` of the task Jacobian ``J = E[rows]`` (units: product of
the rows' units), its gradient ``dm/dq = m tr(J^+ dJ/dq_j)`` from the closed-form derivative of
``E`` (checked in the tests against finite differences and Pinocchio's Jacobian time variation),
the condition number, and the arm's singular configurations.

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
- Other row selections: :func:`singular_conditions` finds which of the conditions make ``m``
  vanish by evaluating it on configurations that satisfy each condition.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum
from typing import NamedTuple

import numba
import numpy as np

from lynxplan.arm.geometry import ArmGeometry
from lynxplan.arm.kinematics import as_configurations
from lynxplan.exceptions import InputError, ShapeError, TaskError

_DEFAULT_GEOMETRY = ArmGeometry()

#: Names of the rows of the extended Jacobian, in order.
ROW_NAMES = ("vx", "vy", "vz", "wx", "wy", "wz", "pitch", "roll")

#: Named tasks -> row indices into :data:`ROW_NAMES`.
NAMED_TASKS: dict[str, tuple[int, ...]] = {
    "position": (0, 1, 2),
    "position_pitch": (0, 1, 2, 6),
    "position_pitch_roll": (0, 1, 2, 6, 7),
}


@dataclass(frozen=True)
class Task:
    """A selection of rows of the extended tool Jacobian.

    Attributes:
        name: Task name (a key of :data:`NAMED_TASKS`, or the row names joined by ``+``).
        rows: Row indices into :data:`ROW_NAMES`, distinct, 1 to 5 of them.
    """

    name: str
    rows: tuple[int, ...]

    @property
    def size(self) -> int:
        """Number of task rows."""
        return len(self.rows)

    @property
    def row_names(self) -> tuple[str, ...]:
        """Names of the selected rows."""
        return tuple(ROW_NAMES[i] for i in self.rows)

    @property
    def rows_array(self) -> np.ndarray:
        """Row indices as an int64 array (for the kernels)."""
        return np.array(self.rows, dtype=np.int64)


def make_task(spec: str | Task | Sequence[str | int]) -> Task:
    """A task from a name (``"position"``, ``"position_pitch"``, ...) or a row selection.

    Args:
        spec: A task name, a Task, or a sequence of row names/indices (see :data:`ROW_NAMES`).

    Raises:
        TaskError: unknown name or row, repeated rows, or more than 5 or no rows.
    """
    if isinstance(spec, Task):
        return spec
    if isinstance(spec, str):
        if spec not in NAMED_TASKS:
            raise TaskError(spec, f"valid names: {', '.join(NAMED_TASKS)}, or a list of rows")
        return Task(spec, NAMED_TASKS[spec])
    rows: list[int] = []
    for item in spec:
        if isinstance(item, str) and item in ROW_NAMES:
            rows.append(ROW_NAMES.index(item))
        elif isinstance(item, (int, np.integer)) and not isinstance(item, bool) and 0 <= item < 8:
            rows.append(int(item))
        else:
            raise TaskError(str(item), f"unknown task row; valid rows: {', '.join(ROW_NAMES)}")
    if not rows or len(rows) > 5 or len(set(rows)) != len(rows):
        raise TaskError(str(list(spec)), "a task needs 1 to 5 distinct rows (the arm has 5 joints)")
    for name, named_rows in NAMED_TASKS.items():
        if tuple(rows) == named_rows:
            return Task(name, named_rows)
    return Task("+".join(ROW_NAMES[i] for i in rows), tuple(rows))


# -- kernels --------------------------------------------------------------------------------------
@numba.njit(cache=True, nogil=True)
def _plane_terms(q: np.ndarray, a2: float, a3: float, d5: float) -> tuple[np.ndarray, np.ndarray]:
    """Radial r_i and height h_i of (tool - o_i) for i = shoulder, elbow, wrist centre."""
    s2, c2 = math.sin(q[1]), math.cos(q[1])
    s23, c23 = math.sin(q[1] + q[2]), math.cos(q[1] + q[2])
    q234 = q[1] + q[2] + q[3]
    s234, c234 = math.sin(q234), math.cos(q234)
    r = np.empty(3)
    h = np.empty(3)
    r[2], h[2] = d5 * s234, -d5 * c234
    r[1], h[1] = r[2] + a3 * c23, h[2] + a3 * s23
    r[0], h[0] = r[1] + a2 * c2, h[1] + a2 * s2
    return r, h


@numba.njit(cache=True, nogil=True)
def extended_jacobian_kernel(
    q: np.ndarray, a2: float, a3: float, d5: float, out: np.ndarray
) -> None:
    """Write the extended Jacobian E(q), shape (8, 5), of one configuration q (5,) into ``out``."""
    s1, c1 = math.sin(q[0]), math.cos(q[0])
    q234 = q[1] + q[2] + q[3]
    s234, c234 = math.sin(q234), math.cos(q234)
    r, h = _plane_terms(q, a2, a3, d5)
    out[:, :] = 0.0
    out[0, 0], out[1, 0] = -s1 * r[0], c1 * r[0]
    for i in range(3):
        # Column of joint i+2: (s1, -c1, 0) x (c1 r_i, s1 r_i, h_i) = (-c1 h_i, -s1 h_i, r_i).
        out[0, i + 1], out[1, i + 1], out[2, i + 1] = -c1 * h[i], -s1 * h[i], r[i]
        out[3, i + 1], out[4, i + 1] = s1, -c1
        out[6, i + 1] = 1.0
    out[5, 0] = 1.0
    out[3, 4], out[4, 4], out[5, 4] = c1 * s234, s1 * s234, -c234
    out[7, 0], out[7, 4] = -c234, 1.0


@numba.njit(cache=True, nogil=True)
def extended_jacobian_derivative_kernel(
    q: np.ndarray, a2: float, a3: float, d5: float, out: np.ndarray
) -> None:
    """Write dE/dq_j, shape (8, 5, 5) (last index j), of one configuration into ``out``.

    In the arm plane, d(r_i, h_i)/dq_j = (-h_k, r_k) with k = max(i, j) (joint j turns the part
    of the chain beyond both o_i and o_j); nothing depends on q5.
    """
    s1, c1 = math.sin(q[0]), math.cos(q[0])
    q234 = q[1] + q[2] + q[3]
    s234, c234 = math.sin(q234), math.cos(q234)
    r, h = _plane_terms(q, a2, a3, d5)
    out[:, :, :] = 0.0
    # j = 0 (q1): derivative of s1 -> c1, c1 -> -s1.
    out[0, 0, 0], out[1, 0, 0] = -c1 * r[0], -s1 * r[0]
    for i in range(3):
        out[0, i + 1, 0], out[1, i + 1, 0] = s1 * h[i], -c1 * h[i]
        out[3, i + 1, 0], out[4, i + 1, 0] = c1, s1
    out[3, 4, 0], out[4, 4, 0] = -s1 * s234, c1 * s234
    for j in range(3):
        out[0, 0, j + 1], out[1, 0, j + 1] = s1 * h[j], -c1 * h[j]
        for i in range(3):
            k = max(i, j)
            out[0, i + 1, j + 1] = -c1 * r[k]
            out[1, i + 1, j + 1] = -s1 * r[k]
            out[2, i + 1, j + 1] = -h[k]
        out[3, 4, j + 1], out[4, 4, j + 1], out[5, 4, j + 1] = c1 * c234, s1 * c234, s234
        out[7, 0, j + 1] = s234


@numba.njit(cache=True, nogil=True)
def manipulability_kernel(J: np.ndarray) -> float:
    """sqrt(det(J J^T)) of a (k, 5) task Jacobian, as |prod diag R| of J^T = Q R.

    The QR form keeps the accuracy of the smallest singular value near a singularity, where
    sqrt(det) of the product carries a noise of ~sqrt(eps) times the largest.
    """
    R = np.linalg.qr(np.ascontiguousarray(J.T))[1]
    m = 1.0
    for i in range(J.shape[0]):
        m *= abs(R[i, i])
    return m


@numba.njit(cache=True, nogil=True)
def gradient_kernel(J: np.ndarray, dJ: np.ndarray, m: float, out: np.ndarray) -> None:
    """dm/dq_j = m tr(J^+ dJ_j) = m sum((J J^T)^-1 J * dJ_j); zeros when m = 0."""
    out[:] = 0.0
    if m <= 0.0:
        return
    B = np.linalg.solve(J @ J.T, J)
    for j in range(5):
        total = 0.0
        for a in range(J.shape[0]):
            for b in range(5):
                total += B[a, b] * dJ[a, b, j]
        out[j] = m * total


@numba.njit(cache=True, nogil=True)
def measures_kernel(
    q: np.ndarray,
    rows: np.ndarray,
    a2: float,
    a3: float,
    d5: float,
    m_out: np.ndarray,
    grad_out: np.ndarray,
) -> None:
    """Manipulability (N,) and its gradient (N, 5) of the configurations q (N, 5)."""
    E = np.empty((8, 5))
    dE = np.empty((8, 5, 5))
    k = rows.shape[0]
    J = np.empty((k, 5))
    dJ = np.empty((k, 5, 5))
    for n in range(q.shape[0]):
        extended_jacobian_kernel(q[n], a2, a3, d5, E)
        extended_jacobian_derivative_kernel(q[n], a2, a3, d5, dE)
        for i in range(k):
            J[i] = E[rows[i]]
            dJ[i] = dE[rows[i]]
        m_out[n] = manipulability_kernel(J)
        gradient_kernel(J, dJ, m_out[n], grad_out[n])


# -- public functions ----------------------------------------------------------------------------
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


# -- singular configurations ---------------------------------------------------------------------
class Singularity(str, Enum):
    """Geometric conditions under which the arm can lose a task direction."""

    ELBOW_STRETCHED = "elbow_stretched"
    """q3 = 0: upper arm and forearm in line (outer reach boundary of the wrist centre)."""
    ELBOW_FOLDED = "elbow_folded"
    """q3 = +-pi: forearm folded back onto the upper arm (outside the AL5's limits)."""
    TOOL_ON_BASE_AXIS = "tool_on_base_axis"
    """Tool point on the base (q1) axis: q1 no longer moves it."""
    WRIST_ON_BASE_AXIS = "wrist_on_base_axis"
    """Wrist centre on the base axis."""
    ARM_COLLINEAR = "arm_collinear"
    """Shoulder, elbow, wrist centre and tool point in one line (sin q3 = 0 and cos q4 = 0)."""
    APPROACH_VERTICAL = "approach_vertical"
    """Approach axis parallel to the base axis (sin q234 = 0): q1 and q5 turn about one axis."""


class SingularityDistance(NamedTuple):
    """How far a configuration is from one singular condition.

    Attributes:
        kind: The condition.
        distance: Distance in its own unit: [m] for base-axis conditions, [rad] for angles.
        unit: ``"m"`` or ``"rad"``.
        normalized: Unitless distance (lengths divided by the arm's maximum reach).
    """

    kind: Singularity
    distance: float
    unit: str
    normalized: float


def _wrap(angle: float) -> float:
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def singularity_distances(
    q: np.ndarray, geometry: ArmGeometry = _DEFAULT_GEOMETRY
) -> tuple[SingularityDistance, ...]:
    """Distance of one configuration q (5,) in [rad] to every condition of :class:`Singularity`."""
    config = as_configurations(q)
    if np.ndim(q) != 1:
        raise InputError(f"q must be one configuration, shape (5,). Got: {np.shape(q)}")
    q1, q2, q3, q4, _ = config[0].tolist()
    r, _ = _plane_terms(config[0], geometry.a2, geometry.a3, geometry.d5)
    r_wrist = float(r[0]) - geometry.d5 * math.sin(q2 + q3 + q4)
    reach = geometry.max_reach
    stretched = abs(_wrap(q3))
    folded = abs(_wrap(q3 - math.pi))
    # Distance of q4 to +-pi/2 (wrist link in line with the forearm).
    wrist_in_line = abs(_wrap(2.0 * q4 - math.pi)) / 2.0
    approach = abs(_wrap(2.0 * (q2 + q3 + q4))) / 2.0
    collinear = max(min(stretched, folded), wrist_in_line)
    del q1
    return (
        SingularityDistance(Singularity.ELBOW_STRETCHED, stretched, "rad", stretched),
        SingularityDistance(Singularity.ELBOW_FOLDED, folded, "rad", folded),
        SingularityDistance(
            Singularity.TOOL_ON_BASE_AXIS, abs(float(r[0])), "m", abs(float(r[0])) / reach
        ),
        SingularityDistance(
            Singularity.WRIST_ON_BASE_AXIS, abs(r_wrist), "m", abs(r_wrist) / reach
        ),
        SingularityDistance(Singularity.ARM_COLLINEAR, collinear, "rad", collinear),
        SingularityDistance(Singularity.APPROACH_VERTICAL, approach, "rad", approach),
    )


def _on_condition(kind: Singularity, rng: np.random.Generator, geometry: ArmGeometry) -> np.ndarray:
    """A random configuration (5,) that satisfies condition ``kind`` exactly (limits ignored)."""
    q = rng.uniform(-math.pi, math.pi, 5)
    if kind in (Singularity.ELBOW_STRETCHED, Singularity.ARM_COLLINEAR):
        q[2] = 0.0
    if kind == Singularity.ELBOW_FOLDED:
        q[2] = math.pi
    if kind == Singularity.ARM_COLLINEAR:
        q[3] = math.pi / 2.0
    if kind == Singularity.APPROACH_VERTICAL:
        q[3] = -q[1] - q[2]
    if kind in (Singularity.TOOL_ON_BASE_AXIS, Singularity.WRIST_ON_BASE_AXIS):
        # r = A cos q2 + B sin q2 with A, B from q3, q4 (d5 terms dropped for the wrist centre).
        d5 = geometry.d5 if kind == Singularity.TOOL_ON_BASE_AXIS else 0.0
        q3, q4 = q[2], q[3]
        A = geometry.a2 + geometry.a3 * math.cos(q3) + d5 * math.sin(q3 + q4)
        B = -geometry.a3 * math.sin(q3) + d5 * math.cos(q3 + q4)
        q[1] = math.atan2(A, -B)
    return q


#: Smallest singular value, relative to the typical largest one, that counts as zero.
_SINGULAR_RATIO = 1e-9


def singular_conditions(
    task: str | Task | Sequence[str | int], geometry: ArmGeometry = _DEFAULT_GEOMETRY
) -> tuple[Singularity, ...]:
    """Conditions of :class:`Singularity` on which the task's manipulability vanishes.

    Evaluates m on 32 random configurations satisfying each condition exactly and keeps
    the conditions where every sample has its smallest singular value below 1e-9 of the
    typical largest one.

    Raises:
        TaskError: the task is rank deficient everywhere (no configuration gives m > 0).
    """
    return _singular_conditions(make_task(task), geometry)


@functools.lru_cache(maxsize=64)
def _singular_conditions(selected: Task, geometry: ArmGeometry) -> tuple[Singularity, ...]:
    samples = 32
    rng = np.random.default_rng(0)
    # Smallest singular value (accurate to eps * largest, unlike sqrt(det)) against the typical
    # largest one: a condition is singular when it is ~0 on every sample.
    typical = singular_values(rng.uniform(-math.pi, math.pi, (samples, 5)), selected, geometry)
    scale = float(np.median(typical[:, 0]))
    if np.median(typical[:, -1]) <= _SINGULAR_RATIO * scale:
        raise TaskError(selected.name, "the task Jacobian is rank deficient everywhere")
    found = []
    for kind in Singularity:
        q = np.array([_on_condition(kind, rng, geometry) for _ in range(samples)])
        sv = singular_values(q, selected, geometry)
        if np.all(sv[:, -1] < _SINGULAR_RATIO * scale):
            found.append(kind)
    elbow = {Singularity.ELBOW_STRETCHED, Singularity.ELBOW_FOLDED}
    if elbow <= set(found):
        # A collinear arm has its elbow stretched or folded: already covered.
        found.remove(Singularity.ARM_COLLINEAR)
    return tuple(found)


def nearest_singularity(
    q: np.ndarray,
    task: str | Task | Sequence[str | int],
    geometry: ArmGeometry = _DEFAULT_GEOMETRY,
) -> SingularityDistance:
    """The condition singular for ``task`` nearest to q (5,) in [rad] (by normalized distance)."""
    kinds = set(singular_conditions(task, geometry))
    candidates = [d for d in singularity_distances(q, geometry) if d.kind in kinds]
    if not candidates:
        raise TaskError(make_task(task).name, "no singular condition of the arm applies")
    return min(candidates, key=lambda d: d.normalized)


def near_singularities(
    q: np.ndarray,
    task: str | Task | Sequence[str | int],
    *,
    angle_tolerance: float,
    length_tolerance: float,
    geometry: ArmGeometry = _DEFAULT_GEOMETRY,
) -> tuple[SingularityDistance, ...]:
    """Conditions singular for ``task`` that q (5,) is within tolerance of, nearest first.

    Args:
        q: Joint angles, shape (5,), in [rad].
        task: Task name or row selection.
        angle_tolerance: Tolerance for angular conditions, in [rad], > 0.
        length_tolerance: Tolerance for base-axis conditions, in [m], > 0.
    """
    for name, value in (
        ("angle_tolerance", angle_tolerance),
        ("length_tolerance", length_tolerance),
    ):
        if not (math.isfinite(value) and value > 0.0):
            raise InputError(f"{name} must be a finite number > 0. Got: {value}")
    kinds = set(singular_conditions(task, geometry))
    near = [
        d
        for d in singularity_distances(q, geometry)
        if d.kind in kinds
        and d.distance <= (length_tolerance if d.unit == "m" else angle_tolerance)
    ]
    return tuple(sorted(near, key=lambda d: d.normalized))


def max_manipulability(
    task: str | Task | Sequence[str | int],
    lower: np.ndarray,
    upper: np.ndarray,
    geometry: ArmGeometry = _DEFAULT_GEOMETRY,
) -> float:
    """Largest manipulability of the task within joint limits (the scale of m-bar and sigma).

    Samples the joint box (fixed seed, 20,000 configurations) and refines the 8 best by
    projected gradient ascent with the analytic gradient.

    Args:
        task: Task name or row selection.
        lower: Lower joint limits, shape (5,), in [rad].
        upper: Upper joint limits, shape (5,), in [rad].
    """
    lo, hi = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    if lo.shape != (5,) or hi.shape != (5,):
        raise ShapeError("lower/upper", "(5,)", lo.shape if lo.shape != (5,) else hi.shape)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all() and (hi >= lo).all()):
        raise InputError("joint limits must be finite with lower <= upper")
    return _max_manipulability(make_task(task), tuple(lo.tolist()), tuple(hi.tolist()), geometry)


@functools.lru_cache(maxsize=16)
def _max_manipulability(
    task: Task, lower: tuple[float, ...], upper: tuple[float, ...], geometry: ArmGeometry
) -> float:
    lo, hi = np.array(lower), np.array(upper)
    rng = np.random.default_rng(0)
    q = rng.uniform(lo, hi, (20_000, 5))
    m = np.asarray(manipulability(q, task, geometry))
    best = q[np.argsort(m)[-8:]]
    step = 0.05
    for _ in range(200):
        m_best, grad = manipulability_and_gradient(best, task, geometry)
        norm = np.linalg.norm(grad, axis=1, keepdims=True)
        trial = np.clip(best + step * grad / np.maximum(norm, 1e-300), lo, hi)
        m_trial = np.asarray(manipulability(trial, task, geometry))
        improved = m_trial > np.asarray(m_best)
        best[improved] = trial[improved]
        if not improved.any():
            step *= 0.5
    return float(np.max(manipulability(best, task, geometry)))
