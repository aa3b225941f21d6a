"""Auto-timing: the shortest synchronised LSPB under per-joint velocity and acceleration limits.

For a normalised LSPB ``s(t)`` with cruise parameter ``T`` and blend time ``ta``, the peak rate is
``1/T`` and the blend acceleration ``1/(T ta)`` (SPEC Part 2: ``dA/T`` and ``dA/(2 T tau)``).

Free motion (joint path linear in ``s``): joint ``j`` moving ``D_j`` needs ``T >= D_j / v_j`` and
``T ta >= D_j / a_j``. With ``V = max D_j/v_j`` and ``A = max D_j/a_j``, the shortest total time
``tt = T + ta`` subject to ``ta <= T`` is the triangular profile ``T = ta = sqrt(A)`` when
``V <= sqrt(A)``, and otherwise the trapezoid ``T = V``, ``ta = A / V``.

Curved joint paths (straight lines in Cartesian space): ``qd = q'(s) sd`` and
``qdd = q'(s) sdd + q''(s) sd^2``. For a fixed ratio ``rho = ta / T`` the profile shape is
fixed and time scaling by ``k`` divides velocities by ``k`` and accelerations by ``k^2``, so the
smallest ``k`` is explicit; the ratio is then chosen by a bounded scalar search.
"""

from __future__ import annotations

import math

import numpy as np

from lynxplan.constants import MIN_SEGMENT_DURATION
from lynxplan.exceptions import InputError, ShapeError
from lynxplan.trajectory.lspb import LspbTiming


def _positive_limits(values: np.ndarray, name: str, size: int) -> np.ndarray:
    array = np.broadcast_to(np.asarray(values, dtype=float), (size,))
    if not np.all(np.isfinite(array)) or np.any(array <= 0.0):
        raise InputError(f"{name} limits must be positive and finite. Got: {array.tolist()}")
    return array


def stationary_timing() -> LspbTiming:
    """Timing given to a zero-length move by auto-timing: ``MIN_SEGMENT_DURATION``, half blends."""
    return LspbTiming(MIN_SEGMENT_DURATION, 0.5 * MIN_SEGMENT_DURATION)


def auto_timing_linear(
    delta: np.ndarray, max_velocity: np.ndarray, max_acceleration: np.ndarray
) -> LspbTiming:
    """Shortest synchronised LSPB for a joint path linear in ``s`` (free motion).

    Args:
        delta: Change per joint, shape (n,), in [rad].
        max_velocity: Speed limit per joint, shape (n,) or scalar, in [rad/s].
        max_acceleration: Acceleration limit per joint, shape (n,) or scalar, in [rad/s^2].

    Returns:
        The timing; a zero-length move gets :func:`stationary_timing`.
    """
    d = np.abs(np.asarray(delta, dtype=float))
    if d.ndim != 1:
        raise ShapeError("delta", "(n,)", d.shape)
    v = _positive_limits(max_velocity, "velocity", d.size)
    a = _positive_limits(max_acceleration, "acceleration", d.size)
    big_v = float(np.max(d / v))
    big_a = float(np.max(d / a))
    if big_a == 0.0:
        return stationary_timing()
    if big_v <= math.sqrt(big_a):
        root = math.sqrt(big_a)
        return LspbTiming(2.0 * root, root)
    return LspbTiming(big_v + big_a / big_v, big_a / big_v)


def _scale_for_ratio(
    rho: float, s: np.ndarray, dq: np.ndarray, ddq: np.ndarray, v: np.ndarray, a: np.ndarray
) -> float:
    """Smallest total time ``tt`` of an LSPB with ``ta = rho T`` keeping the path within limits."""
    # Unit-time profile: T = 1/(1+rho), ta = rho T. The report's law solved for t gives sd and sdd
    # as functions of s: first blend s <= tau/T with sd = sqrt(s/(T tau)), the last symmetric.
    big_t = 1.0 / (1.0 + rho)
    tau = 0.5 * rho * big_t
    s_blend = tau / big_t
    # The blend boundaries, where sdd jumps, are evaluated exactly (interpolated tangents).
    s_all = np.concatenate([s, [s_blend, 1.0 - s_blend]])
    ends = (s_blend, 1.0 - s_blend)
    dq_all = np.vstack([dq] + [[np.interp(x, s, col) for col in dq.T] for x in ends])
    ddq_all = np.vstack([ddq] + [[np.interp(x, s, col) for col in ddq.T] for x in ends])
    tol = 1e-12
    sd = np.minimum(np.sqrt(np.maximum(s_all, 0.0) / (big_t * tau)), 1.0 / big_t)
    sd = np.minimum(sd, np.sqrt(np.maximum(1.0 - s_all, 0.0) / (big_t * tau)))[:, None]
    sdd = 1.0 / (2.0 * big_t * tau)
    first = (s_all <= s_blend + tol)[:, None]
    last = (s_all >= 1.0 - s_blend - tol)[:, None]
    cruise = ((s_all >= s_blend - tol) & (s_all <= 1.0 - s_blend + tol))[:, None]
    curvature = ddq_all * sd**2
    acc = np.where(first, np.abs(dq_all * sdd + curvature), 0.0)
    acc = np.maximum(acc, np.where(last, np.abs(-dq_all * sdd + curvature), 0.0))
    acc = np.maximum(acc, np.where(cruise, np.abs(curvature), 0.0))
    k_vel = float(np.max(np.abs(dq_all) * sd / v))
    k_acc = math.sqrt(float(np.max(acc / a)))
    return max(k_vel, k_acc)


def auto_timing_path(
    s: np.ndarray,
    dq_ds: np.ndarray,
    d2q_ds2: np.ndarray,
    max_velocity: np.ndarray,
    max_acceleration: np.ndarray,
) -> LspbTiming:
    """Shortest LSPB of the path parameter keeping a curved joint path within limits.

    The limits are enforced on the given grid of ``s`` (a dense grid makes the answer tight).

    Args:
        s: Path parameter grid over [0, 1], shape (m,).
        dq_ds: Joint path tangent at ``s``, shape (m, n), in [rad].
        d2q_ds2: Joint path curvature at ``s``, shape (m, n), in [rad].
        max_velocity: Speed limit per joint, shape (n,) or scalar, in [rad/s].
        max_acceleration: Acceleration limit per joint, shape (n,) or scalar, in [rad/s^2].
    """
    s = np.asarray(s, dtype=float)
    dq, ddq = np.asarray(dq_ds, dtype=float), np.asarray(d2q_ds2, dtype=float)
    if s.ndim != 1 or dq.shape != (s.size, dq.shape[-1]) or ddq.shape != dq.shape:
        raise ShapeError("dq_ds, d2q_ds2", "(m, n) with m = len(s)", dq.shape)
    v = _positive_limits(max_velocity, "velocity", dq.shape[1])
    a = _positive_limits(max_acceleration, "acceleration", dq.shape[1])
    if not np.any(dq) and not np.any(ddq):
        return stationary_timing()
    # Golden-section search on rho in (0, 1]; the scale is unimodal in practice, and the coarse
    # pre-scan guards against a poor bracket.
    candidates = np.linspace(0.02, 1.0, 50)
    scales = [_scale_for_ratio(r, s, dq, ddq, v, a) for r in candidates]
    best = int(np.argmin(scales))
    lo = candidates[max(best - 1, 0)]
    hi = candidates[min(best + 1, candidates.size - 1)]
    golden = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(40):
        x1 = hi - golden * (hi - lo)
        x2 = lo + golden * (hi - lo)
        if _scale_for_ratio(x1, s, dq, ddq, v, a) <= _scale_for_ratio(x2, s, dq, ddq, v, a):
            hi = x2
        else:
            lo = x1
    rho = 0.5 * (lo + hi)
    tt = _scale_for_ratio(rho, s, dq, ddq, v, a)
    if tt <= 0.0:
        return stationary_timing()
    big_t = tt / (1.0 + rho)
    return LspbTiming(tt, min(rho * big_t, 0.5 * tt))


def min_rest_to_rest_duration(
    delta: np.ndarray, max_velocity: np.ndarray, max_acceleration: np.ndarray
) -> float:
    """A lower bound on the duration of any rest-to-rest motion by ``delta`` under the limits,
    in [s]: the slowest joint's own bang-coast-bang time (``2 sqrt(D/a)``, or ``D/v + v/a``
    when it reaches ``v``). Synchronising the joints (LSPB, ruckig, toppra), a jerk limit or
    rests at intermediate waypoints only lengthen a motion, so no timing method is shorter.

    Computed with Python floats from validated positive limits: it never raises, and is
    ``inf`` where the time overflows (e.g. an acceleration limit of 1e-300), so a caller can
    bound the samples a request implies before anything is allocated.

    Args:
        delta: Change per joint, shape (n,), in [rad].
        max_velocity: Speed limit per joint, shape (n,) or scalar, > 0, in [rad/s].
        max_acceleration: Acceleration limit per joint, shape (n,) or scalar, > 0, in [rad/s^2].
    """
    d = np.abs(np.asarray(delta, dtype=float)).ravel()
    v = np.broadcast_to(np.asarray(max_velocity, dtype=float), d.shape)
    a = np.broadcast_to(np.asarray(max_acceleration, dtype=float), d.shape)
    longest = 0.0
    for dj, vj, aj in zip(d.tolist(), v.tolist(), a.tolist(), strict=True):
        if dj == 0.0:
            continue
        cruise = vj * vj / aj  # distance needed to reach vj and stop again
        time = 2.0 * math.sqrt(dj / aj) if dj <= cruise else dj / vj + vj / aj
        longest = max(longest, time)
    return longest


def samples_implied(duration: float, rate: float) -> float:
    """Samples of a motion of ``duration`` [s] sampled at ``rate`` [Hz], both ends included
    (a bound of :func:`lynxplan.trajectory.retime.sample_times`'s count): a float, ``inf``
    when it overflows, computed before anything is allocated."""
    return math.floor(duration * rate) + 2.0 if math.isfinite(duration * rate) else math.inf
