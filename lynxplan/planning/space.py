"""The joint space: a box of joint limits, Euclidean distance, straight-line interpolation.

:class:`JointSpace` for Python callers; :func:`draw_sample`, :func:`nearest` and :func:`steer` are
the same operations compiled for the planner's kernels.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np

from lynxplan.exceptions import (
    ConfigurationOutsideLimitsError,
    NonFiniteInputError,
    ShapeError,
)
from lynxplan.planning import rng as _rng
from lynxplan.planning.kernel_model import njit_no_refcount


@dataclass(frozen=True)
class JointSpace:
    """The configuration space of a robot with revolute joints, bounded by its position limits.

    Attributes:
        lower: Lower position limits, shape (nq,), in [rad] (read-only).
        upper: Upper position limits, shape (nq,), in [rad] (read-only).
        joint_names: One name per joint (used in errors).
    """

    lower: np.ndarray
    upper: np.ndarray
    joint_names: tuple[str, ...]

    def __post_init__(self) -> None:
        for name in ("lower", "upper"):
            array = np.array(getattr(self, name), dtype=float)
            array.setflags(write=False)
            object.__setattr__(self, name, array)

    @classmethod
    def of(cls, robot: object) -> JointSpace:
        """The joint space of a robot with ``limits.lower``/``limits.upper`` and a model."""
        limits = robot.limits  # type: ignore[attr-defined]
        model = robot.model  # type: ignore[attr-defined]
        names = tuple(str(n) for n in list(model.names)[1:])
        return cls(np.asarray(limits.lower), np.asarray(limits.upper), names)

    @property
    def dimension(self) -> int:
        """Number of joints nq."""
        return int(self.lower.size)

    def distance(self, q_a: np.ndarray, q_b: np.ndarray) -> float:
        """Euclidean joint-space distance, in [rad]. q_a, q_b: shape (nq,), in [rad]."""
        return float(np.linalg.norm(np.asarray(q_b) - np.asarray(q_a)))

    def interpolate(self, q_a: np.ndarray, q_b: np.ndarray, s: np.ndarray | float) -> np.ndarray:
        """Points of the straight joint line: s (...,) in [0, 1] -> (..., nq), in [rad]."""
        fraction = np.asarray(s, dtype=float)[..., None]
        points: np.ndarray = np.asarray(q_a) + fraction * (np.asarray(q_b) - np.asarray(q_a))
        return points

    def path_length(self, waypoints: np.ndarray) -> float:
        """Sum of the Euclidean lengths of the segments of (N, nq) waypoints, in [rad]."""
        return float(np.linalg.norm(np.diff(waypoints, axis=0), axis=1).sum())

    def check(self, q: object, what: str, tolerance: float = 0.0) -> np.ndarray:
        """A configuration as a fresh float array (nq,), checked for shape, values and limits.

        Args:
            q: The configuration, shape (nq,), in [rad].
            what: Its name in errors (``"start"``, ``"goal"``).
            tolerance: Accepted excursion outside a limit, in [rad] (snapped onto it).

        Raises:
            ShapeError, NonFiniteInputError: bad shape or values.
            ConfigurationOutsideLimitsError: a joint outside its limits (joint, value, limits).
        """
        config = np.array(q, dtype=float)
        if config.shape != (self.dimension,):
            raise ShapeError(what, f"({self.dimension},)", config.shape)
        if not np.isfinite(config).all():
            raise NonFiniteInputError(what)
        for j in range(self.dimension):
            value, low, high = float(config[j]), float(self.lower[j]), float(self.upper[j])
            if value < low - tolerance or value > high + tolerance:
                raise ConfigurationOutsideLimitsError(what, self.joint_names[j], value, low, high)
        clipped: np.ndarray = np.clip(config, self.lower, self.upper)
        return clipped


@njit_no_refcount()
def nearest(nodes: np.ndarray, count: int, q: np.ndarray) -> int:
    """Index of the row of nodes[:count] (N, nq) nearest to q (nq,) (Euclidean)."""
    best, best_index = np.inf, 0
    nq = q.shape[0]
    for i in range(count):
        total = 0.0
        for j in range(nq):
            d = nodes[i, j] - q[j]
            total += d * d
        if total < best:
            best, best_index = total, i
    return best_index


@numba.njit(cache=True, inline="always")
def draw_sample(
    lower: np.ndarray,
    upper: np.ndarray,
    goal_bias: float,
    other: np.ndarray,
    roots: int,
    state: np.ndarray,
    out: np.ndarray,
) -> None:
    """A uniform sample in the joint box, or (with probability goal_bias) a root of the other
    tree (other: its nodes, roots: its root count) -> out (nq,)."""
    if _rng.uniform(state) < goal_bias:
        out[:] = other[_rng.integer(state, roots)]
    else:
        for j in range(out.shape[0]):
            out[j] = lower[j] + _rng.uniform(state) * (upper[j] - lower[j])


@numba.njit(cache=True, inline="always")
def steer(q: np.ndarray, sample: np.ndarray, step: float, out: np.ndarray) -> bool:
    """q (nq,) moved by at most ``step`` [rad] towards sample -> out; False when they coincide."""
    distance = 0.0
    for j in range(q.shape[0]):
        distance += (sample[j] - q[j]) ** 2
    distance = math.sqrt(distance)
    if distance < 1e-12:
        return False
    fraction = min(1.0, step / distance)
    for j in range(q.shape[0]):
        out[j] = q[j] + fraction * (sample[j] - q[j])
    return True
