"""Bench section ``parallel``: 3-RRR IK throughput, workspace grids, FK solves (single core)."""

from __future__ import annotations

import math

import numpy as np

from lynxplan.bench import Figure, median_seconds

SECTION = "parallel"


def _poses(count: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    return np.column_stack(
        [rng.uniform(0.15, 0.35, count), rng.uniform(0.05, 0.25, count), rng.uniform(-1, 1, count)]
    )


def run(quick: bool) -> list[Figure]:
    """Measure the parallel-robot figures."""
    from lynxplan.parallel.fk import solve_fk_batch
    from lynxplan.parallel.geometry import ParallelGeometry
    from lynxplan.parallel.ik import ik_kernel, leg_constants, solve_ik_batch
    from lynxplan.parallel.workspace import constant_orientation_workspace, orientation_stack

    geometry = ParallelGeometry()
    repeats = 3 if quick else 7
    figures = []

    count = 100_000 if quick else 400_000
    poses = _poses(count)
    legs = leg_constants(geometry)
    out, distance = np.empty((count, 8, 3)), np.empty((count, 3))
    seconds = median_seconds(lambda: ik_kernel(poses, legs, out, distance), repeats=repeats)
    rate = count / seconds
    figures.append(
        Figure(SECTION, "IK kernel, all 8 modes", rate, "poses/s", ">= 3e6", rate >= 3e6)
    )
    seconds = median_seconds(lambda: solve_ik_batch(poses, geometry), repeats=repeats)
    figures.append(
        Figure(SECTION, "IK solve_ik_batch (validation + allocation)", count / seconds, "poses/s")
    )

    alpha = math.radians(20.0)
    seconds = median_seconds(
        lambda: constant_orientation_workspace(alpha, geometry, step=5e-4), repeats=repeats
    )
    points = constant_orientation_workspace(alpha, geometry, step=5e-4).mask.size
    figures.append(
        Figure(
            SECTION,
            f"workspace 0.5 mm, report region ({points} points)",
            seconds * 1e3,
            "ms",
            "<= 50",
            seconds <= 0.05,
        )
    )
    alphas = np.radians(np.arange(360.0))
    seconds = median_seconds(
        lambda: orientation_stack(alphas, geometry, step=1e-3), repeats=1 if quick else 3
    )
    figures.append(
        Figure(SECTION, "orientation stack, 360 x 1 mm", seconds, "s", "<= 2", seconds <= 2.0)
    )
    seconds = median_seconds(
        lambda: constant_orientation_workspace(alpha, geometry, step=5e-4, mode=0), repeats=repeats
    )
    figures.append(Figure(SECTION, "workspace 0.5 mm restricted to mode +++", seconds * 1e3, "ms"))

    fk_count = 2_000 if quick else 20_000
    theta = solve_ik_batch(poses[:fk_count], geometry).angles[:, 0]
    theta = theta[~np.isnan(theta).any(axis=1)]
    seconds = median_seconds(lambda: solve_fk_batch(theta, geometry), repeats=repeats)
    figures.append(
        Figure(SECTION, "FK all assembly modes (batched sextic)", len(theta) / seconds, "solves/s")
    )
    return figures
