"""Bench section ``arm``: batch FK/IK throughput, single-pose IK latency, CLIK baseline.

Everything runs on one core (the numba kernels do not use threads); times are the thread's CPU
time (see :func:`lynxplan.bench.median_seconds`).
"""

from __future__ import annotations

import time

import numpy as np

from lynxplan.bench import Figure, median_seconds


def run(quick: bool) -> list[Figure]:
    """Measure the arm figures; ``quick`` uses smaller batches and fewer repeats."""
    from lynxplan.arm import forward_kinematics, load_arm, solve_ik_batch
    from lynxplan.arm.clik import solve_clik

    arm = load_arm()
    rng = np.random.default_rng(0)
    n = 100_000 if quick else 1_000_000
    repeats = 3 if quick else 7
    q = rng.uniform(arm.limits.lower, arm.limits.upper, size=(n, 5))
    poses = forward_kinematics(q)

    buffer = np.empty((n, 4, 4))
    fk_seconds = median_seconds(lambda: forward_kinematics(q, out=buffer), repeats=repeats)
    fk_alloc_seconds = median_seconds(lambda: forward_kinematics(q), repeats=repeats)
    ik_seconds = median_seconds(lambda: solve_ik_batch(poses), repeats=repeats)
    chunk = 100_000

    def ik_in_chunks() -> None:
        for start in range(0, n, chunk):
            solve_ik_batch(poses[start : start + chunk])

    ik_chunked_seconds = median_seconds(ik_in_chunks, repeats=repeats)
    # the same closed form as plain vectorised numpy, on the same poses, in the same chunks
    from lynxplan.bench.al5_numpy import ik_numpy
    from lynxplan.constants import LIMIT_SNAP_TOLERANCE

    geometry = arm.geometry

    def numpy_in_chunks() -> None:
        for start in range(0, n, chunk):
            ik_numpy(
                poses[start : start + chunk],
                geometry.a2,
                geometry.a3,
                geometry.d5,
                arm.limits.lower,
                arm.limits.upper,
                LIMIT_SNAP_TOLERANCE,
            )

    numpy_seconds = median_seconds(numpy_in_chunks, repeats=repeats)
    single = poses[0]
    calls = 2_000 if quick else 20_000
    single_seconds = median_seconds(lambda: arm.ik(single), repeats=repeats, number=calls)

    clik_count = 20 if quick else 200
    mid = 0.5 * (arm.limits.lower + arm.limits.upper)
    start = time.thread_time()
    results = [
        solve_clik(arm.model, arm.data, arm.tool_frame_id, poses[k], mid) for k in range(clik_count)
    ]
    clik_seconds = (time.thread_time() - start) / clik_count
    success = sum(r.success for r in results) / clik_count
    per_pose_ik = ik_seconds / n

    return [
        Figure(
            "arm",
            f"batch FK into a preallocated array ({n:,} poses)",
            n / fk_seconds,
            "poses/s",
            ">= 1e7",
            n / fk_seconds >= 1e7,
        ),
        Figure("arm", "batch FK allocating its output", n / fk_alloc_seconds, "poses/s"),
        Figure(
            "arm",
            f"batch IK, 4 branches + limit flags, batches of {chunk:,} poses",
            n / ik_chunked_seconds,
            "poses/s",
            ">= 6e6",
            n / ik_chunked_seconds >= 6e6,
        ),
        Figure(
            "arm",
            f"batch IK as plain vectorised numpy (same formulas), batches of {chunk:,}",
            n / numpy_seconds,
            "poses/s",
        ),
        Figure(
            "arm",
            "speed-up: compiled batch IK / vectorised numpy",
            numpy_seconds / ik_chunked_seconds,
            "x",
            ">= 5",
            numpy_seconds / ik_chunked_seconds >= 5,
        ),
        Figure(
            "arm",
            f"batch IK, 4 branches + limit flags, one call of {n:,} poses",
            n / ik_seconds,
            "poses/s",
        ),
        Figure(
            "arm",
            "single-pose arm.ik (branches, FK check, selection)",
            single_seconds * 1e6,
            "us",
            "<= 20",
            single_seconds * 1e6 <= 20,
        ),
        Figure(
            "arm",
            f"CLIK baseline, Pinocchio DLS ({clik_count} targets)",
            clik_seconds * 1e6,
            "us/solve",
        ),
        Figure("arm", "CLIK baseline success rate", 100.0 * success, "%"),
        Figure(
            "arm",
            "speed-up: CLIK / batch IK per pose",
            clik_seconds / per_pose_ik,
            "x",
            ">= 1000",
            clik_seconds / per_pose_ik >= 1000,
        ),
        Figure("arm", "speed-up: CLIK / single-pose arm.ik", clik_seconds / single_seconds, "x"),
    ]
