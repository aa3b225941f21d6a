"""Property tests over the public API: finite in-range input gives a finite, verified result (or a
documented kinematic failure); anything else raises a LynxplanInputError subclass, never another
exception type (no numba typing error, no numpy error, no NaN result)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from lynxplan import guards, load_arm
from lynxplan.collision import CollisionWorld, check_trajectory
from lynxplan.collision.obstacles import axis_aligned_box
from lynxplan.constants import ACOS_CLAMP_TOLERANCE
from lynxplan.exceptions import KinematicsError, LynxplanError, LynxplanInputError
from lynxplan.parallel import ParallelGeometry, solve_fk, solve_ik_batch
from lynxplan.parallel.ik import elbows, platform_joints
from lynxplan.trajectory import LspbTiming, free_segment, line_segment

ARM = load_arm()
#: IK position accuracy: acos arguments within ACOS_CLAMP_TOLERANCE (1e-9) of 1 are clamped, so at
#: a stretched elbow the angle may be off by sqrt(2e-9) = 4.5e-5 rad: ~7e-6 m at the pen tip.
IK_POSITION_TOLERANCE = math.sqrt(2 * ACOS_CLAMP_TOLERANCE) * (ARM.geometry.a2 + ARM.geometry.a3)
SETTINGS = settings(
    max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True
)
#: Any float: NaN, infinities, huge and tiny values, negative zero.
ANY_FLOAT = st.floats(allow_nan=True, allow_infinity=True)
#: Mostly reasonable angles, sometimes anything.
ANGLE = st.one_of(st.floats(-4.0, 4.0), ANY_FLOAT)
#: Arrays of random shape (0..3 dimensions, small sides) and a random numeric/odd dtype.
ODD_ARRAYS = hnp.arrays(
    dtype=st.sampled_from([np.float64, np.float32, np.int64, np.complex128, np.bool_, np.uint8]),
    shape=hnp.array_shapes(min_dims=0, max_dims=3, min_side=0, max_side=6),
)


def in_range(values: Any) -> bool:
    array = np.asarray(values, dtype=float)
    return bool(np.isfinite(array).all() and (np.abs(array) <= guards.MAX_ABS_ANGLE).all())


def rigid(T: np.ndarray) -> bool:
    R = T[:3, :3]
    if not np.isfinite(R).all() or np.abs(R).max() > 2.0:
        return False
    return bool(np.allclose(R.T @ R, np.eye(3), atol=1e-9) and np.linalg.det(R) > 0)


@SETTINGS
@given(st.lists(ANGLE, min_size=5, max_size=5))
def test_fk(q: list[float]) -> None:
    if in_range(q):
        T = ARM.fk(q)
        assert np.isfinite(T).all() and rigid(T)
        np.testing.assert_allclose(T, ARM.frame_placement(q), atol=1e-9)  # Pinocchio agrees
    else:
        with pytest.raises(LynxplanInputError):
            ARM.fk(q)


@SETTINGS
@given(ODD_ARRAYS)
def test_fk_and_jacobian_odd_arrays(q: np.ndarray) -> None:
    for call in (ARM.fk, ARM.jacobian):
        try:
            result = call(q)
        except LynxplanInputError:
            continue
        assert q.shape[-1:] == (5,) and q.dtype.kind in "biuf" and in_range(q)
        assert np.isfinite(result).all()


@SETTINGS
@given(st.lists(st.floats(-3.0, 3.0), min_size=5, max_size=5), st.lists(ANY_FLOAT, max_size=16))
def test_ik(q: list[float], noise: list[float]) -> None:
    T = ARM.fk(q)
    pose = T.copy()
    for k, value in enumerate(noise):  # overwrite some entries with arbitrary floats
        pose.flat[k] = value if k % 2 else pose.flat[k]
    valid = bool(np.isfinite(pose).all()) and rigid(pose) and np.allclose(pose[3], [0, 0, 0, 1])
    valid = valid and bool((np.abs(pose[:3, 3]) <= guards.MAX_ABS_LENGTH).all())
    try:
        result = ARM.ik(pose)
    except LynxplanInputError:
        assert not valid or not rigid(pose)
        return
    except KinematicsError:  # a rigid, finite pose out of reach: a documented outcome
        assert valid
        return
    assert valid or np.allclose(pose, T)
    for solution in result.solutions:  # every branch is checked by FK
        assert np.isfinite(solution.q).all()
        assert solution.position_error < IK_POSITION_TOLERANCE
        reached = ARM.fk(solution.q)[:3, 3]  # the reported error is the measured one
        assert math.isclose(
            solution.position_error, float(np.linalg.norm(reached - pose[:3, 3])), abs_tol=1e-12
        )
        assert np.isfinite(solution.orientation_error)


@SETTINGS
@given(ODD_ARRAYS)
def test_ik_batch_odd_arrays(T: np.ndarray) -> None:
    try:
        batch = ARM.ik_batch(T)
    except LynxplanInputError:
        return
    assert T.shape[-2:] == (4, 4) and T.dtype.kind in "biuf"
    assert batch.q.shape[0] == (1 if T.ndim == 2 else T.shape[0])


@SETTINGS
@given(st.lists(st.lists(st.floats(-3.0, 3.0), min_size=5, max_size=5), min_size=1, max_size=8))
def test_ik_batch_round_trip(q: list[list[float]]) -> None:
    T = ARM.fk(np.array(q))
    batch = ARM.ik_batch(T)
    assert (batch.status == 0).all()
    for k in range(len(q)):
        reached = ARM.fk(batch.q[k])
        np.testing.assert_allclose(
            reached[:, :3, 3], np.broadcast_to(T[k, :3, 3], (4, 3)), atol=IK_POSITION_TOLERANCE
        )


@SETTINGS
@given(
    st.lists(ANGLE, min_size=5, max_size=5),
    st.lists(ANGLE, min_size=5, max_size=5),
    st.one_of(st.none(), st.tuples(ANY_FLOAT, ANY_FLOAT)),
)
def test_free_segment(q0: list[float], q1: list[float], times: tuple[float, float] | None):
    try:
        timing = None if times is None else LspbTiming(*times)
        segment = free_segment(q0, q1, timing)
    except LynxplanInputError:
        timing_ok = times is None or (
            all(math.isfinite(t) for t in times)
            and 0 < 2 * times[1] <= times[0] <= guards.MAX_DURATION
        )
        assert not (in_range(q0) and in_range(q1) and timing_ok)
        return
    assert in_range(q0) and in_range(q1)
    t = np.linspace(0.0, segment.duration, 7)
    samples = segment.sample(t)
    assert np.isfinite(samples.q).all() and np.isfinite(samples.qd).all()
    np.testing.assert_allclose(samples.q[0], q0, atol=1e-9)
    np.testing.assert_allclose(samples.q[-1], q1, atol=1e-9)


_LINE_START = np.radians([90.0, 60.0, -60.0, 40.0, 0.0])


@settings(max_examples=25, deadline=None, derandomize=True)
@given(st.lists(st.floats(-0.03, 0.03), min_size=3, max_size=3), st.lists(ANY_FLOAT, max_size=4))
def test_line_segment(offset: list[float], noise: list[float]) -> None:
    T0 = ARM.fk(_LINE_START)
    T1 = T0.copy()
    T1[:3, 3] += offset
    for k, value in enumerate(noise):
        T1[k, 3] = value
    try:
        segment = line_segment(T0, T1, _LINE_START)
    except LynxplanInputError:
        assert noise and not (
            np.isfinite(T1).all()
            and rigid(T1)
            and T1[3, 3] == 1.0
            and (np.abs(T1[:3, 3]) <= guards.MAX_ABS_LENGTH).all()
        )
        return
    except KinematicsError:
        return  # the line leaves the reach: a documented outcome naming where
    samples = segment.sample(np.linspace(0.0, segment.duration, 9))
    assert np.isfinite(samples.q).all()
    np.testing.assert_allclose(ARM.fk(samples.q[-1])[:3, 3], T1[:3, 3], atol=1e-6)


_WORLD = CollisionWorld(ARM, [axis_aligned_box("wall", [0.1, 0.1, -0.1], [0.1, 0.02, 0.3])])


@settings(max_examples=30, deadline=None, derandomize=True)
@given(st.lists(st.lists(ANGLE, min_size=5, max_size=5), min_size=1, max_size=3))
def test_collision_check(q: list[list[float]]) -> None:
    t = np.arange(len(q), dtype=float)
    try:
        report = check_trajectory(_WORLD, q, t)
    except LynxplanInputError:
        assert not in_range(q)
        return
    assert in_range(q)
    assert math.isfinite(report.min_clearance.clearance)


_PARALLEL = ParallelGeometry()


@SETTINGS
@given(
    st.lists(
        st.tuples(
            st.one_of(st.floats(0.0, 0.5), ANY_FLOAT),
            st.one_of(st.floats(0.0, 0.4), ANY_FLOAT),
            ANGLE,
        ),
        min_size=1,
        max_size=6,
    )
)
def test_parallel_ik(poses: list[tuple[float, float, float]]) -> None:
    array = np.array(poses, dtype=float)
    valid = bool(np.isfinite(array).all()) and bool((np.abs(array[:, :2]) <= 1000).all())
    valid = valid and in_range(array[:, 2])
    try:
        result = solve_ik_batch(array)
    except LynxplanInputError:
        assert not valid
        return
    assert valid
    joints = platform_joints(array, _PARALLEL)  # (N, 3, 2)
    for n in range(len(array)):
        for m in range(8):
            theta = result.angles[n, m]
            if np.isnan(theta).any():
                assert not result.reachable[n].all()
                continue
            distal = np.linalg.norm(elbows(theta, _PARALLEL) - joints[n], axis=-1)
            np.testing.assert_allclose(distal, _PARALLEL.distal, atol=1e-9)


@SETTINGS
@given(st.lists(ANGLE, min_size=3, max_size=3))
def test_parallel_fk(theta: list[float]) -> None:
    try:
        result = solve_fk(theta)
    except LynxplanInputError:
        assert not in_range(theta)
        return
    except LynxplanError:  # no assembly mode, or an architecture singularity: documented
        assert in_range(theta)
        return
    assert in_range(theta) and np.isfinite(result.poses).all()
