"""Assertions for planners' own tests: collision-free motion and joint limits.

Both raise ``AssertionError`` with a message naming what failed (link, obstacle, time, joint), so a
pytest failure reads like a report line.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lynxplan.exceptions import ShapeError


def assert_collision_free(
    q: Any,
    t: Any,
    world: Any,
    *,
    clearance: float = 0.0,
    segment: Any = None,
    acceleration_bound: Any = None,
) -> Any:
    """Assert that a sampled motion keeps at least ``clearance`` from every obstacle.

    Args:
        q: Joint angles, shape (N, nq), in [rad].
        t: Sample times, shape (N,), in [s].
        world: A :class:`lynxplan.collision.CollisionWorld`.
        clearance: Required distance at every sample, in [m] (0: no contact). Between samples
            the check proves there is no contact (see :mod:`lynxplan.collision.verify`).
        segment: Segment index of each sample, shape (N,), for the report's per-segment minima.
        acceleration_bound: Passed to :func:`lynxplan.collision.check_trajectory`.

    Returns:
        The :class:`lynxplan.collision.MotionReport`, for further checks.

    Raises:
        AssertionError: a contact, an uncertified interval, or a clearance below the required.
    """
    from lynxplan.collision import check_trajectory

    report = check_trajectory(world, q, t, segment, acceleration_bound=acceleration_bound)
    if report.contacts:
        lines = [
            f"{c.link} ({c.geometry}) hits {c.obstacle} at t = {c.time:.4f} s, "
            f"penetration {c.penetration_depth * 1e3:.4f} mm"
            + (" (between samples)" if c.between_samples else "")
            for c in report.contacts
        ]
        raise AssertionError(f"{len(lines)} contact(s): " + "; ".join(lines))
    if not report.certified:
        raise AssertionError("the between-sample check could not certify every sample interval")
    worst = report.min_clearance
    if worst.clearance < clearance:
        raise AssertionError(
            f"clearance {worst.clearance * 1e3:.4f} mm < required {clearance * 1e3:.4f} mm: "
            f"{worst.link} ({worst.geometry}) to {worst.obstacle} at t = {worst.time:.4f} s"
        )
    return report


def assert_within_limits(q: Any, arm: Any, *, tolerance: float = 0.0) -> None:
    """Assert that every sample is within the arm's joint position limits.

    Args:
        q: Joint angles, shape (nq,) or (N, nq), in [rad].
        arm: The arm (``lynxplan.arm.Arm``), whose ``limits.lower``/``upper`` (nq,) are in [rad].
        tolerance: Accepted excess beyond a limit, in [rad].

    Raises:
        AssertionError: naming the first violating sample, joint, value and limit (in degrees).
        ShapeError: q has the wrong shape.
    """
    config = np.atleast_2d(np.asarray(q, dtype=float))
    lower, upper = np.asarray(arm.limits.lower), np.asarray(arm.limits.upper)
    if config.ndim != 2 or config.shape[1] != lower.shape[0]:
        raise ShapeError("q", f"({lower.shape[0]},) or (N, {lower.shape[0]})", np.shape(q))
    bad = ~np.isfinite(config) | (config < lower - tolerance) | (config > upper + tolerance)
    if not bad.any():
        return
    sample, joint = (int(i) for i in np.argwhere(bad)[0])
    value = config[sample, joint]
    raise AssertionError(
        f"{int(bad.any(axis=1).sum())} sample(s) outside the joint limits; first: sample "
        f"{sample}, joint q{joint + 1} = {np.degrees(value):.6g} deg outside "
        f"[{np.degrees(lower[joint]):.6g}, {np.degrees(upper[joint]):.6g}] deg"
    )
