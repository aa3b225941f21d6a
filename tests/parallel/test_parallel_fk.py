"""FK of the planar 3-RRR: round trips with the IK, assembly-mode counts, nearest selection."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from lynxplan.exceptions import (
    DegenerateForwardKinematicsError,
    NoAssemblyModeError,
    NonFiniteInputError,
    ShapeError,
)
from lynxplan.parallel.fk import (
    closure_polynomial,
    nearest_assembly_mode,
    pose_distance,
    sextic_coefficients,
    solve_fk,
    solve_fk_batch,
)
from lynxplan.parallel.geometry import ParallelGeometry, pose_from_mm_deg
from lynxplan.parallel.ik import WORKING_MODES, elbows, platform_joints, solve_ik, solve_ik_batch

GEOMETRY = ParallelGeometry()
REFERENCE_POSE = pose_from_mm_deg(260, 180, 30)
POSE_ATOL = 1e-9  # [m] and [rad]
CLOSURE_ATOL_M = 1e-12


def count_by_scan(theta: np.ndarray, samples: int = 200_000) -> int:
    """Assembly modes counted independently: scan alpha, place the centre on the intersection of
    leg circles A and B (both branches) and count sign changes of leg C's length error."""
    alpha = np.linspace(-math.pi, math.pi, samples, endpoint=False)
    rp, el = GEOMETRY.platform_circumradius, GEOMETRY.distal
    phases = np.radians([30.0, 150.0, 270.0])
    e = elbows(theta)
    anchor = e[None] + rp * np.stack(
        [np.cos(alpha[:, None] + phases), np.sin(alpha[:, None] + phases)], axis=-1
    )
    chord = anchor[:, 1] - anchor[:, 0]
    length = np.linalg.norm(chord, axis=1)
    h2 = el**2 - (length / 2) ** 2
    normal = np.stack([-chord[:, 1], chord[:, 0]], axis=1) / length[:, None]
    count = 0
    for sign in (1.0, -1.0):
        centre = (anchor[:, 0] + anchor[:, 1]) / 2 + sign * np.sqrt(np.maximum(h2, 0))[
            :, None
        ] * normal
        miss = np.linalg.norm(centre - anchor[:, 2], axis=1) - el
        valid = h2 > 0
        both = valid & np.roll(valid, -1)
        count += int(np.sum(both & (np.sign(miss) != np.sign(np.roll(miss, -1)))))
    return count


def test_reference_pose_is_among_assembly_modes_of_each_working_mode() -> None:
    theta = solve_ik(REFERENCE_POSE)
    for m in range(8):
        result = solve_fk(theta[m])
        distance = pose_distance(result.poses, REFERENCE_POSE, GEOMETRY)
        k = int(np.argmin(distance))
        assert distance[k] < POSE_ATOL
        assert result.mode_labels()[k] == WORKING_MODES[m]


@pytest.mark.parametrize(("mode", "count"), [(0, 6), (1, 4), (2, 4), (3, 2), (4, 6), (7, 2)])
def test_assembly_mode_count_matches_independent_scan(mode: int, count: int) -> None:
    theta = solve_ik(REFERENCE_POSE)[mode]
    assert solve_fk(theta).n_modes == count == count_by_scan(theta)


def test_assembly_mode_counts_on_random_configurations_match_scan() -> None:
    rng = np.random.default_rng(7)
    poses = np.column_stack(
        [rng.uniform(0.15, 0.35, 40), rng.uniform(0.05, 0.25, 40), rng.uniform(-1, 1, 40)]
    )
    ik = solve_ik_batch(poses)
    keep = ik.reachable.all(axis=1)
    thetas = ik.angles[keep][:6, 0]
    results = solve_fk_batch(thetas)
    for theta, result in zip(thetas, results, strict=True):
        assert result.n_modes == count_by_scan(theta, samples=100_000)
        assert result.n_modes % 2 == 0
        assert 2 <= result.n_modes <= 6


@settings(max_examples=60, deadline=None)
@given(
    st.tuples(st.floats(0.10, 0.40), st.floats(0.02, 0.30), st.floats(-math.pi, math.pi)),
    st.integers(0, 7),
)
def test_ik_then_fk_recovers_the_pose(pose: tuple[float, float, float], mode: int) -> None:
    ik = solve_ik_batch(np.array(pose))
    assume(ik.reachable.all())  # ~20 % of the box is reachable: hypothesis draws more
    result = solve_fk(ik.angles[0, mode])
    assert np.min(pose_distance(result.poses, np.array(pose), GEOMETRY)) < POSE_ATOL


@settings(max_examples=60, deadline=None)
@given(st.tuples(*[st.floats(-math.pi, math.pi)] * 3))
def test_fk_then_ik_reproduces_theta_and_closes_loops(theta: tuple[float, float, float]) -> None:
    result = solve_fk(np.array(theta))
    for pose, mode in zip(result.poses, result.working_modes, strict=True):
        # Independent of the IK code: each distal link has length L.
        gaps = np.linalg.norm(platform_joints(pose) - elbows(np.array(theta)), axis=1)
        np.testing.assert_allclose(gaps, GEOMETRY.distal, atol=CLOSURE_ATOL_M)
        back = solve_ik(pose)[mode]
        np.testing.assert_allclose(np.angle(np.exp(1j * (back - theta))), 0, atol=1e-9)


def test_batch_matches_single() -> None:
    thetas = solve_ik(REFERENCE_POSE)[[0, 3]]
    batch = solve_fk_batch(thetas)
    for theta, result in zip(thetas, batch, strict=True):
        np.testing.assert_allclose(result.poses, solve_fk(theta).poses, atol=1e-12)


def test_nearest_assembly_mode_picks_the_reference() -> None:
    theta = solve_ik(REFERENCE_POSE)[0]
    np.testing.assert_allclose(
        nearest_assembly_mode(theta, REFERENCE_POSE + 0.01), REFERENCE_POSE, atol=POSE_ATOL
    )
    other = solve_fk(theta).poses[0]
    np.testing.assert_allclose(nearest_assembly_mode(theta, other), other, atol=POSE_ATOL)


def test_no_assembly_mode() -> None:
    theta = np.radians([-135.0, -45.0, 90.0])  # every elbow points away from the centre
    assert solve_fk(theta).n_modes == 0
    with pytest.raises(
        NoAssemblyModeError,
        match=r"actuated angles \(-135\.0000, -45\.0000, 90\.0000\) deg admit no assembly mode",
    ):
        nearest_assembly_mode(theta, REFERENCE_POSE)


def test_fk_input_errors() -> None:
    with pytest.raises(ShapeError, match=r"theta must have shape \(3,\) or \(N, 3\)\. Got: \(2,\)"):
        solve_fk_batch(np.zeros(2))
    with pytest.raises(ShapeError, match=r"theta must have shape \(3,\)\. Got: \(1, 3\)"):
        solve_fk(np.zeros((1, 3)))
    with pytest.raises(NonFiniteInputError, match="theta contains NaN"):
        solve_fk(np.array([0.0, np.inf, 0.0]))
    with pytest.raises(NonFiniteInputError, match="reference contains NaN"):
        nearest_assembly_mode(np.zeros(3), np.array([0.0, np.nan, 0.0]))
    with pytest.raises(ShapeError, match=r"reference must have shape \(3,\)"):
        nearest_assembly_mode(np.zeros(3), np.zeros(2))


def test_sextic_coefficients_reproduce_the_closure_function() -> None:
    """The degree-3 trigonometric polynomial from 16 samples equals f at arbitrary angles."""
    rng = np.random.default_rng(11)
    elbow = elbows(rng.uniform(-math.pi, math.pi, (50, 3)))
    alpha = rng.uniform(-10, 10, (50, 9))
    c = sextic_coefficients(elbow, GEOMETRY)  # c[:, 3 - k] multiplies exp(i k alpha)
    z = np.exp(1j * alpha)
    series = sum(c[:, 3 - k, None] * z**k for k in range(-3, 4)).real
    direct = closure_polynomial(elbow, alpha, GEOMETRY.distal, GEOMETRY.platform_circumradius)
    np.testing.assert_allclose(series, direct, atol=1e-14 * np.abs(direct).max())
    np.testing.assert_allclose(c[:, ::-1], np.conj(c), atol=1e-15)  # f is real


def test_degenerate_mechanism_is_reported() -> None:
    # Base circumradius = S: all elbows can meet at the base centre; with rp = L the platform
    # then turns freely about it, so the closure polynomial vanishes identically.
    geometry = ParallelGeometry(base_circumradius=0.17)
    towards = geometry.base_centre - geometry.base_joints
    theta = np.arctan2(towards[:, 1], towards[:, 0])
    with pytest.raises(
        DegenerateForwardKinematicsError,
        match=r"\(30\.0000, 150\.0000, -90\.0000\) deg leave the platform free",
    ):
        solve_fk(theta, geometry)
