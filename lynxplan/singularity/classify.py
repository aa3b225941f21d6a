"""Singular configurations of the 5-DOF arm per task: distances, conditions, nearest ones,
the best manipulability (see :mod:`lynxplan.singularity.measures`)."""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from enum import Enum
from typing import NamedTuple

import numpy as np

from lynxplan.arm.geometry import ArmGeometry
from lynxplan.arm.kinematics import as_configurations
from lynxplan.exceptions import InputError, ShapeError, TaskError
from lynxplan.singularity.jacobian_kernels import _plane_terms
from lynxplan.singularity.measures import (
    manipulability,
    manipulability_and_gradient,
    singular_values,
)
from lynxplan.singularity.tasks import Task, make_task

_DEFAULT_GEOMETRY = ArmGeometry()


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
