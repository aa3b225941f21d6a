"""The Pinocchio closed-loop model verifies the closed-form IK and cross-checks the FK."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.parallel.fk import pose_distance, solve_fk
from lynxplan.parallel.geometry import ParallelGeometry, pose_from_mm_deg
from lynxplan.parallel.ik import solve_ik, solve_ik_batch
from lynxplan.parallel.pinocchio_model import (
    ClosedLoopModel,
    build_closed_loop_model,
    closure_residual,
    configuration_from_pose,
    platform_pose,
    solve_closure,
)

CLOSURE_ATOL_M = 1e-12  # 1e-9 mm
POSE_ATOL = 1e-9


@pytest.fixture(scope="module")
def closed() -> ClosedLoopModel:
    return build_closed_loop_model()


def test_model_structure(closed: ClosedLoopModel) -> None:
    assert closed.model.nq == 7
    assert len(closed.constraints) == 2
    assert sorted([*closed.actuated, *closed.passive]) == list(range(7))


def test_every_ik_solution_closes_the_loops(closed: ClosedLoopModel) -> None:
    rng = np.random.default_rng(3)
    poses = np.column_stack(
        [rng.uniform(0.1, 0.4, 60), rng.uniform(0.02, 0.3, 60), rng.uniform(-3, 3, 60)]
    )
    ik = solve_ik_batch(poses)
    checked = 0
    for pose, angles, ok in zip(poses, ik.angles, ik.reachable.all(axis=1), strict=True):
        if not ok:
            continue
        for theta in angles:
            q = configuration_from_pose(closed, pose, theta)
            assert closure_residual(closed, q) <= CLOSURE_ATOL_M
            assert pose_distance(platform_pose(closed, q), pose, closed.geometry) < POSE_ATOL
            checked += 1
    assert checked >= 8 * 10


def test_wrong_angles_do_not_close(closed: ClosedLoopModel) -> None:
    pose = pose_from_mm_deg(260, 180, 30)
    theta = solve_ik(pose)[0] + np.array([0.0, 0.01, 0.0])
    assert closure_residual(closed, configuration_from_pose(closed, pose, theta)) > 1e-4


@pytest.mark.parametrize("mode", [0, 1, 3])
def test_numerical_closure_solve_finds_exactly_the_fk_modes(
    closed: ClosedLoopModel, mode: int
) -> None:
    theta = solve_ik(pose_from_mm_deg(260, 180, 30))[mode]
    fk = solve_fk(theta)
    rng = np.random.default_rng(mode)
    found = np.zeros(fk.n_modes, dtype=bool)
    for _ in range(60):
        q, converged = solve_closure(closed, theta, rng.uniform(-np.pi, np.pi, 7))
        if not converged:
            continue
        pose = platform_pose(closed, q)
        distance = pose_distance(fk.poses, pose, closed.geometry)
        assert distance.min() < POSE_ATOL, f"numerical solve found a pose FK missed: {pose}"
        found[np.argmin(distance)] = True
    assert found.all()


def test_other_geometry(closed: ClosedLoopModel) -> None:
    geometry = ParallelGeometry(
        base_circumradius=0.25, proximal=0.16, distal=0.14, platform_circumradius=0.1
    )
    other = build_closed_loop_model(geometry)
    pose = np.array([0.2, 0.15, 0.2])
    for theta in solve_ik(pose, geometry):
        assert (
            closure_residual(other, configuration_from_pose(other, pose, theta)) <= CLOSURE_ATOL_M
        )
