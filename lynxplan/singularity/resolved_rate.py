"""Resolved-rate Cartesian motion along a path, four ways of handling singularities (SPEC Part 5).

The reference is a path of task coordinates ``x = (x, y, z, pitch)`` (tool point in [m], approach
pitch ``q2 + q3 + q4`` in [rad]), sampled at uniform path parameter ``s`` in [0, 1] (two samples
for a straight line) and timed by an LSPB law ``s(t)`` of duration ``duration`` with blends
``blend``, then held at its end for ``hold`` seconds. Each step of ``dt`` commands the task rate
``xdot_c = xdot_ref + gain (x_ref - x(q))`` (closed loop, so a strategy that leaves the path comes
back to it) and integrates ``q += qdot dt``:

1. ``pinv``: ``qdot = J^+ xdot_c`` with ``J^+ = J^T (J J^T)^-1`` (baseline; blows up).
2. ``speed_limit``: the report's solution 1; the reference clock advances at ``sigma <= 1`` chosen
   each step so that ``J^+ (sigma xdot_ref + gain e)`` respects every joint-speed limit: the tool
   slows down and the path takes longer.
3. ``dls``: damped least squares solved in the 5x5 form ``(J^T J + lambda^2 I) qdot = J^T xdot_c``
   with ``lambda^2 = lambda_min^2 + lambda_max^2 (1 - m/m_dls)^2`` for ``m < m_dls``.
4. ``tr``: the report's task reconstruction, with ``d = (dm/dq J^+)^T``, ``n = d/|d|`` and
   ``xdot_p = (I - 1/2 (1 - sign(xdot_c . n)) k1(m) n n^T) xdot_c + k2(m) n``,
   ``qdot = J^+ xdot_p``;
   ``k1`` = 1 for m <= m_bar, ``2u^3 - 3u^2 + 1`` with ``u = (m - m_bar)/sigma`` on
   (m_bar, m_bar + sigma), 0 above; ``k2 = k_r (m_bar - m)`` for m <= m_bar, else 0. SPEC writes it
   for a displacement ``dr``; it is applied here to the commanded rate (``dr / dt``), so ``k_r`` is
   in task units per second per unit of m and the result does not depend on ``dt``.

The loop runs in numba (closed-form kernels); :func:`run_reference` is the same algorithm in plain
Python/numpy with Pinocchio's Jacobian and Jacobian time variation, used to cross-check the kernel
and as the bench baseline.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any, NamedTuple

import numba
import numpy as np

from lynxplan import guards
from lynxplan.arm.geometry import ArmGeometry, JointLimits
from lynxplan.arm.kinematics import as_configurations
from lynxplan.constants import (
    COMPLETION_TOLERANCE,
    LIMIT_CHECK_RELATIVE_TOLERANCE,
    RESOLVED_RATE_MAX_TIME_FACTOR,
)
from lynxplan.exceptions import InputError, ShapeError, SingularityParameterError, TaskError
from lynxplan.singularity.measures import (
    ROW_NAMES,
    Task,
    extended_jacobian_derivative_kernel,
    extended_jacobian_kernel,
    make_task,
    manipulability_kernel,
)

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


@numba.njit(cache=True, nogil=True)
def lspb_kernel(T: float, ta: float, t: float) -> tuple[float, float]:
    """LSPB path parameter s in [0, 1] and its rate ds/dt in [1/s] at time t (clamped)."""
    v = 1.0 / (T - ta)
    acc = v / ta
    if t <= 0.0:
        return 0.0, 0.0
    if t >= T:
        return 1.0, 0.0
    if t < ta:
        return 0.5 * acc * t * t, acc * t
    if t > T - ta:
        return 1.0 - 0.5 * acc * (T - t) ** 2, acc * (T - t)
    return v * (t - 0.5 * ta), v


@numba.njit(cache=True, nogil=True)
def path_sample_kernel(
    points: np.ndarray, T: float, ta: float, t: float, x: np.ndarray, xd: np.ndarray
) -> None:
    """Piecewise-linear path of ``points`` (M, 4) timed by LSPB: write x(t), xdot(t) (4,)."""
    s, sd = lspb_kernel(T, ta, t)
    segments = points.shape[0] - 1
    u = s * segments
    i = min(int(u), segments - 1)
    f = u - i
    for c in range(4):
        slope = (points[i + 1, c] - points[i, c]) * segments
        x[c] = points[i, c] + f * (points[i + 1, c] - points[i, c])
        xd[c] = slope * sd


@numba.njit(cache=True, nogil=True)
def k1_kernel(m: float, m_bar: float, sigma: float) -> float:
    """Shape function k1(m) of the task reconstruction (SPEC Part 5)."""
    if m <= m_bar:
        return 1.0
    if m >= m_bar + sigma:
        return 0.0
    u = (m - m_bar) / sigma
    return 2.0 * u**3 - 3.0 * u**2 + 1.0


@numba.njit(cache=True, nogil=True)
def k2_kernel(m: float, m_bar: float, k_r: float) -> float:
    """Escape gain k2(m) = k_r (m_bar - m) for m <= m_bar, else 0 (SPEC Part 5)."""
    return k_r * (m_bar - m) if m <= m_bar else 0.0


@numba.njit(cache=True, nogil=True)
def _sign(value: float) -> float:
    if value > 0.0:
        return 1.0
    if value < 0.0:
        return -1.0
    return 0.0


@numba.njit(cache=True, nogil=True)
def _pseudo_inverse(J: np.ndarray) -> np.ndarray:
    """J^+ = J^T (J J^T)^-1 (k x k solve), shape (5, k); SVD pseudo-inverse if J J^T is singular."""
    A = J @ J.T
    if np.linalg.det(A) <= 0.0:
        return np.ascontiguousarray(np.linalg.pinv(J))
    return np.ascontiguousarray(np.linalg.solve(A, J).T)


@numba.njit(cache=True, nogil=True)
def _speed_scale(a: np.ndarray, b: np.ndarray, vmax: np.ndarray) -> float:
    """Largest sigma in [0, 1] with |sigma a_i + b_i| <= vmax_i; scales b in place if needed."""
    worst = 0.0
    for i in range(5):
        worst = max(worst, abs(b[i]) / vmax[i])
    if worst >= 1.0:
        for i in range(5):
            b[i] /= worst
        return 0.0
    sigma = 1.0
    for i in range(5):
        if a[i] > 0.0:
            sigma = min(sigma, (vmax[i] - b[i]) / a[i])
        elif a[i] < 0.0:
            sigma = min(sigma, (vmax[i] + b[i]) / -a[i])
    return max(sigma, 0.0)


@numba.njit(cache=True, nogil=True)
def _task_coordinates(q: np.ndarray, a2: float, a3: float, d5: float, x: np.ndarray) -> None:
    """Tool point (m) and approach pitch (rad) of q, written into x (4,)."""
    c1, s1 = math.cos(q[0]), math.sin(q[0])
    q23 = q[1] + q[2]
    q234 = q23 + q[3]
    r = d5 * math.sin(q234) + a3 * math.cos(q23) + a2 * math.cos(q[1])
    x[0], x[1] = c1 * r, s1 * r
    x[2] = a3 * math.sin(q23) + a2 * math.sin(q[1]) - d5 * math.cos(q234)
    x[3] = q234


@numba.njit(cache=True, nogil=True)
def resolved_rate_kernel(
    strategy: int,
    q0: np.ndarray,
    rows: np.ndarray,
    columns: np.ndarray,
    a2: float,
    a3: float,
    d5: float,
    points: np.ndarray,
    timing: np.ndarray,
    dt: float,
    gain: float,
    vmax: np.ndarray,
    params: np.ndarray,
    t_out: np.ndarray,
    tau_out: np.ndarray,
    q_out: np.ndarray,
    qd_out: np.ndarray,
    x_out: np.ndarray,
    xref_out: np.ndarray,
    m_out: np.ndarray,
    k1_out: np.ndarray,
) -> int:
    """Run one strategy; fill the per-step outputs and return the number of steps taken.

    ``columns[i]`` is the column of (x, y, z, pitch) of task row ``rows[i]``; ``timing`` is
    (duration, blend, hold); ``params`` is :meth:`TrParameters.as_array`.
    """
    T, ta, hold = timing[0], timing[1], timing[2]
    m_bar, sig, k_r, lam_min, lam_max, m_dls = (
        params[0],
        params[1],
        params[2],
        params[3],
        params[4],
        params[5],
    )
    k = rows.shape[0]
    E = np.empty((8, 5))
    dE = np.empty((8, 5, 5))
    J = np.empty((k, 5))
    dJ = np.empty((k, 5, 5))
    grad = np.empty(5)
    x = np.empty(4)
    xr = np.empty(4)
    xrd = np.empty(4)
    e = np.empty(k)
    ff = np.empty(k)
    q = q0.copy()
    t = 0.0
    tau = 0.0
    end = T + hold
    steps = t_out.shape[0]
    for n in range(steps):
        extended_jacobian_kernel(q, a2, a3, d5, E)
        for i in range(k):
            J[i] = E[rows[i]]
        _task_coordinates(q, a2, a3, d5, x)
        path_sample_kernel(points, T, ta, tau, xr, xrd)
        for i in range(k):
            e[i] = xr[columns[i]] - x[columns[i]]
            ff[i] = xrd[columns[i]]
        m = manipulability_kernel(J)
        k1 = 0.0
        rate = 1.0
        if strategy == 2:
            lam2 = lam_min * lam_min
            if m < m_dls:
                lam2 += (lam_max * (1.0 - m / m_dls)) ** 2
            A = J.T @ J
            for i in range(5):
                A[i, i] += lam2
            qd = np.linalg.solve(A, J.T @ (ff + gain * e))
        else:
            Jp = _pseudo_inverse(J)
            if strategy == 1:
                qa = Jp @ ff
                qb = Jp @ (gain * e)
                rate = _speed_scale(qa, qb, vmax)
                qd = rate * qa + qb
            elif strategy == 3:
                extended_jacobian_derivative_kernel(q, a2, a3, d5, dE)
                for i in range(k):
                    dJ[i] = dE[rows[i]]
                # gradient of m: m tr(J^+ dJ_j)
                for j in range(5):
                    total = 0.0
                    for i in range(k):
                        for c in range(5):
                            total += Jp[c, i] * dJ[i, c, j]
                    grad[j] = m * total
                d = grad @ Jp
                norm = math.sqrt(d @ d)
                xc = ff + gain * e
                if norm > 0.0:
                    nv = d / norm
                    k1 = k1_kernel(m, m_bar, sig)
                    k2 = k2_kernel(m, m_bar, k_r)
                    along = xc @ nv
                    xc = xc - 0.5 * (1.0 - _sign(along)) * k1 * along * nv + k2 * nv
                qd = Jp @ xc
            else:
                qd = Jp @ (ff + gain * e)
        t_out[n] = t
        tau_out[n] = tau
        q_out[n] = q
        qd_out[n] = qd
        x_out[n] = x
        xref_out[n] = xr
        m_out[n] = m
        k1_out[n] = k1
        if tau >= end - 1e-12:
            return n + 1
        q += qd * dt
        t += dt
        tau = min(tau + rate * dt, end)
    return steps


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
        return np.linalg.norm(self.x[:, :3] - self.x_ref[:, :3], axis=1)


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
        return int(math.ceil(total / self.dt)) + 2

    @property
    def columns(self) -> np.ndarray:
        """Column of (x, y, z, pitch) of each task row."""
        return np.array([PATH_ROWS[r] for r in self.task.rows], dtype=np.int64)


def run_resolved_rate(
    problem: ResolvedRateProblem, strategy: str | Strategy, *, max_steps: int | None = None
) -> ResolvedRateRun:
    """Run one strategy along the problem's path (numba kernel).

    Args:
        problem: Path, start, task, parameters.
        strategy: ``"pinv"``, ``"speed_limit"``, ``"dls"`` or ``"tr"``.
        max_steps: Stop after this many steps (default: the problem's budget).
    """
    chosen = parse_strategy(strategy)
    steps = problem.max_steps if max_steps is None else int(max_steps)
    if steps < 1:
        raise InputError(f"max_steps must be >= 1. Got: {steps}")
    # Per step: t, m, q (5), qd (5), task error and reference (about 20 floats).
    guards.check_size(f"resolved-rate steps (path time / dt = {problem.dt:.3g} s)", steps, 160.0)
    out = _allocate(steps)
    g = problem.geometry
    path = problem.path
    count = resolved_rate_kernel(
        int(chosen),
        np.array(problem.q0),
        problem.task.rows_array,
        problem.columns,
        g.a2,
        g.a3,
        g.d5,
        np.ascontiguousarray(path.points),
        np.array([path.duration, path.blend, path.hold]),
        problem.dt,
        problem.gain,
        np.array(problem.velocity_limits),
        problem.parameters.as_array(),
        *out,
    )
    return ResolvedRateRun(chosen, problem.task, *(array[:count] for array in out))


def _allocate(steps: int) -> tuple[np.ndarray, ...]:
    return (
        np.empty(steps),
        np.empty(steps),
        np.empty((steps, 5)),
        np.empty((steps, 5)),
        np.empty((steps, 4)),
        np.empty((steps, 4)),
        np.empty(steps),
        np.empty(steps),
    )


def run_all(problem: ResolvedRateProblem) -> dict[Strategy, ResolvedRateRun]:
    """Every strategy on the same problem, in :class:`Strategy` order."""
    return {strategy: run_resolved_rate(problem, strategy) for strategy in Strategy}


# -- plain Python/numpy reference (Pinocchio Jacobians) -------------------------------------------
def run_reference(
    problem: ResolvedRateProblem, strategy: str | Strategy, arm: Any, *, max_steps: int
) -> ResolvedRateRun:
    """The same algorithm as :func:`run_resolved_rate`, step by step in Python with numpy and
    Pinocchio (frame placement, LOCAL_WORLD_ALIGNED Jacobian, Jacobian time variation for dm/dq).

    Args:
        problem: As for :func:`run_resolved_rate`.
        strategy: Strategy name.
        arm: The :class:`lynxplan.arm.Arm` whose Pinocchio model is used.
        max_steps: Number of steps to run at most.
    """
    import pinocchio as pin

    chosen = parse_strategy(strategy)
    model, data, frame = arm.model, arm.data, arm.tool_frame_id
    rows, columns = list(problem.task.rows), problem.columns
    m_bar, sig, k_r, lam_min, lam_max, m_dls = problem.parameters.as_array().tolist()
    path, dt, gain = problem.path, problem.dt, problem.gain
    vmax = np.array(problem.velocity_limits)
    pitch_row = np.array([0.0, 1.0, 1.0, 1.0, 0.0])

    def extended(q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        pin.framesForwardKinematics(model, data, q)
        J6 = pin.computeFrameJacobian(model, data, q, frame, pin.LOCAL_WORLD_ALIGNED)
        roll = np.array([-math.cos(q[1] + q[2] + q[3]), 0.0, 0.0, 0.0, 1.0])
        return np.vstack([J6, pitch_row, roll]), data.oMf[frame].translation.copy()

    def gradient(q: np.ndarray, J: np.ndarray, Jp: np.ndarray, m: float) -> np.ndarray:
        grad = np.zeros(5)
        for j in range(5):
            pin.computeJointJacobiansTimeVariation(model, data, q, np.eye(5)[j])
            dJ6 = pin.getFrameJacobianTimeVariation(model, data, frame, pin.LOCAL_WORLD_ALIGNED)
            dE = np.vstack([dJ6, np.zeros(5), np.zeros(5)])
            dE[7, 0] = math.sin(q[1] + q[2] + q[3]) if 1 <= j <= 3 else 0.0
            grad[j] = m * np.trace(Jp @ dE[rows])
        return grad

    out = _allocate(max_steps)
    q, t, tau = np.array(problem.q0), 0.0, 0.0
    end = path.duration + path.hold
    count = max_steps
    for n in range(max_steps):
        E, p = extended(q)
        J = E[rows]
        x = np.array([*p, q[1] + q[2] + q[3]])
        xr_all, xrd_all = path.sample(np.array([tau]))
        e = xr_all[0][columns] - x[columns]
        ff = xrd_all[0][columns]
        m = math.sqrt(max(np.linalg.det(J @ J.T), 0.0))
        k1, rate = 0.0, 1.0
        if chosen == Strategy.DLS:
            lam2 = lam_min**2 + ((lam_max * (1.0 - m / m_dls)) ** 2 if m < m_dls else 0.0)
            qd = np.linalg.solve(J.T @ J + lam2 * np.eye(5), J.T @ (ff + gain * e))
        else:
            Jp = np.linalg.pinv(J) if m == 0.0 else np.linalg.solve(J @ J.T, J).T
            if chosen == Strategy.SPEED_LIMIT:
                qa, qb = Jp @ ff, Jp @ (gain * e)
                rate = _speed_scale_py(qa, qb, vmax)
                qd = rate * qa + qb
            elif chosen == Strategy.TR:
                d = gradient(q, J, Jp, m) @ Jp
                xc = ff + gain * e
                if np.linalg.norm(d) > 0.0:
                    nv = d / np.linalg.norm(d)
                    k1 = float(k1_kernel(m, m_bar, sig))
                    k2 = float(k2_kernel(m, m_bar, k_r))
                    projector = np.eye(len(rows)) - 0.5 * (1 - np.sign(xc @ nv)) * k1 * np.outer(
                        nv, nv
                    )
                    xc = projector @ xc + k2 * nv
                qd = Jp @ xc
            else:
                qd = Jp @ (ff + gain * e)
        for array, value in zip(out, (t, tau, q, qd, x, xr_all[0], m, k1), strict=True):
            array[n] = value
        if tau >= end - 1e-12:
            count = n + 1
            break
        q = q + qd * dt
        t += dt
        tau = min(tau + rate * dt, end)
    return ResolvedRateRun(chosen, problem.task, *(array[:count] for array in out))


def _speed_scale_py(a: np.ndarray, b: np.ndarray, vmax: np.ndarray) -> float:
    worst = float(np.max(np.abs(b) / vmax))
    if worst >= 1.0:
        b /= worst
        return 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        bounds = np.where(a > 0, (vmax - b) / a, np.where(a < 0, (vmax + b) / -a, np.inf))
    return float(max(min(1.0, bounds.min()), 0.0))


# -- metrics ---------------------------------------------------------------------------------------
class RunMetrics(NamedTuple):
    """Figures of one strategy's run.

    Attributes:
        strategy: Strategy name.
        peak_joint_speed: Largest |qdot_i| over the run, in [rad/s].
        peak_speed_ratio: Largest |qdot_i| / limit_i (> 1: a limit is exceeded).
        speed_limit_exceeded: Whether a joint exceeded its speed limit.
        max_tracking_error: Largest tool-point distance from the reference, in [m].
        rms_tracking_error: RMS of that distance over the run, in [m].
        max_pitch_error: Largest |pitch - pitch_ref|, in [rad] (0 when pitch is not a task row).
        min_manipulability: Smallest m(q) reached (task units).
        completion_time: First time the reference has reached its end and the tool is within
            ``COMPLETION_TOLERANCE`` of it, in [s]; None if it never is.
        joint_limit_violation: Largest excursion outside the joint position limits, in [rad].
    """

    strategy: str
    peak_joint_speed: float
    peak_speed_ratio: float
    speed_limit_exceeded: bool
    max_tracking_error: float
    rms_tracking_error: float
    max_pitch_error: float
    min_manipulability: float
    completion_time: float | None
    joint_limit_violation: float


def run_metrics(
    run: ResolvedRateRun, problem: ResolvedRateProblem, limits: JointLimits = _DEFAULT_LIMITS
) -> RunMetrics:
    """Metrics of a run against the problem's speed limits and ``limits``' position limits."""
    ratio = float(np.max(np.abs(run.qd) / problem.velocity_limits))
    error = run.position_error
    pitch_error = (
        float(np.max(np.abs(run.x[:, 3] - run.x_ref[:, 3]))) if 6 in run.task.rows else 0.0
    )
    arrived = (run.path_time >= problem.path.duration - 1e-12) & (error <= COMPLETION_TOLERANCE)
    completion = float(run.t[np.argmax(arrived)]) if arrived.any() else None
    violation = np.maximum(limits.lower - run.q, run.q - limits.upper).max()
    return RunMetrics(
        strategy=STRATEGY_NAMES[run.strategy],
        peak_joint_speed=float(np.max(np.abs(run.qd))),
        peak_speed_ratio=ratio,
        speed_limit_exceeded=ratio > 1.0 + LIMIT_CHECK_RELATIVE_TOLERANCE,
        max_tracking_error=float(error.max()),
        rms_tracking_error=float(np.sqrt(np.mean(error**2))),
        max_pitch_error=pitch_error,
        min_manipulability=float(run.m.min()),
        completion_time=completion,
        joint_limit_violation=max(float(violation), 0.0),
    )
