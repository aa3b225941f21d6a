"""The report's LSPB time law: continuity, boundary values, peaks, errors."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from lynxplan.exceptions import TimingError
from lynxplan.trajectory.lspb import (
    LspbTiming,
    lspb,
    lspb_since_start,
    unit_lspb,
    unit_lspb_scalar,
)

ATOL = 1e-9


@st.composite
def timings(draw: st.DrawFn) -> LspbTiming:
    ta = draw(st.floats(0.01, 2.0))
    return LspbTiming(draw(st.floats(2.0 * ta, 10.0)), ta)


@settings(max_examples=60, deadline=None)
@given(timings(), st.floats(-3, 3), st.floats(-3, 3))
def test_position_and_velocity_continuous_at_blend_joints(
    timing: LspbTiming, a0: float, da: float
) -> None:
    tau, big_t = timing.tau, timing.cruise_parameter
    eps = 1e-10
    # Over the 2 eps gap the position may move by up to peak velocity * 2 eps and the velocity by
    # peak acceleration * 2 eps; a jump would be far larger than that.
    peak_velocity = abs(da) / big_t
    peak_acceleration = abs(da) / (2.0 * big_t * tau)
    for joint in (tau, big_t - tau):
        before = lspb(joint - eps, a0, da, timing)
        after = lspb(joint + eps, a0, da, timing)
        np.testing.assert_allclose(
            before.position, after.position, rtol=0, atol=ATOL + 2.0 * eps * peak_velocity
        )
        np.testing.assert_allclose(
            before.velocity, after.velocity, rtol=0, atol=ATOL + 2.0 * eps * peak_acceleration
        )


@settings(max_examples=60, deadline=None)
@given(timings(), st.floats(-3, 3), st.floats(-3, 3))
def test_boundaries_at_rest_and_exact_change(timing: LspbTiming, a0: float, da: float) -> None:
    tau, big_t = timing.tau, timing.cruise_parameter
    start = lspb(-tau, a0, da, timing)
    end = lspb(big_t + tau, a0, da, timing)
    np.testing.assert_allclose([start.position, start.velocity], [a0, 0.0], atol=ATOL)
    np.testing.assert_allclose([end.position, end.velocity], [a0 + da, 0.0], atol=ATOL)


def test_peaks_match_the_report_formulas() -> None:
    timing = LspbTiming(3.0, 1.0)  # the report's free-motion example
    da = np.array([1.2, 0.9, -0.68, 1.0, 0.0])
    big_t, tau = 2.0, 0.5
    t = np.linspace(-tau, big_t + tau, 30001)[:, None]
    state = lspb(t, 0.0, da, timing)
    np.testing.assert_allclose(np.abs(state.velocity).max(axis=0), np.abs(da) / big_t, atol=ATOL)
    np.testing.assert_allclose(
        np.abs(state.acceleration).max(axis=0), np.abs(da) / (2 * big_t * tau), atol=ATOL
    )
    assert timing.peak_rate() == pytest.approx(1 / big_t)
    assert timing.blend_rate() == pytest.approx(1 / (2 * big_t * tau))


def test_velocity_and_acceleration_are_derivatives_of_position() -> None:
    timing = LspbTiming(2.0, 0.5)
    t = np.linspace(0.0, 2.0, 200001)
    state = lspb_since_start(t, 0.3, -1.7, timing)
    # Trapezoidal integration of the velocity reproduces the position (independent of formulas).
    integral = 0.3 + np.concatenate(
        [[0.0], np.cumsum(0.5 * (state.velocity[1:] + state.velocity[:-1]) * np.diff(t))]
    )
    np.testing.assert_allclose(integral, state.position, atol=1e-9)
    accel = np.gradient(state.velocity, t)
    # Away from the acceleration steps at t = 0, ta, tt - ta, tt (since start).
    away = np.min(np.abs(t[:, None] - np.array([0.0, 0.5, 1.5, 2.0])), axis=1) > 1e-4
    np.testing.assert_allclose(accel[away], state.acceleration[away], atol=1e-6)


def test_since_start_is_report_time_shifted_by_tau() -> None:
    timing = LspbTiming(2.0, 0.5)
    t = np.linspace(0.0, 2.0, 101)
    np.testing.assert_allclose(
        lspb_since_start(t, 1.0, 2.0, timing).position,
        lspb(t - 0.25, 1.0, 2.0, timing).position,
        atol=0,
    )
    unit = unit_lspb(t, timing)
    assert unit.position[0] == 0.0
    assert unit.position[-1] == pytest.approx(1.0, abs=ATOL)


def test_held_at_rest_outside_the_segment() -> None:
    state = lspb_since_start(np.array([-1.0, 5.0]), 1.0, 2.0, LspbTiming(2.0, 0.5))
    np.testing.assert_allclose(state.position, [1.0, 3.0], atol=0)
    np.testing.assert_allclose(state.velocity, [0.0, 0.0], atol=0)
    np.testing.assert_allclose(state.acceleration, [0.0, 0.0], atol=0)


def test_zero_length_move_is_a_valid_stationary_segment() -> None:
    state = lspb_since_start(np.linspace(0, 2, 11), 0.7, 0.0, LspbTiming(2.0, 0.5))
    np.testing.assert_allclose(state.position, 0.7, atol=0)
    np.testing.assert_allclose(state.velocity, 0.0, atol=0)


def test_triangular_profile_allowed_at_tt_equal_two_ta() -> None:
    timing = LspbTiming(2.0, 1.0)
    state = lspb_since_start(np.array([0.999999, 1.0, 1.000001]), 0.0, 1.0, timing)
    np.testing.assert_allclose(state.position, 0.5, atol=1e-5)
    np.testing.assert_allclose(state.velocity, 1.0, atol=1e-5)


@pytest.mark.parametrize(
    ("tt", "ta", "match"),
    [
        (1.0, 0.6, "blends overlap: tt must be at least 2 ta = 1.2 s"),
        (0.0, 0.5, "total time tt must be positive"),
        (-2.0, 0.5, "total time tt must be positive"),
        (2.0, 0.0, "blend time ta must be positive"),
        (2.0, -0.1, "blend time ta must be positive"),
        (float("nan"), 0.5, "times must be finite"),
    ],
)
def test_invalid_timings_are_clear_errors(tt: float, ta: float, match: str) -> None:
    with pytest.raises(TimingError, match=match) as info:
        LspbTiming(tt, ta)
    assert info.value.tt == tt or np.isnan(tt)
    assert info.value.ta == ta


@settings(max_examples=60, deadline=None)
@given(timings(), st.floats(-1.0, 12.0))
def test_scalar_law_equals_the_vectorised_law(timing: LspbTiming, t: float) -> None:
    vectorised = unit_lspb(t, timing)
    expected = [float(v) for v in vectorised]
    np.testing.assert_allclose(unit_lspb_scalar(t, timing), expected, atol=ATOL)
