"""Ruckig's rest-to-rest motions (:func:`rest_to_rest`) and their samples at many times in one
compiled evaluation (:func:`ruckig_states`).

``ruckig.Trajectory.at_time`` costs about 1.4 us per call from Python, and a trajectory sampled
at 100 Hz needs one call per sample: most of the time of a planned path's time-parameterisation
went there. :func:`ruckig_states` evaluates the same profiles for all samples at once, with
ruckig's own arithmetic (bit-identical to ``at_time``; tested).
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from lynxplan.exceptions import RetimingError


def rest_to_rest(
    start: list[float],
    end: list[float],
    limits: tuple[list[float], list[float], list[float]],
    minimum_duration: float | None = None,
) -> Any:
    """Ruckig's time-optimal jerk-limited motion from rest at ``start`` to rest at ``end``
    (dofs each), within ``limits`` = (velocity, acceleration, jerk) per dof; at least
    ``minimum_duration`` [s] where given. Returns the ``ruckig.Trajectory``.

    Raises:
        RetimingError: ruckig rejects the input or finds no trajectory.
    """
    from ruckig import InputParameter, Result, Ruckig, RuckigError, Trajectory

    dofs = len(start)
    params = InputParameter(dofs)
    params.current_position, params.target_position = start, end
    params.current_velocity = params.current_acceleration = [0.0] * dofs
    params.target_velocity = params.target_acceleration = [0.0] * dofs
    params.max_velocity, params.max_acceleration, params.max_jerk = limits
    if minimum_duration is not None:
        params.minimum_duration = float(minimum_duration)
    trajectory = Trajectory(dofs)
    try:
        result = Ruckig(dofs).calculate(params, trajectory)
    except RuckigError as exc:
        raise RetimingError("ruckig", str(exc).strip().splitlines()[0]) from exc
    if result not in (Result.Working, Result.Finished):
        raise RetimingError("ruckig", str(result))
    return trajectory


@numba.njit(cache=True, nogil=True)
def _sample_profile(
    ends: np.ndarray,
    start: np.ndarray,
    jerk: np.ndarray,
    duration: float,
    t: np.ndarray,
    out: np.ndarray,
    dof: int,
) -> None:
    """One degree of freedom's states at the times t (N,), in [s] -> out[0..2, :, dof].

    ends: (7,) the phases' end times; start: (3, 8) position, velocity, acceleration at the
    start of each phase (the 8th: at the end of the last); jerk: (7,) each phase's jerk.
    """
    for n in range(t.shape[0]):
        time = t[n]
        if time >= duration:  # over: from the trajectory's end, at zero jerk
            k, dt = 7, time - duration
        else:
            k = 0  # the first phase that ends after ``time`` (7: past the last one)
            while k < 7 and ends[k] <= time:
                k += 1
            dt = time - ends[k - 1] if k > 0 else time
        p0, v0, a0 = start[0, k], start[1, k], start[2, k]
        j = jerk[k] if k < 7 else 0.0
        out[0, n, dof] = p0 + dt * (v0 + dt * (a0 / 2 + dt * j / 6))
        out[1, n, dof] = v0 + dt * (a0 + dt * j / 2)
        out[2, n, dof] = a0 + dt * j


def ruckig_states(trajectory: Any, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity and acceleration of a ruckig ``Trajectory`` at the times t (N,), in
    [s]: shapes (N, dofs) each.

    Each degree of freedom's profile is seven phases of constant jerk ``j[k]`` from the states
    ``p[k], v[k], a[k]`` at the cumulative phase times; ``at_time`` finds the phase of a time
    (the first phase end above it), integrates from its start as ``p + dt (v + dt (a / 2 +
    dt j / 6))`` (the same operations here, in the same order) and, past the last phase, from
    the state at its end at zero jerk (from the trajectory's end at and after its duration). A
    trajectory with several sections (intermediate waypoints) or a brake phase (a start outside
    the limits; never a rest-to-rest motion) is sampled through ``at_time`` itself.
    """
    sections = trajectory.profiles
    profiles = sections[0]
    if len(sections) != 1 or any(p.brake.duration > 0.0 for p in profiles):
        states = np.array([trajectory.at_time(float(x)) for x in t])  # (N, 3, dofs)
        return states[:, 0], states[:, 1], states[:, 2]
    times = np.ascontiguousarray(t, dtype=float)
    out = np.empty((3, len(times), len(profiles)))
    duration = float(trajectory.duration)
    for dof, profile in enumerate(profiles):
        ends = np.cumsum(np.asarray(profile.t, dtype=float))  # ruckig's t_sum
        start = np.array([profile.p, profile.v, profile.a], dtype=float)
        _sample_profile(ends, start, np.asarray(profile.j, dtype=float), duration, times, out, dof)
    return out[0], out[1], out[2]
