"""The resolved-rate problem: strategies, parameters, the timed reference path, the run's result.

Units as in :mod:`lynxplan.singularity.resolved_rate`: task coordinates ``(x, y, z, pitch)`` in
[m, m, m, rad], times in [s].
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import IntEnum
from typing import NamedTuple

import numpy as np

from lynxplan import guards
from lynxplan.arm.geometry import ArmGeometry, JointLimits
from lynxplan.arm.kinematics import as_configurations
from lynxplan.constants import RESOLVED_RATE_MAX_TIME_FACTOR
from lynxplan.exceptions import InputError, ShapeError, SingularityParameterError, TaskError
from lynxplan.singularity.measures import ROW_NAMES, Task, make_task
from lynxplan.singularity.rate_kernel import path_sample_kernel

_DEFAULT_GEOMETRY = ArmGeometry()
_DEFAULT_LIMITS = JointLimits()

#: Rows of the extended Jacobian a path can prescribe -> column of the path's (x, y, z, pitch).
PATH_ROWS = {0: 0, 1: 1, 2: 2, 6: 3}


class Strategy(IntEnum):
    """How resolved rate handles the singularity."""

    PINV = 0
    """Plain pseudo-inverse (baseline)."""
    SPEED_LIMIT = 1
    """Slow the tool so that no joint exceeds its speed limit."""
    DLS = 2
    """Damped least squares, damping rising near the singular set."""
    TR = 3
    """The report's task reconstruction (k1 shape function, k2 escape gain)."""


STRATEGY_NAMES = {
    Strategy.PINV: "pinv",
    Strategy.SPEED_LIMIT: "speed_limit",
    Strategy.DLS: "dls",
    Strategy.TR: "tr",
}


def parse_strategy(name: str | Strategy) -> Strategy:
    """Strategy from its name (``pinv``, ``speed_limit``, ``dls``, ``tr``)."""
    if isinstance(name, Strategy):
        return name
    for strategy, strategy_name in STRATEGY_NAMES.items():
        if name == strategy_name:
            return strategy
    raise InputError(
        f"unknown strategy {name!r}; valid strategies: {', '.join(STRATEGY_NAMES.values())}"
    )


@dataclass(frozen=True)
class TrParameters:
    """Parameters of the task reconstruction and of the DLS damping.

    Attributes:
        m_bar: Safety threshold of the manipulability (task units), > 0.
        sigma: Acting range of k1 above m_bar (task units), > 0.
        k_r: Escape gain, in [task units/s per unit of m], >= 0.
        lambda_max: DLS damping at m = 0, in [m/rad] for position rows, > 0.
        lambda_min: DLS damping everywhere (keeps the 5x5 system regular), > 0.
        m_dls: Manipulability below which DLS damping rises; None = m_bar + sigma.
    """

    m_bar: float
    sigma: float
    k_r: float
    lambda_max: float = 0.02
    lambda_min: float = 1e-4
    m_dls: float | None = None

    def __post_init__(self) -> None:
        for name in ("m_bar", "sigma", "lambda_max", "lambda_min"):
            _require_positive(name, getattr(self, name))
        # Damping outside this range leaves the 5x5 DLS system singular or meaningless.
        for name in ("lambda_max", "lambda_min"):
            _require_at_most(name, getattr(self, name), DAMPING_RANGE)
        _require_finite_non_negative("k_r", self.k_r)
        if self.m_dls is not None:
            _require_positive("m_dls", self.m_dls)

    def as_array(self) -> np.ndarray:
        """Packed for the kernel: m_bar, sigma, k_r, lambda_min, lambda_max, m_dls."""
        m_dls = self.m_bar + self.sigma if self.m_dls is None else self.m_dls
        return np.array([self.m_bar, self.sigma, self.k_r, self.lambda_min, self.lambda_max, m_dls])


def _require_positive(name: str, value: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0):
        raise SingularityParameterError(name, value, "a finite number > 0")


#: Valid DLS damping, in [m/rad]: below, J J^T + lambda^2 I is singular in floating point.
DAMPING_RANGE = (1e-6, 10.0)


def _require_at_most(name: str, value: float, bounds: tuple[float, float]) -> None:
    if not bounds[0] <= value <= bounds[1]:
        raise SingularityParameterError(name, value, f"within [{bounds[0]:g}, {bounds[1]:g}]")


def _require_finite_non_negative(name: str, value: float) -> None:
    if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0.0):
        raise SingularityParameterError(name, value, "a finite number >= 0")


@dataclass(frozen=True)
class PathReference:
    """A timed path of task coordinates.

    Attributes:
        points: Samples ``(x, y, z, pitch)`` at uniform s in [0, 1], shape (M, 4), M >= 2,
            in [m, m, m, rad].
        duration: Time to traverse the path, in [s], > 0.
        blend: LSPB blend time, in [s], 0 < blend <= duration / 2.
        hold: Time the reference stays at the end, in [s], >= 0.
    """

    points: np.ndarray
    duration: float
    blend: float
    hold: float = 0.0

    def __post_init__(self) -> None:
        points = np.array(self.points, dtype=float)
        if points.ndim != 2 or points.shape[1] != 4 or points.shape[0] < 2:
            raise ShapeError("points", "(M, 4) with M >= 2", points.shape)
        if not np.isfinite(points).all():
            raise InputError("path points contain NaN or infinite values")
        guards.angles("path pitch", points[:, 3])
        guards.length("path point coordinate", float(np.abs(points[:, :3]).max()))
        points.setflags(write=False)
        object.__setattr__(self, "points", points)
        _require_positive("duration", self.duration)
        _require_positive("blend", self.blend)
        if self.blend > self.duration / 2.0:
            raise SingularityParameterError(
                "blend", self.blend, f"<= duration / 2 = {self.duration / 2.0:.6g} s"
            )
        _require_finite_non_negative("hold", self.hold)
        for name in ("duration", "hold"):
            if getattr(self, name) > guards.MAX_DURATION:
                raise SingularityParameterError(
                    name, getattr(self, name), f"<= {guards.MAX_DURATION:g} s"
                )

    @classmethod
    def line(
        cls,
        start: Sequence[float] | np.ndarray,
        end: Sequence[float] | np.ndarray,
        pitch: float,
        duration: float,
        blend: float,
        hold: float = 0.0,
    ) -> PathReference:
        """Straight line from ``start`` to ``end`` (3,) in [m] at constant ``pitch`` in [rad]."""
        points = np.array([[*start, pitch], [*end, pitch]], dtype=float)
        return cls(points, duration, blend, hold)

    def sample(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Reference task coordinates (N, 4) and rates (N, 4) at path times t (N,) in [s]."""
        times = np.atleast_1d(np.asarray(t, dtype=float))
        x = np.empty((times.size, 4))
        xd = np.empty((times.size, 4))
        for i, ti in enumerate(times):
            path_sample_kernel(self.points, self.duration, self.blend, ti, x[i], xd[i])
        return x, xd


class ResolvedRateRun(NamedTuple):
    """One strategy's run along the path. Arrays have one row per step.

    Attributes:
        strategy: The strategy.
        task: The task (rows of the extended Jacobian).
        t: Time, shape (N,), in [s].
        path_time: Reference clock, shape (N,), in [s] (slower than t for ``speed_limit``).
        q: Joint angles, shape (N, 5), in [rad].
        qd: Joint speeds commanded at each step, shape (N, 5), in [rad/s].
        x: Reached (x, y, z, pitch), shape (N, 4), in [m, m, m, rad].
        x_ref: Reference (x, y, z, pitch), shape (N, 4).
        m: Manipulability of the task, shape (N,).
        k1: Task-reconstruction shape function at each step (0 for other strategies), (N,).
    """

    strategy: Strategy
    task: Task
    t: np.ndarray
    path_time: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    x: np.ndarray
    x_ref: np.ndarray
    m: np.ndarray
    k1: np.ndarray

    @property
    def position_error(self) -> np.ndarray:
        """Distance of the tool point from the reference point, shape (N,), in [m]."""
        return np.asarray(np.linalg.norm(self.x[:, :3] - self.x_ref[:, :3], axis=1))


@dataclass(frozen=True)
class ResolvedRateProblem:
    """Everything a resolved-rate run needs besides the strategy.

    Attributes:
        path: The timed reference.
        q0: Start configuration, shape (5,), in [rad].
        task: Task rows; must be a subset of (vx, vy, vz, pitch).
        parameters: TR and DLS parameters.
        dt: Step, in [s], > 0.
        gain: Tracking gain on the task error, in [1/s], >= 0.
        velocity_limits: Joint speed limits, shape (5,), in [rad/s], > 0.
        geometry: Arm dimensions.
    """

    path: PathReference
    q0: np.ndarray
    task: Task
    parameters: TrParameters
    dt: float = 1e-3
    gain: float = 2.0
    velocity_limits: np.ndarray = field(default_factory=lambda: _DEFAULT_LIMITS.velocity)
    geometry: ArmGeometry = _DEFAULT_GEOMETRY

    def __post_init__(self) -> None:
        q0 = as_configurations(self.q0, "q0")
        if np.ndim(self.q0) != 1:
            raise ShapeError("q0", "(5,)", np.shape(self.q0))
        q0 = q0[0].copy()
        q0.setflags(write=False)
        object.__setattr__(self, "q0", q0)
        task = make_task(self.task)
        if not set(task.rows) <= set(PATH_ROWS):
            names = ", ".join(ROW_NAMES[i] for i in PATH_ROWS)
            raise TaskError(task.name, f"resolved rate along a path takes rows among {names}")
        object.__setattr__(self, "task", task)
        _require_positive("dt", self.dt)
        _require_finite_non_negative("gain", self.gain)
        if self.gain * self.dt > 1.0:  # explicit Euler on the task error: stable for gain dt <= 1
            raise SingularityParameterError(
                "gain", self.gain, f"<= 1 / dt = {1.0 / self.dt:.6g} 1/s (gain * dt <= 1)"
            )
        limits = np.array(self.velocity_limits, dtype=float)
        if limits.shape != (5,):
            raise ShapeError("velocity_limits", "(5,)", limits.shape)
        if not (np.isfinite(limits).all() and (limits > 0).all()):
            raise InputError(f"velocity_limits must be finite and > 0. Got: {limits.tolist()}")
        limits.setflags(write=False)
        object.__setattr__(self, "velocity_limits", limits)

    @property
    def max_steps(self) -> int:
        """Step budget: the path time times the max time factor, plus the hold."""
        total = self.path.duration * RESOLVED_RATE_MAX_TIME_FACTOR + self.path.hold
        steps = total / self.dt + 2.0
        guards.check_size(f"resolved-rate steps (path time / dt = {self.dt:.3g} s)", steps, 160.0)
        return math.ceil(total / self.dt) + 2

    @property
    def columns(self) -> np.ndarray:
        """Column of (x, y, z, pitch) of each task row."""
        return np.array([PATH_ROWS[r] for r in self.task.rows], dtype=np.int64)
