"""Collision check of a sampled joint trajectory: at every sample and between samples.

At the samples
    Every (primitive, obstacle) pair has a cheap lower bound of its distance
    (:meth:`CollisionWorld.lower_bounds`). Pairs whose bound is <= 0 are queried exactly
    (these are the contacts); the minimum clearance of each segment is found by branch and bound:
    candidates in increasing order of their bound, exact queries until the next bound is no smaller
    than the best exact distance found. Every reported clearance is an exact (engine) distance.

Between samples
    The exact verifier (:mod:`lynxplan.collision.verify`, conservative advancement, proof there)
    decides every sample interval: pairs whose sphere bounds at both samples already pass its
    test need no exact query; the others are tested with exact distances and bisected where
    those do not suffice. The motion bound of a pair on interval k is
    ``D = sum_j R_j |q[k+1, j] - q[k, j]|`` (:meth:`CollisionWorld.motion_bounds`); an
    ``acceleration_bound`` adds the interpolation-error margin
    ``m = sum_j R_j max|qdd_j| dt^2 / 8``.

Accuracy: with the default ``"coal"`` engine the clearances are exact to ~1e-10 m; the
``"fcl"`` engine (python-fcl) over-estimates box-box distances by up to millimetres (FCL issue
#508) and is kept for comparison (see :mod:`lynxplan.collision.world` and tests/collision).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lynxplan import guards
from lynxplan.collision.report import (
    NO_RECORD,
    ClearanceRecord,
    Contact,
    MotionReport,
)
from lynxplan.collision.verify import Certification, separated, smallest_exact
from lynxplan.collision.world import CollisionWorld, _configurations, reach_products
from lynxplan.exceptions import LynxplanError, NonFiniteInputError, ShapeError, TrajectoryCheckError


class _Checker:
    """State of one check: poses, lower bounds and a cache of exact distances."""

    def __init__(self, world: CollisionWorld, q: np.ndarray, t: np.ndarray) -> None:
        self.world, self.q, self.t = world, q, t
        self.poses = world.primitive_poses(q)
        self.bounds = world.lower_bounds(self.poses)
        self.cache: dict[tuple[int, int], float] = {}
        self.queries = 0

    def exact(self, sample: int, pair: int) -> float:
        key = (sample, pair)
        if key not in self.cache:
            self.cache[key] = self.world.distance(self.poses[sample], pair)
            self.queries += 1
        return self.cache[key]

    def record(self, clearance: float, pair: int, time: float, sample: int) -> ClearanceRecord:
        return ClearanceRecord(clearance, *self.world.pair_names(pair), time, sample)

    def segment_minimum(self, samples: np.ndarray) -> ClearanceRecord:
        """Branch and bound over the (sample, pair) candidates of one segment."""
        if self.world.pair_count == 0 or samples.size == 0:
            return NO_RECORD
        pairs = self.world.pair_count
        sample_of_row = samples.tolist()

        def exact(candidate: int) -> float:
            row, pair = divmod(candidate, pairs)
            return self.exact(sample_of_row[row], pair)

        best, candidate = smallest_exact(self.bounds[samples].ravel(), exact)
        row, pair = divmod(candidate, pairs)
        sample = sample_of_row[row]
        return self.record(best, pair, float(self.t[sample]), sample)

    def sample_contacts(self) -> list[Contact]:
        """Contacts at the samples, merged into runs of consecutive samples per pair."""
        contacts = []
        candidates = np.argwhere(self.bounds <= 0)
        for pair in np.unique(candidates[:, 1]).tolist():
            samples = candidates[candidates[:, 1] == pair, 0]
            depth = np.array([-self.exact(int(n), pair) for n in samples])
            touching = samples[depth >= 0]
            depth = depth[depth >= 0]
            if touching.size == 0:
                continue
            breaks = np.flatnonzero(np.diff(touching) > 1) + 1
            for run, run_depth in zip(
                np.split(touching, breaks), np.split(depth, breaks), strict=True
            ):
                deepest = int(np.argmax(run_depth))
                contacts.append(
                    Contact(
                        *self.world.pair_names(pair),
                        time=float(self.t[run[deepest]]),
                        penetration_depth=float(run_depth[deepest]),
                        t_start=float(self.t[run[0]]),
                        t_end=float(self.t[run[-1]]),
                        between_samples=False,
                    )
                )
        return contacts


def check_trajectory(
    world: CollisionWorld,
    q: Any,
    t: Any,
    segment: Any = None,
    *,
    acceleration_bound: Any = None,
) -> MotionReport:
    """Check a sampled joint trajectory against the world, at and between samples.

    Args:
        world: The collision world (arm primitives + obstacles).
        q: Joint angles, shape (N, nq), in [rad].
        t: Sample times, shape (N,), strictly increasing, in [s].
        segment: Segment index of each sample, shape (N,), integers; default: one segment.
        acceleration_bound: Largest |joint acceleration| of the real motion, shape (nq,) or
            scalar, in [rad/s^2]; adds the interpolation-error margin of the between-sample
            test. Default: the motion between samples is linear in joint space.

    Returns:
        The minimum clearances (overall and per segment), every contact, and whether every
        sample interval was certified (see the module docstring for the proof).

    Raises:
        ShapeError, NonFiniteInputError: bad array shapes or values.
        TrajectoryCheckError: times not strictly increasing, or a bad acceleration bound.
    """
    config = _configurations(guards.configurations("q", q, dof=world.model.nq), world.model.nq)
    times, segments = _check_times(t, segment, len(config))
    margins = _interpolation_margins(world, acceleration_bound, times)
    checker = _Checker(world, config, times)
    contacts = checker.sample_contacts()
    ids = np.unique(segments)
    minima = {int(s): checker.segment_minimum(np.flatnonzero(segments == s)) for s in ids}

    def exact_at(k: int, s: float, pair: int) -> float:
        q = config[k] + s * (config[k + 1] - config[k])
        return world.distance(world.primitive_poses(q)[0], pair)

    certification = Certification(world, times, exact_at)
    certification.contacts = contacts
    if len(config) > 1 and world.pair_count:
        motion = world.motion_bounds(config)  # (N - 1, P)
        lower = np.maximum(checker.bounds, 0.0)
        suspect = np.argwhere(~separated(lower[:-1], lower[1:], motion, margins[:, None]))
        for k, pair in suspect.tolist():
            d0, d1 = checker.exact(k, pair), checker.exact(k + 1, pair)
            if d0 <= 0 or d1 <= 0:
                continue  # already a contact at a sample
            lowest = certification.bisect(
                k, pair, (0.0, 1.0, d0, d1), float(motion[k, pair]), float(margins[k])
            )
            owner = int(segments[k])
            if lowest is not None and lowest.clearance < minima[owner].clearance:
                minima[owner] = lowest
    return certification.report(0.0, minima, checker.queries + certification.queries)


def clearance_profile(world: CollisionWorld, q: Any) -> np.ndarray:
    """Exact clearance to each obstacle at each sample (minimum over the arm's primitives).

    Branch and bound per sample: exact queries only for primitives whose lower bound is below the
    best distance found. q: shape (N, nq), in [rad] -> shape (N, n_obstacles), in [m].
    """
    config = _configurations(guards.configurations("q", q, dof=world.model.nq), world.model.nq)
    poses = world.primitive_poses(config)
    bounds = world.lower_bounds(poses)
    profile = np.full((len(config), len(world.obstacles)), np.inf)
    for o in range(len(world.obstacles)):
        pairs = np.flatnonzero(~world.pair_is_self & (world.pair_other == o))
        order = np.argsort(bounds[:, pairs], axis=1)
        for n in range(len(config)):
            best = np.inf
            for pair in pairs[order[n]].tolist():
                bound = bounds[n, pair]
                if bound >= best and bound > 0:
                    break
                best = min(best, world.distance(poses[n], pair))
            profile[n, o] = best
    return profile


def _check_times(t: Any, segment: Any, count: int) -> tuple[np.ndarray, np.ndarray]:
    times = guards.float_array("t", t)
    if times.shape != (count,):
        raise ShapeError("t", f"({count},)", times.shape)
    if not np.isfinite(times).all():
        raise NonFiniteInputError("t")
    steps = np.diff(times)
    if (steps <= 0).any():
        k = int(np.argmax(steps <= 0))
        raise TrajectoryCheckError(
            f"sample times must be strictly increasing: t[{k}] = {times[k]:.9g} s, "
            f"t[{k + 1}] = {times[k + 1]:.9g} s"
        )
    if segment is None:
        return times, np.zeros(count, dtype=np.intp)
    segments = np.asarray(segment)
    if segments.dtype == object:
        raise TrajectoryCheckError("segment indices must be integers. Got objects")
    if segments.shape != (count,):
        raise ShapeError("segment", f"({count},)", segments.shape)
    if not np.issubdtype(segments.dtype, np.integer):
        raise TrajectoryCheckError(f"segment indices must be integers. Got dtype {segments.dtype}")
    return times, segments.astype(np.intp)


def _interpolation_margins(world: CollisionWorld, bound: Any, times: np.ndarray) -> np.ndarray:
    """Per interval, the largest distance by which the real motion may leave the linear one, [m]."""
    if bound is None or len(times) < 2:
        return np.zeros(max(len(times) - 1, 0))
    try:
        acceleration = np.broadcast_to(
            guards.float_array("acceleration_bound", bound), (world.model.nq,)
        )
    except ValueError as exc:
        if isinstance(exc, LynxplanError):
            raise
        raise ShapeError(
            "acceleration_bound", f"() or ({world.model.nq},)", np.shape(bound)
        ) from None
    if not np.isfinite(acceleration).all() or (acceleration < 0).any():
        raise TrajectoryCheckError(
            f"acceleration_bound must be finite and >= 0. Got: {np.asarray(bound).tolist()}"
        )
    # Linear interpolation error of a C2 function: |q - lerp| <= max|q''| dt^2 / 8 per joint.
    joint_error = np.diff(times)[:, None] ** 2 / 8.0 * acceleration  # (N - 1, nq)
    return np.asarray(reach_products(joint_error, world._reach).max(axis=1))
