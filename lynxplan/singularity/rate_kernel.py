"""The resolved-rate loop in numba (see :mod:`lynxplan.singularity.resolved_rate`), in named steps.

Each step: the task state (extended Jacobian rows, task coordinates, reference, error), the joint
rate of the strategy, the record of the step, the integration. The kernel takes structured
parameters: the task rows, the timed path, the strategy's settings and the output arrays.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba
import numpy as np

from lynxplan.singularity.measures import (
    extended_jacobian_derivative_kernel,
    extended_jacobian_kernel,
    manipulability_kernel,
)
from lynxplan.trajectory.lspb import lspb_scalar

#: Strategy indices of :class:`lynxplan.singularity.resolved_rate.Strategy` (kernel side).
_PINV, _SPEED_LIMIT, _DLS, _TR = 0, 1, 2, 3


class RateTask(NamedTuple):
    """Task rows of the extended Jacobian and the column of ``(x, y, z, pitch)`` of each."""

    rows: np.ndarray
    """(k,) int64."""
    columns: np.ndarray
    """(k,) int64."""


class RatePath(NamedTuple):
    """The timed reference: points (M, 4) at uniform s, LSPB duration and blend, hold, in [s]."""

    points: np.ndarray
    duration: float
    blend: float
    hold: float


class RateSettings(NamedTuple):
    """Strategy, step [s], tracking gain [1/s], joint speed limits (5,) [rad/s], TR and DLS
    parameters (see :class:`lynxplan.singularity.resolved_rate.TrParameters`)."""

    strategy: int
    dt: float
    gain: float
    vmax: np.ndarray
    m_bar: float
    sigma: float
    k_r: float
    lambda_min: float
    lambda_max: float
    m_dls: float


class RateOutputs(NamedTuple):
    """Per-step output arrays (N rows), the fields of ``ResolvedRateRun`` after the task."""

    t: np.ndarray
    path_time: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    x: np.ndarray
    x_ref: np.ndarray
    m: np.ndarray
    k1: np.ndarray

    @classmethod
    def empty(cls, steps: int) -> RateOutputs:
        """Uninitialised arrays for ``steps`` steps."""
        return cls(
            np.empty(steps),
            np.empty(steps),
            np.empty((steps, 5)),
            np.empty((steps, 5)),
            np.empty((steps, 4)),
            np.empty((steps, 4)),
            np.empty(steps),
            np.empty(steps),
        )


class RateScratch(NamedTuple):
    """Work arrays of one run, allocated once."""

    E: np.ndarray
    """Extended Jacobian, (8, 5)."""
    x: np.ndarray
    """Reached task coordinates, (4,)."""
    xr: np.ndarray
    """Reference task coordinates, (4,)."""
    xrd: np.ndarray
    """Reference task rates, (4,)."""
    dE: np.ndarray  # noqa: N815 (the maths name)
    """Extended Jacobian derivatives, (8, 5, 5)."""
    grad: np.ndarray
    """Manipulability gradient, (5,)."""


@numba.njit(cache=True, nogil=True)
def lspb_kernel(T: float, ta: float, t: float) -> tuple[float, float]:
    """LSPB path parameter s in [0, 1] and its rate ds/dt in [1/s] at time t (clamped), for
    duration ``T`` and blend ``ta`` in [s]: the law of :mod:`lynxplan.trajectory.lspb`."""
    s, sd, _ = lspb_scalar(t, T, ta)
    return s, sd


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


@numba.njit(cache=True, nogil=True, inline="always")
def _dls_rate(J: np.ndarray, xc: np.ndarray, m: float, settings: RateSettings) -> np.ndarray:
    """Damped least squares, damping rising below ``m_dls``: (J^T J + lambda^2 I) qd = J^T xc."""
    lam2 = settings.lambda_min * settings.lambda_min
    if m < settings.m_dls:
        lam2 += (settings.lambda_max * (1.0 - m / settings.m_dls)) ** 2
    A = J.T @ J
    for i in range(5):
        A[i, i] += lam2
    return np.linalg.solve(A, J.T @ xc)


@numba.njit(cache=True, nogil=True, inline="always")
def _tr_command(
    q: np.ndarray,
    arm: tuple[float, float, float],
    rows: np.ndarray,
    Jp: np.ndarray,
    m: float,
    xc: np.ndarray,
    settings: RateSettings,
    work: tuple[np.ndarray, np.ndarray],
) -> tuple[np.ndarray, float]:
    """Task reconstruction: the reconstructed command ``xdot_p`` and ``k1(m)``; ``work`` =
    (dE (8, 5, 5), grad (5,)) are work arrays."""
    dE, grad = work
    k = rows.shape[0]
    extended_jacobian_derivative_kernel(q, arm[0], arm[1], arm[2], dE)
    # gradient of m: m tr(J^+ dJ_j)
    for j in range(5):
        total = 0.0
        for i in range(k):
            for c in range(5):
                total += Jp[c, i] * dE[rows[i], c, j]
        grad[j] = m * total
    d = grad @ Jp
    norm = math.sqrt(d @ d)
    if norm <= 0.0:
        return xc, 0.0
    nv = d / norm
    k1 = k1_kernel(m, settings.m_bar, settings.sigma)
    k2 = k2_kernel(m, settings.m_bar, settings.k_r)
    along = xc @ nv
    return xc - 0.5 * (1.0 - _sign(along)) * k1 * along * nv + k2 * nv, k1


@numba.njit(cache=True, nogil=True, inline="always")
def _joint_rate(
    q: np.ndarray,
    arm: tuple[float, float, float],
    rows: np.ndarray,
    J: np.ndarray,
    m: float,
    task_error: tuple[np.ndarray, np.ndarray],
    settings: RateSettings,
    work: tuple[np.ndarray, np.ndarray],
) -> tuple[np.ndarray, float, float]:
    """Step 2: the strategy's joint rate ``qd`` (5,), ``k1`` and the path-clock rate from the
    task error and feed-forward rate ``task_error`` = (e, ff) (k,) each; ``work`` as in
    ``_tr_command``."""
    e, ff = task_error
    gain = settings.gain
    if settings.strategy == _DLS:
        return _dls_rate(J, ff + gain * e, m, settings), 0.0, 1.0
    Jp = _pseudo_inverse(J)
    if settings.strategy == _SPEED_LIMIT:
        qa = Jp @ ff
        qb = Jp @ (gain * e)
        rate = _speed_scale(qa, qb, settings.vmax)
        return rate * qa + qb, 0.0, rate
    if settings.strategy == _TR:
        xc, k1 = _tr_command(q, arm, rows, Jp, m, ff + gain * e, settings, work)
        return Jp @ xc, k1, 1.0
    return Jp @ (ff + gain * e), 0.0, 1.0


@numba.njit(cache=True, nogil=True)
def resolved_rate_kernel(
    q0: np.ndarray,
    arm: tuple[float, float, float],
    task: RateTask,
    path: RatePath,
    settings: RateSettings,
    out: RateOutputs,
) -> int:
    """Run one strategy from ``q0`` (5,) for the arm's ``(a2, a3, d5)`` in [m]; fill ``out`` and
    return the number of steps taken (at most its length)."""
    k = task.rows.shape[0]
    scratch = RateScratch(
        np.empty((8, 5)), np.empty(4), np.empty(4), np.empty(4), np.empty((8, 5, 5)), np.empty(5)
    )
    J = np.empty((k, 5))
    e = np.empty(k)
    ff = np.empty(k)
    q = q0.copy()
    a2, a3, d5 = arm
    rows, columns, points = task.rows, task.columns, path.points
    E, x, xr, xrd, dE, grad = scratch
    t = 0.0
    tau = 0.0
    end = path.duration + path.hold
    steps = out.t.shape[0]
    for n in range(steps):
        # Step 1, the task state: J, x, the reference, e, ff and m (written out here: array
        # arguments of a helper cost reference counting at every step).
        extended_jacobian_kernel(q, a2, a3, d5, E)
        for i in range(k):
            J[i] = E[rows[i]]
        _task_coordinates(q, a2, a3, d5, x)
        path_sample_kernel(points, path.duration, path.blend, tau, xr, xrd)
        for i in range(k):
            e[i] = xr[columns[i]] - x[columns[i]]
            ff[i] = xrd[columns[i]]
        m = manipulability_kernel(J)
        qd, k1, rate = _joint_rate(q, arm, rows, J, m, (e, ff), settings, (dE, grad))
        out.t[n] = t
        out.path_time[n] = tau
        out.q[n] = q
        out.qd[n] = qd
        out.x[n] = x
        out.x_ref[n] = xr
        out.m[n] = m
        out.k1[n] = k1
        if tau >= end - 1e-12:
            return n + 1
        q += qd * settings.dt
        t += settings.dt
        tau = min(tau + rate * settings.dt, end)
    return int(steps)
