"""Side-by-side time-parameterisations of the same segments (SPEC Part 2, comparisons).

Methods, per segment:

- ``lspb``: the segment's own LSPB timing (the report's tt = 2 s, ta = 0.5 s in the OK task);
- ``lspb_auto``: the shortest synchronised LSPB within the velocity and acceleration limits;
- ``ruckig``: time-optimal, jerk-limited rest-to-rest motion (free segments only: ruckig goes
  state to state, it does not follow a Cartesian line);
- ``ruckig_lspb_duration``: ruckig forced to the segment's LSPB duration (profile shape). When
  that duration is shorter than ruckig's jerk-limited minimum, ruckig returns its minimum
  instead: :attr:`ProfileStats.duration_matched` is then False;
- ``toppra``: time-optimal parameterisation of the same geometric joint path under joint
  velocity and acceleration limits (free and straight-line segments), verified on its samples
  and slowed down uniformly if needed (:func:`toppra_profile`, :attr:`ProfileStats.time_scale`).

Every figure is measured on the sampled output, not taken from the libraries: peaks of |qd|,
|qdd| and |jerk| (finite differences of the sampled acceleration), and limit violations. LSPB and
toppra have piecewise-constant accelerations, so their jerk is impulsive: the sampled figure is
the acceleration step divided by the sample period, and it is not counted as a violation.
"""

from __future__ import annotations

import dataclasses
import math
from typing import NamedTuple

import numpy as np

from lynxplan import guards
from lynxplan.constants import LIMIT_CHECK_RELATIVE_TOLERANCE, LIMIT_SNAP_TOLERANCE
from lynxplan.exceptions import RetimingError
from lynxplan.trajectory.free import FreeSegment
from lynxplan.trajectory.limits import MotionLimits
from lynxplan.trajectory.line import LineSegment
from lynxplan.trajectory.lspb import LspbTiming
from lynxplan.trajectory.plan import DEFAULT_SAMPLE_RATE, Plan
from lynxplan.trajectory.ruckig_samples import rest_to_rest, ruckig_states
from lynxplan.trajectory.timing import auto_timing_linear, auto_timing_path, samples_implied

METHODS = ("lspb", "lspb_auto", "ruckig", "ruckig_lspb_duration", "toppra")
#: Methods whose jerk is bounded by construction (the others' sampled jerk is impulsive).
JERK_LIMITED_METHODS = ("ruckig", "ruckig_lspb_duration")
#: toppra is given the limits times this factor: it enforces them on its grid points only, and
#: the margin absorbs the spline's overshoot in between (the samples are still verified).
TOPPRA_LIMIT_SAFETY = 0.99
#: Grid points of toppra's discretisation on a free segment (a straight joint line).
TOPPRA_FREE_GRID_POINTS = 101
#: A forced duration counts as matched when the result is within this of it, in [s].
DURATION_MATCH_TOLERANCE = 1e-9
#: Rounds of uniform slow-down of a toppra profile before giving up.
TOPPRA_RESCALE_ROUNDS = 5


class Profile(NamedTuple):
    """A sampled joint trajectory of one segment (N samples, from 0 to the duration)."""

    t: np.ndarray
    """Time since the segment start, shape (N,), in [s]."""
    q: np.ndarray
    """Joint angles, shape (N, 5), in [rad]."""
    qd: np.ndarray
    """Joint velocities, shape (N, 5), in [rad/s]."""
    qdd: np.ndarray
    """Joint accelerations, shape (N, 5), in [rad/s^2]."""
    time_scale: float = 1.0
    """Uniform slow-down applied after the library's result (toppra), >= 1."""
    requested_duration: float | None = None
    """Duration the method was asked to meet (ruckig forced to the LSPB's), in [s]."""

    @property
    def jerk(self) -> np.ndarray:
        """Forward differences of the sampled acceleration, shape (N, 5), in [rad/s^3]."""
        if self.t.size < 2:
            return np.zeros_like(self.qdd)
        jerk = np.diff(self.qdd, axis=0) / np.diff(self.t)[:, None]
        return np.vstack([jerk, jerk[-1:]])


class ProfileStats(NamedTuple):
    """Figures of one method on one segment, measured on its samples."""

    method: str
    """One of :data:`METHODS`."""
    duration: float
    """Duration, in [s]."""
    peak_velocity: np.ndarray
    """Peak |qd| per joint, shape (5,), in [rad/s]."""
    peak_acceleration: np.ndarray
    """Peak |qdd| per joint, shape (5,), in [rad/s^2]."""
    peak_jerk: np.ndarray
    """Peak sampled |jerk| per joint, shape (5,), in [rad/s^3] (impulsive for LSPB/toppra)."""
    velocity_ratio: float
    """Largest peak velocity / limit over joints (> 1 is a violation)."""
    acceleration_ratio: float
    """Largest peak acceleration / limit over joints (> 1 is a violation)."""
    violations: tuple[str, ...]
    """Human-readable limit violations (position, velocity, acceleration; jerk for ruckig)."""
    time_scale: float = 1.0
    """Uniform slow-down factor applied to the library's result (toppra; 1 = none)."""
    duration_matched: bool | None = None
    """Whether a forced duration was met (ruckig forced to the LSPB's); None if not forced."""


def sample_times(duration: float, rate: float) -> np.ndarray:
    """Times 0, 1/rate, ... and the duration itself, shape (N,), in [s].

    Raises:
        ResourceLimitError: more samples than the resource limit (checked before allocating).
    """
    guards.check_size("trajectory samples (duration x rate)", samples_implied(duration, rate), 8.0)
    count = math.floor(duration * rate + 1e-9) + 1
    t = np.arange(count) / rate
    return t if t[-1] >= duration - 1e-12 else np.append(t, duration)


def lspb_profile(segment: FreeSegment | LineSegment, timing: LspbTiming, rate: float) -> Profile:
    """The segment re-timed with ``timing`` and sampled at ``rate`` [Hz]."""
    retimed = dataclasses.replace(segment, timing=timing)
    t = sample_times(timing.tt, rate)
    samples = retimed.sample(t)
    return Profile(t, samples.q, samples.qd, samples.qdd)


def auto_timing_of(segment: FreeSegment | LineSegment, limits: MotionLimits) -> LspbTiming:
    """The shortest synchronised LSPB of the segment's path within ``limits``."""
    if isinstance(segment, FreeSegment):
        delta = segment.q_end - segment.q_start
        return auto_timing_linear(delta, limits.velocity, limits.acceleration)
    g = segment.grid
    return auto_timing_path(g.s, g.dq_ds, g.d2q_ds2, limits.velocity, limits.acceleration)


def ruckig_profile(
    q_start: np.ndarray,
    q_end: np.ndarray,
    limits: MotionLimits,
    rate: float,
    minimum_duration: float | None = None,
) -> Profile:
    """Time-optimal jerk-limited rest-to-rest motion by ruckig, sampled at ``rate`` [Hz].

    Args:
        q_start: Start configuration, shape (5,), in [rad].
        q_end: End configuration, shape (5,), in [rad].
        limits: Velocity, acceleration and jerk limits.
        rate: Sample rate, in [Hz].
        minimum_duration: Force at least this duration, in [s] (e.g. the LSPB's tt).
    """
    trajectory = rest_to_rest(
        list(map(float, q_start)),
        list(map(float, q_end)),
        (
            list(map(float, limits.velocity)),
            list(map(float, limits.acceleration)),
            list(map(float, limits.jerk)),
        ),
        minimum_duration,
    )
    t = sample_times(trajectory.duration, rate)
    position, velocity, acceleration = ruckig_states(trajectory, t)
    return Profile(t, position, velocity, acceleration, requested_duration=minimum_duration)


def toppra_profile(
    segment: FreeSegment | LineSegment, limits: MotionLimits, rate: float
) -> Profile:
    """Time-optimal parameterisation of the segment's joint path by toppra, sampled at ``rate``.

    The path is a cubic spline through the segment's joint path on its grid (a straight joint
    line for free motion); toppra discretises it on the same grid (a line segment's IK grid,
    :data:`TOPPRA_FREE_GRID_POINTS` points on a free segment). toppra enforces the limits on its
    grid points only, so it is given the velocity and acceleration limits times
    :data:`TOPPRA_LIMIT_SAFETY` and its output is then verified on the samples: if a sampled
    velocity or acceleration still exceeds a limit, time is stretched uniformly by the factor
    ``k = max(velocity ratio, sqrt(acceleration ratio))`` (velocities scale by 1/k,
    accelerations by 1/k^2), re-sampled and re-verified. The factor used is the profile's
    ``time_scale`` (1 when the first result was within the limits).

    Raises:
        RetimingError: toppra found no parameterisation, or the samples still exceed the limits
            after :data:`TOPPRA_RESCALE_ROUNDS` slow-downs.
    """
    from lynxplan._toppra import import_toppra

    toppra = import_toppra()

    if isinstance(segment, LineSegment):
        s, waypoints = segment.grid.s, segment.grid.q
    else:
        s = np.linspace(0.0, 1.0, TOPPRA_FREE_GRID_POINTS)
        waypoints = segment.joint_path(s)
    if np.allclose(waypoints, waypoints[0], atol=1e-12, rtol=0):  # nothing to move
        t = np.array([0.0])
        zero = np.zeros((1, 5))
        return Profile(t, waypoints[:1].copy(), zero, zero)
    path = toppra.SplineInterpolator(s, waypoints)
    v_max = limits.velocity * TOPPRA_LIMIT_SAFETY
    a_max = limits.acceleration * TOPPRA_LIMIT_SAFETY
    velocity = toppra.constraint.JointVelocityConstraint(np.column_stack([-v_max, v_max]))
    acceleration = toppra.constraint.JointAccelerationConstraint(np.column_stack([-a_max, a_max]))
    algorithm = toppra.algorithm.TOPPRA(
        [velocity, acceleration], path, gridpoints=s, parametrizer="ParametrizeConstAccel"
    )
    trajectory = algorithm.compute_trajectory(0.0, 0.0)
    if trajectory is None:
        raise RetimingError("toppra", "the path is not parameterisable under the limits")
    duration = float(trajectory.duration)
    scale = 1.0
    for _ in range(TOPPRA_RESCALE_ROUNDS + 1):
        t = sample_times(duration * scale, rate)
        tau = np.minimum(t / scale, duration)  # time on toppra's own clock
        qd, qdd = trajectory(tau, 1) / scale, trajectory(tau, 2) / scale**2
        needed = max(
            float(np.max(np.abs(qd).max(axis=0) / limits.velocity)),
            math.sqrt(float(np.max(np.abs(qdd).max(axis=0) / limits.acceleration))),
        )
        if needed <= 1.0:
            return Profile(t, trajectory(tau), qd, qdd, time_scale=scale)
        scale *= needed * (1.0 + 1e-12)
    raise RetimingError(
        "toppra", f"the samples still exceed the limits after a slow-down by {scale:.6g}"
    )


def profile_stats(method: str, profile: Profile, limits: MotionLimits) -> ProfileStats:
    """Peaks and limit violations of a sampled profile."""
    slack = 1.0 + LIMIT_CHECK_RELATIVE_TOLERANCE
    peak_v = np.abs(profile.qd).max(axis=0)
    peak_a = np.abs(profile.qdd).max(axis=0)
    peak_j = np.abs(profile.jerk).max(axis=0)
    violations: list[str] = []
    lower, upper = limits.position[:, 0], limits.position[:, 1]
    for j in range(5):
        low, high = profile.q[:, j].min(), profile.q[:, j].max()
        if low < lower[j] - LIMIT_SNAP_TOLERANCE or high > upper[j] + LIMIT_SNAP_TOLERANCE:
            violations.append(f"q{j + 1} position [{low:.4f}, {high:.4f}] rad outside limits")
        checks = [("velocity", peak_v, limits.velocity, "rad/s")]
        checks.append(("acceleration", peak_a, limits.acceleration, "rad/s^2"))
        if method in JERK_LIMITED_METHODS:
            checks.append(("jerk", peak_j, limits.jerk, "rad/s^3"))
        for name, peak, limit, unit in checks:
            if peak[j] > limit[j] * slack:
                violations.append(f"q{j + 1} {name} {peak[j]:.4f} > {limit[j]:.4g} {unit}")
    return ProfileStats(
        method,
        float(profile.t[-1]),
        peak_v,
        peak_a,
        peak_j,
        float(np.max(peak_v / limits.velocity)),
        float(np.max(peak_a / limits.acceleration)),
        tuple(violations),
        profile.time_scale,
        None
        if profile.requested_duration is None
        else bool(abs(profile.t[-1] - profile.requested_duration) <= DURATION_MATCH_TOLERANCE),
    )


class SegmentComparison(NamedTuple):
    """Every applicable method on one segment."""

    segment: int
    """Segment index in the plan."""
    kind: str
    """``"free"`` or ``"line"``."""
    stats: dict[str, ProfileStats]
    """Method name -> figures (ruckig methods only on free segments)."""
    profiles: dict[str, Profile]
    """Method name -> sampled profile."""


def compare_segment(
    segment: FreeSegment | LineSegment,
    limits: MotionLimits,
    rate: float = DEFAULT_SAMPLE_RATE,
    index: int = 0,
) -> SegmentComparison:
    """Run every applicable method on ``segment`` and measure the samples."""
    profiles = {
        "lspb": lspb_profile(segment, segment.timing, rate),
        "lspb_auto": lspb_profile(segment, auto_timing_of(segment, limits), rate),
    }
    if isinstance(segment, FreeSegment):
        profiles["ruckig"] = ruckig_profile(segment.q_start, segment.q_end, limits, rate)
        profiles["ruckig_lspb_duration"] = ruckig_profile(
            segment.q_start, segment.q_end, limits, rate, minimum_duration=segment.duration
        )
    profiles["toppra"] = toppra_profile(segment, limits, rate)
    stats = {name: profile_stats(name, p, limits) for name, p in profiles.items()}
    return SegmentComparison(index, segment.kind, stats, profiles)


class PlanComparison(NamedTuple):
    """Per-segment comparisons and whole-plan totals."""

    segments: list[SegmentComparison]
    """One comparison per segment."""
    total_duration: dict[str, float]
    """Method -> sum of durations over the segments it applies to, in [s]."""
    segments_covered: dict[str, int]
    """Method -> number of segments it applies to."""
    peak_velocity: dict[str, np.ndarray]
    """Method -> peak |qd| per joint over the plan, shape (5,), in [rad/s]."""
    peak_acceleration: dict[str, np.ndarray]
    """Method -> peak |qdd| per joint over the plan, shape (5,), in [rad/s^2]."""
    violation_count: dict[str, int]
    """Method -> number of segments with a limit violation."""


def compare_plan(plan: Plan, rate: float = DEFAULT_SAMPLE_RATE) -> PlanComparison:
    """Compare every method on every segment of ``plan`` (limits: the plan's)."""
    comparisons = [
        compare_segment(seg, plan.limits, rate, i) for i, seg in enumerate(plan.segments)
    ]
    totals: dict[str, float] = {}
    covered: dict[str, int] = {}
    peak_v: dict[str, np.ndarray] = {}
    peak_a: dict[str, np.ndarray] = {}
    violated: dict[str, int] = {}
    for comparison in comparisons:
        for name, stats in comparison.stats.items():
            totals[name] = totals.get(name, 0.0) + stats.duration
            covered[name] = covered.get(name, 0) + 1
            peak_v[name] = np.maximum(peak_v.get(name, 0.0), stats.peak_velocity)
            peak_a[name] = np.maximum(peak_a.get(name, 0.0), stats.peak_acceleration)
            violated[name] = violated.get(name, 0) + bool(stats.violations)
    return PlanComparison(comparisons, totals, covered, peak_v, peak_a, violated)
