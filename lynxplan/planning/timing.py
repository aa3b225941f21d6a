"""Time-parameterisation of a planned path under joint velocity/acceleration (and jerk) limits.

The path is a chain of straight joint segments that were certified collision-free; any motion
that leaves them would have to be checked again. Every method here therefore moves along each
segment with one scalar law ``q(t) = q_k + s(t) (q_k+1 - q_k)``, ``s`` from 0 to 1, at rest at
the waypoints (the joints are synchronised by construction, the trajectory *is* the path):

- ``"ruckig"`` (default): ruckig's time-optimal jerk-limited profile of ``s``, with the limits
  of ``s`` the tightest over the joints (``v_s = min_j v_j / |dq_j|``, same for acceleration
  and jerk);
- ``"lspb"``: the report's linear segment with parabolic blends, the shortest one within the
  limits (:func:`lynxplan.trajectory.timing.auto_timing_linear`);
- ``"toppra"``: toppra's time-optimal parameterisation of the segment under the joint velocity
  and acceleration limits (for a straight segment it is the bang-coast-bang LSPB; kept for
  comparison with the other tools).
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from lynxplan import guards
from lynxplan.exceptions import InputError, RetimingError
from lynxplan.trajectory.lspb import unit_lspb
from lynxplan.trajectory.ruckig_samples import rest_to_rest, ruckig_states
from lynxplan.trajectory.timing import auto_timing_linear, samples_implied

METHODS = ("ruckig", "lspb", "toppra")
#: Default sample rate of the time-parameterised trajectory, in [Hz].
DEFAULT_SAMPLE_RATE = 100.0


class TimedPath(NamedTuple):
    """A sampled joint trajectory along a path.

    Attributes:
        t: Sample times, shape (N,), in [s].
        q: Joint angles, shape (N, nq), in [rad].
        qd: Joint velocities, shape (N, nq), in [rad/s].
        qdd: Joint accelerations, shape (N, nq), in [rad/s^2].
        segment: Path segment of each sample, shape (N,).
    """

    t: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    segment: np.ndarray


def _unit_limits(limits: tuple[np.ndarray, ...], delta: np.ndarray) -> list[float]:
    """The limits of the path parameter s (one per joint limit array (nq,)): the tightest
    ``limit_j / |delta_j|`` over the joints that move."""
    steps = [abs(x) for x in delta.tolist()]
    return [
        min(bound / step for bound, step in zip(limit.tolist(), steps, strict=True) if step > 0)
        for limit in limits
    ]


def _ruckig_law(
    delta: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray, jerk: np.ndarray, rate: float
) -> tuple[np.ndarray, ...]:
    v, a, j = _unit_limits((velocity, acceleration, jerk), delta)
    trajectory = rest_to_rest([0.0], [1.0], ([v], [a], [j]))
    t = _times(float(trajectory.duration), rate)
    s, sd, sdd = ruckig_states(trajectory, t)
    return t, s[:, 0], sd[:, 0], sdd[:, 0]


def _lspb_law(
    delta: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray, rate: float
) -> tuple[np.ndarray, ...]:
    timing = auto_timing_linear(delta, velocity, acceleration)
    t = _times(timing.tt, rate)
    s = unit_lspb(t, timing)
    return t, s.position, s.velocity, s.acceleration


def _toppra_law(
    delta: np.ndarray, velocity: np.ndarray, acceleration: np.ndarray, rate: float
) -> tuple[np.ndarray, ...]:
    import toppra
    import toppra.algorithm
    import toppra.constraint

    grid = np.linspace(0.0, 1.0, 21)
    path = toppra.SplineInterpolator(grid, grid[:, None] * delta[None, :])
    v = toppra.constraint.JointVelocityConstraint(np.column_stack([-velocity, velocity]))
    a = toppra.constraint.JointAccelerationConstraint(
        np.column_stack([-acceleration, acceleration])
    )
    algorithm = toppra.algorithm.TOPPRA(
        [v, a], path, gridpoints=grid, parametrizer="ParametrizeConstAccel"
    )
    trajectory = algorithm.compute_trajectory(0.0, 0.0)
    if trajectory is None:
        raise RetimingError("toppra", "the segment is not parameterisable under the limits")
    t = _times(float(trajectory.duration), rate)
    # Project toppra's joint samples on the segment: s from the largest-moving joint.
    j = int(np.argmax(np.abs(delta)))
    s = trajectory(t)[:, j] / delta[j]
    sd = trajectory(t, 1)[:, j] / delta[j]
    sdd = trajectory(t, 2)[:, j] / delta[j]
    return t, np.clip(s, 0.0, 1.0), sd, sdd


def _times(duration: float, rate: float) -> np.ndarray:
    """Equally spaced sample times from 0 to ``duration`` [s], both included, at least ``rate``
    [Hz]: np.linspace's values (its step times the index, the last exactly ``duration``),
    without its overhead. ResourceLimitError beyond the sample limit, before allocating."""
    guards.check_size("trajectory samples (duration x rate)", samples_implied(duration, rate), 8.0)
    count = max(2, math.ceil(duration * rate - 1e-9) + 1)
    t = np.arange(count) * (duration / (count - 1))
    t[-1] = duration
    return t


def time_parameterize(
    waypoints: np.ndarray,
    velocity: np.ndarray,
    acceleration: np.ndarray,
    jerk: np.ndarray,
    *,
    method: str = "ruckig",
    rate: float = DEFAULT_SAMPLE_RATE,
) -> TimedPath:
    """Rest-to-rest motion along each straight segment of a path, sampled at ``rate``.

    Args:
        waypoints: Shape (N, nq), in [rad].
        velocity: Joint speed limits, shape (nq,), in [rad/s].
        acceleration: Joint acceleration limits, shape (nq,), in [rad/s^2].
        jerk: Joint jerk limits, shape (nq,), in [rad/s^3] (ruckig only).
        method: One of :data:`METHODS`.
        rate: Sample rate, in [Hz]; every segment's end is a sample too.

    Raises:
        InputError: unknown method or non-positive rate.
        RetimingError: a library found no profile.
    """
    if method not in METHODS:
        raise InputError(f"timing method must be one of {', '.join(METHODS)}. Got: {method!r}")
    if not math.isfinite(rate) or rate <= 0:
        raise InputError(f"sample rate must be positive. Got: {rate!r} Hz")
    path = np.asarray(waypoints, dtype=float)
    deltas = path[1:] - path[:-1]  # (N - 1, nq)
    moving = np.abs(deltas).max(axis=1, initial=0.0) > 0
    times, s_parts, sd_parts, sdd_parts, segments, counts = [np.zeros(1)], [], [], [], [], []
    offset = 0.0
    for k in np.flatnonzero(moving).tolist():
        delta = deltas[k]
        if method == "ruckig":
            t, s, sd, sdd = _ruckig_law(delta, velocity, acceleration, jerk, rate)
        elif method == "lspb":
            t, s, sd, sdd = _lspb_law(delta, velocity, acceleration, rate)
        else:
            t, s, sd, sdd = _toppra_law(delta, velocity, acceleration, rate)
        s = s[1:]
        s[-1] = 1.0  # the segment ends exactly on the waypoint
        times.append(offset + t[1:])
        s_parts.append(s)
        sd_parts.append(sd[1:])
        sdd_parts.append(sdd[1:])
        segments.append(k)
        counts.append(len(s))
        offset += float(t[-1])
    # every sample at once: its segment's start plus s, s' and s'' times the segment
    guards.check_size("trajectory samples (duration x rate)", sum(counts) + 1, 8.0)
    segment = np.repeat(np.asarray(segments, dtype=np.int64), counts)
    step = deltas[segment]
    rest = np.zeros((1, path.shape[1]))
    q, qd, qdd = path[:1].copy(), rest, rest.copy()
    if len(segment):
        q = np.concatenate([q, path[segment] + np.concatenate(s_parts)[:, None] * step])
        qd = np.concatenate([qd, np.concatenate(sd_parts)[:, None] * step])
        qdd = np.concatenate([qdd, np.concatenate(sdd_parts)[:, None] * step])
    return TimedPath(
        np.concatenate(times), q, qd, qdd, np.concatenate([np.zeros(1, dtype=np.int64), segment])
    )
