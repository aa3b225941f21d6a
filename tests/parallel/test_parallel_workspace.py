"""Constant-orientation workspace and singularity loci of the planar 3-RRR."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lynxplan.exceptions import InputError, NonFiniteInputError
from lynxplan.parallel.geometry import ParallelGeometry
from lynxplan.parallel.ik import platform_joints, solve_ik, solve_ik_batch
from lynxplan.parallel.singular import (
    jacobians,
    type1_circles,
    type1_index,
    type2_grid,
    type2_index,
)
from lynxplan.parallel.workspace import (
    REPORT_X_RANGE,
    REPORT_Y_RANGE,
    constant_orientation_workspace,
    grid_axes,
    orientation_stack,
    reachable_stack,
)

GEOMETRY = ParallelGeometry()
ALPHA = math.radians(20.0)


def exact_area_mm2(alpha: float, columns: int = 20_000) -> float:
    """Workspace area in the report region by exact vertical-line/annulus intersections,
    integrated over x with the midpoint rule (independent of the grid code)."""
    lo, hi = GEOMETRY.leg_reach
    centres = GEOMETRY.base_joints - platform_joints(np.array([0.0, 0.0, alpha]))
    (x0, x1), (y0, y1) = REPORT_X_RANGE, REPORT_Y_RANGE
    width = (x1 - x0) / columns
    total = 0.0
    for x in x0 + width * (np.arange(columns) + 0.5):
        intervals = [(y0, y1)]
        for cx, cy in centres:
            dx2 = (x - cx) ** 2
            if dx2 > hi * hi:
                intervals = []
                break
            outer = math.sqrt(hi * hi - dx2)
            inner = math.sqrt(lo * lo - dx2) if dx2 < lo * lo else 0.0
            leg = [(cy - outer, cy - inner), (cy + inner, cy + outer)]
            intervals = [
                (max(a, c), min(b, d))
                for a, b in intervals
                for c, d in leg
                if min(b, d) > max(a, c)
            ]
        total += sum(b - a for a, b in intervals) * width
    return total * 1e6


def test_area_converges_to_exact_area() -> None:
    exact = exact_area_mm2(ALPHA)
    errors = [
        abs(constant_orientation_workspace(ALPHA, step=step).area_mm2 - exact)
        for step in (2e-3, 1e-3, 5e-4, 2.5e-4)
    ]
    assert errors[-1] < errors[0]
    assert errors[2] / exact < 1e-3
    assert errors[-1] / exact < 5e-4


def test_grid_agrees_with_ik_reachability() -> None:
    w = constant_orientation_workspace(math.radians(-10.0), step=4e-3)
    xx, yy = np.meshgrid(w.x, w.y)
    poses = np.column_stack([xx.ravel(), yy.ravel(), np.full(xx.size, w.alpha)])
    reachable = solve_ik_batch(poses).reachable.all(axis=1).reshape(w.mask.shape)
    np.testing.assert_array_equal(w.mask, reachable)
    assert w.points > 0
    assert w.mode is None


def test_report_grid_size() -> None:
    x, y = grid_axes(1e-3)
    assert (len(x), len(y)) == (351, 321)
    np.testing.assert_allclose([x[-1], y[-1]], [0.42, 0.32], atol=1e-12)
    x, y = grid_axes(5e-4)
    assert len(x) * len(y) == 701 * 641


def test_mode_restriction_is_a_singularity_free_part() -> None:
    full = constant_orientation_workspace(ALPHA)
    det = type2_grid(full.x, full.y, ALPHA, 0)
    restricted = constant_orientation_workspace(ALPHA, mode="+++")
    assert restricted.mode == 0
    assert 0 < restricted.points < full.points
    assert not np.any(restricted.mask & ~full.mask)
    signs = np.unique(np.sign(det[restricted.mask]))
    assert len(signs) == 1
    i, j = np.argwhere(restricted.mask)[0]
    seeded = constant_orientation_workspace(ALPHA, mode=0, seed=(full.x[j], full.y[i]))
    np.testing.assert_array_equal(seeded.mask, restricted.mask)


def test_stack_matches_single_orientations() -> None:
    alphas = np.radians([-10.0, 20.0, 100.0])
    stack = orientation_stack(alphas, step=2e-3)
    for k, alpha in enumerate(alphas):
        single = constant_orientation_workspace(alpha, step=2e-3)
        np.testing.assert_array_equal(stack.masks[k], single.mask)
        assert stack.areas_mm2[k] == pytest.approx(single.area_mm2)
    assert np.all(stack.total >= stack.masks[0])
    assert np.all(stack.dexterous <= stack.masks[0])


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"step": 0.0}, InputError, "step must be positive. Got: 0 mm"),
        ({"step": float("nan")}, NonFiniteInputError, "step contains NaN"),
        ({"x_range": (0.4, 0.1)}, InputError, "region must have min < max"),
        ({"step": 1e-6}, InputError, "0.001 mm step .*1.12e\\+11 requested, more than the limit"),
        ({"mode": 9}, InputError, "integer in 0..7"),
        ({"mode": 0, "seed": (0.0, 0.0)}, InputError, r"seed \(0\.000, 0\.000\) mm is outside"),
    ],
)
def test_workspace_errors(kwargs: dict, error: type[Exception], match: str) -> None:
    with pytest.raises(error, match=match):
        constant_orientation_workspace(ALPHA, **kwargs)


def test_nonfinite_alpha() -> None:
    with pytest.raises(NonFiniteInputError, match="alpha contains NaN"):
        constant_orientation_workspace(float("nan"))
    with pytest.raises(NonFiniteInputError, match="alphas contains NaN"):
        reachable_stack(np.array([np.inf]), np.zeros(2), np.zeros(2))


def test_jacobians_match_finite_differences() -> None:
    rng = np.random.default_rng(5)
    pose = np.array([0.26, 0.18, math.radians(30)])
    h = 1e-7
    for mode in range(8):
        theta = solve_ik(pose)[mode]
        jac = jacobians(pose, theta)
        for _ in range(3):
            direction = rng.normal(size=3)
            dtheta = (
                solve_ik(pose + h * direction)[mode] - solve_ik(pose - h * direction)[mode]
            ) / (2 * h)
            np.testing.assert_allclose(
                jac.direct[0] @ direction, jac.inverse[0] * dtheta, rtol=1e-6, atol=1e-9
            )


def test_type2_zero_means_concurrent_distal_lines() -> None:
    x, y = grid_axes(2e-3)
    det = type2_grid(x, y, ALPHA, 0)
    xx, yy = np.meshgrid(x[::40], y[::40])
    poses = np.column_stack([xx.ravel(), yy.ravel(), np.full(xx.size, ALPHA)])
    np.testing.assert_allclose(det[::40, ::40], type2_index(poses, 0).reshape(xx.shape), atol=1e-12)
    change = np.argwhere(np.sign(det[:, :-1]) * np.sign(det[:, 1:]) < 0)
    assert len(change) > 10
    for i, j in change[:: max(1, len(change) // 10)]:
        a, b = x[j], x[j + 1]
        for _ in range(60):  # bisection on the Type II index along the grid row
            mid = (a + b) / 2
            same = np.sign(type2_index(np.array([mid, y[i], ALPHA]), 0)[0]) == np.sign(det[i, j])
            a, b = (mid, b) if same else (a, mid)
        pose = np.array([a, y[i], ALPHA])
        theta = solve_ik(pose)[0]
        joints = platform_joints(pose)
        n = joints - (
            GEOMETRY.base_joints
            + GEOMETRY.proximal * np.column_stack([np.cos(theta), np.sin(theta)])
        )
        # Lines 1 and 2 meet at q (or are parallel); line 3 must pass through q.
        m = np.column_stack([n[0], -n[1]])
        if abs(np.linalg.det(m)) < 1e-12:
            continue
        t = np.linalg.solve(m, joints[1] - joints[0])
        q = joints[0] + t[0] * n[0]
        u, r = n[2] / np.linalg.norm(n[2]), q - joints[2]
        miss = abs(u[0] * r[1] - u[1] * r[0])
        assert miss < 1e-6 * (1 + np.linalg.norm(q - joints[2]))


def test_type1_circles_are_stretched_or_folded_legs() -> None:
    circles = type1_circles(ALPHA)
    assert len(circles) == 6
    for circle in circles:
        for angle in np.linspace(0, 2 * math.pi, 7):
            centre = circle.centre + circle.radius * np.array([math.cos(angle), math.sin(angle)])
            pose = np.array([*centre, ALPHA])
            distance = np.linalg.norm(platform_joints(pose) - GEOMETRY.base_joints, axis=1)
            assert distance[circle.leg] == pytest.approx(circle.radius, abs=1e-12)
            result = solve_ik_batch(pose)
            if result.reachable.all():
                assert abs(type1_index(pose, 0)[0, circle.leg]) < 1e-6
