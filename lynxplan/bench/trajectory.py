"""Bench section ``trajectory``: the OK task planned and sampled at 1 kHz, vectorised vs a loop.

Both sides build the 13-segment plan (the straight lines' grids are solved the same way) and then
produce, per sample, q, qd, qdd and the tool pose; the straight segments solve the analytic IK at
every sample. The vectorised side does it with batch kernels; the baseline loops over samples in
Python and calls the single-pose IK kernel (nearest-branch selection included) and the FK kernel
once per sample. Also timed: the ruckig and toppra comparisons of the whole task.
"""

from __future__ import annotations

import math

import numpy as np

from lynxplan.bench import Figure, median_seconds

RATE = 1000.0


def _loop_sample(plan: object) -> np.ndarray:
    """Per-sample Python loop producing the same samples as ``plan.sample(RATE)``."""
    from lynxplan.arm.geometry import ArmGeometry
    from lynxplan.arm.ik import ik_single_kernel
    from lynxplan.arm.kinematics import fk_kernel
    from lynxplan.constants import LIMIT_SNAP_TOLERANCE
    from lynxplan.trajectory.line import LineSegment
    from lynxplan.trajectory.lspb import unit_lspb_scalar

    geometry = ArmGeometry()
    lower = plan.limits.position[:, 0].copy()  # type: ignore[attr-defined]
    upper = plan.limits.position[:, 1].copy()  # type: ignore[attr-defined]
    segments = plan.segments  # type: ignore[attr-defined]
    starts = np.concatenate([[0.0], np.cumsum([seg.duration for seg in segments])])
    count = math.floor(starts[-1] * RATE + 1e-9) + 1
    tool = np.empty((1, 4, 4))
    target = np.eye(4)
    out = np.empty((count, 5))
    # Packed arguments of the single-pose kernel: (a2, a3, d5, limit_tol, lower, upper).
    params = np.concatenate(
        [[geometry.a2, geometry.a3, geometry.d5, LIMIT_SNAP_TOLERANCE], lower, upper]
    )
    rows, scalars = np.empty((4, 8)), np.empty(5)
    index = 0
    previous = segments[0].q_start.copy()
    for k in range(count):
        t = k / RATE
        while index < len(segments) - 1 and t >= starts[index + 1]:
            index += 1
        seg = segments[index]
        s, sd, sdd = unit_lspb_scalar(t - starts[index], seg.timing)
        if isinstance(seg, LineSegment):
            p0, p1 = seg.T_start[:3, 3], seg.T_end[:3, 3]
            p = p0 + s * (p1 - p0)
            pitch = seg.pitch[0] + s * (seg.pitch[1] - seg.pitch[0])
            azimuth = math.atan2(p[1], p[0])
            target[:3, 3] = p
            target[:3, 2] = (
                math.cos(azimuth) * math.sin(pitch),
                math.sin(azimuth) * math.sin(pitch),
                -math.cos(pitch),
            )
            reference = previous.copy()
            reference[4] = seg.roll[0] + s * (seg.roll[1] - seg.roll[0])
            ik_single_kernel(target, reference, params, 1, rows, scalars)  # 1: approach only
            q = rows[int(scalars[4]), :5].copy()
            first, second = seg.path_derivatives(s)
            qd, qdd = first * sd, first * sdd + second * sd * sd
        else:
            delta = seg.q_end - seg.q_start
            q = seg.q_start + delta * s
            qd, qdd = delta * sd, delta * sdd
        fk_kernel(q.reshape(1, 5), geometry.a2, geometry.a3, geometry.d5, tool)
        previous = q
        out[k] = q
        del qd, qdd  # produced like the vectorised side's, not kept
    return out


def run(quick: bool) -> list[Figure]:
    """Measure the trajectory figures."""
    from lynxplan.trajectory.ok_task import ok_task_plan
    from lynxplan.trajectory.retime import compare_plan, ruckig_profile, toppra_profile

    repeats = 3 if quick else 7
    plan = ok_task_plan()
    samples = plan.sample(RATE)
    vector = median_seconds(lambda: ok_task_plan().sample(RATE), repeats=repeats)
    loop = median_seconds(lambda: _loop_sample(ok_task_plan()), repeats=3 if quick else 5)
    # The loop must reproduce the vectorised samples (otherwise the comparison is meaningless).
    gap = float(np.abs(_loop_sample(plan) - samples.q).max())
    if gap > 1e-9:
        raise RuntimeError(f"per-sample loop differs from the vectorised samples by {gap} rad")

    free = [seg for seg in plan.segments if seg.kind == "free"]
    limits = plan.limits

    def ruckig_all() -> None:
        for seg in free:
            ruckig_profile(seg.q_start, seg.q_end, limits, RATE)

    def toppra_all() -> None:
        for seg in plan.segments:
            toppra_profile(seg, limits, RATE)

    ruckig_seconds = median_seconds(ruckig_all, repeats=repeats)
    toppra_seconds = median_seconds(toppra_all, repeats=3 if quick else 5)
    compare_seconds = median_seconds(lambda: compare_plan(plan, RATE), repeats=3)
    ratio = loop / vector
    n = samples.t.size
    return [
        Figure(
            "trajectory",
            f"OK task plan + sample at 1 kHz, vectorised IK ({n:,} samples)",
            vector * 1e3,
            "ms",
            "<= 50",
            vector * 1e3 <= 50.0,
        ),
        Figure(
            "trajectory",
            "OK task plan + sample at 1 kHz, per-sample Python loop of the IK kernel",
            loop * 1e3,
            "ms",
        ),
        Figure("trajectory", "vectorised speed-up over the loop", ratio, "x", ">= 20", ratio >= 20),
        Figure(
            "trajectory",
            f"ruckig: {len(free)} free segments, solve + sample at 1 kHz",
            ruckig_seconds * 1e3,
            "ms",
        ),
        Figure(
            "trajectory",
            f"toppra: {len(plan.segments)} segments (free + line), solve + sample at 1 kHz",
            toppra_seconds * 1e3,
            "ms",
        ),
        Figure(
            "trajectory",
            "whole comparison table of the OK task (5 methods, sampled, checked)",
            compare_seconds * 1e3,
            "ms",
        ),
    ]
