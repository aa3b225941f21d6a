"""Free motion in joint space."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.exceptions import InputError, NonFiniteInputError, ShapeError
from lynxplan.trajectory import LspbTiming, MotionLimits, free_segment

Q_END = np.array([1.2, 0.9, -0.68, 1.0, 0.0])  # the report's free-motion example


def test_reports_example_all_joints_start_and_stop_together() -> None:
    segment = free_segment(np.zeros(5), Q_END, LspbTiming(3.0, 1.0))
    t = np.linspace(0.0, 3.0, 3001)
    samples = segment.sample(t)
    np.testing.assert_allclose(samples.q[0], 0.0, atol=0)
    np.testing.assert_allclose(samples.q[-1], Q_END, atol=1e-12)
    np.testing.assert_allclose(samples.qd[[0, -1]], 0.0, atol=1e-12)
    # Synchronised: every moving joint has covered the same fraction at every sample.
    fraction = samples.q[:, :4] / Q_END[:4]
    np.testing.assert_allclose(fraction, fraction[:, :1].repeat(4, axis=1), atol=1e-12)
    # Peak speed dA/T with T = tt - ta = 2 s (the report's q2(t) plot peaks at 0.45 rad/s).
    np.testing.assert_allclose(np.abs(samples.qd).max(0), np.abs(Q_END) / 2.0, atol=1e-12)
    assert np.all(samples.branch == -1)
    assert np.all(samples.orientation_residual == 0)


def test_auto_timed_free_motion_meets_the_limits() -> None:
    limits = MotionLimits(acceleration=[8, 4, 8, 8, 8])
    segment = free_segment(np.zeros(5), Q_END, limits=limits)
    samples = segment.sample(np.linspace(0, segment.duration, 4001))
    assert np.all(np.abs(samples.qd).max(0) <= limits.velocity * (1 + 1e-9))
    assert np.all(np.abs(samples.qdd).max(0) <= limits.acceleration * (1 + 1e-9))
    np.testing.assert_allclose(segment.joint_path(np.array([0.5]))[0], Q_END / 2, atol=1e-15)
    tangent, curvature = segment.path_derivatives(np.array([0.1, 0.9]))
    np.testing.assert_allclose(tangent, [Q_END, Q_END], atol=0)
    np.testing.assert_allclose(curvature, 0.0, atol=0)


def test_zero_length_free_motion_is_stationary() -> None:
    segment = free_segment(Q_END, Q_END)
    samples = segment.sample(np.linspace(0, segment.duration, 11))
    np.testing.assert_allclose(samples.q, np.tile(Q_END, (11, 1)), atol=0)
    np.testing.assert_allclose(samples.qd, 0.0, atol=0)


def test_errors() -> None:
    with pytest.raises(ShapeError, match=r"q_end must have shape \(5,\). Got: \(4,\)"):
        free_segment(np.zeros(5), np.zeros(4))
    with pytest.raises(NonFiniteInputError, match="q_start contains NaN"):
        free_segment(np.full(5, np.nan), np.zeros(5))
    with pytest.raises(InputError, match="acceleration limits must be positive"):
        MotionLimits(acceleration=-1.0)
