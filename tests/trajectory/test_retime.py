"""ruckig and toppra comparisons: results checked on their sampled output, not trusted."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lynxplan.arm.kinematics import forward_kinematics
from lynxplan.exceptions import RetimingError
from lynxplan.scenarios import load_scenario
from lynxplan.trajectory import (
    LspbTiming,
    MotionLimits,
    free_segment,
    line_segment,
    ok_task_plan,
    retime,
)
from lynxplan.trajectory.ok_task import ok_task_configurations
from lynxplan.trajectory.retime import (
    Profile,
    compare_plan,
    compare_segment,
    profile_stats,
    ruckig_profile,
    toppra_profile,
)

LIMITS = MotionLimits()
SLACK = 1 + 1e-6
#: toppra's sampled output must be within the limits (no overshoot allowed, rounding only).
TOPPRA_SLACK = 1 + 1e-9
SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
Q = ok_task_configurations()
HOME_MOVE = free_segment(Q[12], Q[13], LspbTiming(2.0, 0.5))  # I3 -> home, the largest move


def test_ruckig_is_within_velocity_acceleration_and_jerk_limits() -> None:
    profile = ruckig_profile(HOME_MOVE.q_start, HOME_MOVE.q_end, LIMITS, 1000.0)
    assert np.all(np.abs(profile.qd).max(0) <= LIMITS.velocity * SLACK)
    assert np.all(np.abs(profile.qdd).max(0) <= LIMITS.acceleration * SLACK)
    # Sampled jerk (finite differences of a piecewise-linear acceleration) within the limit.
    assert np.all(np.abs(profile.jerk).max(0) <= LIMITS.jerk * 1.001)
    np.testing.assert_allclose(profile.q[[0, -1]], [Q[12], Q[13]], atol=1e-9)
    np.testing.assert_allclose(profile.qd[[0, -1]], 0.0, atol=1e-9)
    # Velocities are the derivative of the positions (checked by differences).
    np.testing.assert_allclose(
        np.gradient(profile.q, profile.t, axis=0)[1:-1], profile.qd[1:-1], atol=1e-4
    )


def test_ruckig_forced_to_the_lspb_duration() -> None:
    profile = ruckig_profile(HOME_MOVE.q_start, HOME_MOVE.q_end, LIMITS, 1000.0, 2.0)
    assert profile.t[-1] == pytest.approx(2.0, abs=1e-9)
    np.testing.assert_allclose(profile.q[-1], Q[13], atol=1e-9)
    assert profile_stats("ruckig_lspb_duration", profile, LIMITS).duration_matched is True


def test_ruckig_cannot_meet_a_duration_below_its_jerk_limited_minimum() -> None:
    fastest = ruckig_profile(HOME_MOVE.q_start, HOME_MOVE.q_end, LIMITS, 1000.0)
    assert profile_stats("ruckig", fastest, LIMITS).duration_matched is None  # not forced
    asked = 0.5 * fastest.t[-1]
    profile = ruckig_profile(HOME_MOVE.q_start, HOME_MOVE.q_end, LIMITS, 1000.0, asked)
    stats = profile_stats("ruckig_lspb_duration", profile, LIMITS)
    assert stats.duration == pytest.approx(fastest.t[-1], abs=1e-9)  # its minimum, not asked
    assert stats.duration_matched is False
    assert stats.violations == ()
    # A segment whose LSPB is shorter than ruckig's minimum reports it in the comparison.
    short = free_segment(Q[12], Q[13], LspbTiming(asked, asked / 4))
    compared = compare_segment(short, LIMITS, 500.0).stats["ruckig_lspb_duration"]
    assert compared.duration_matched is False
    assert compared.duration > asked


def test_free_segment_comparison_orders_the_durations() -> None:
    comparison = compare_segment(HOME_MOVE, LIMITS, 1000.0)
    stats = comparison.stats
    assert set(stats) == {"lspb", "lspb_auto", "ruckig", "ruckig_lspb_duration", "toppra"}
    # Without a jerk limit the synchronised trapezoid is time-optimal on a straight joint path:
    # toppra finds the same duration; ruckig's jerk limit makes it longer.
    assert stats["toppra"].duration == pytest.approx(stats["lspb_auto"].duration, rel=0.02)
    assert stats["ruckig"].duration >= stats["lspb_auto"].duration
    assert stats["lspb"].duration == 2.0
    for name in ("lspb", "lspb_auto", "ruckig", "ruckig_lspb_duration", "toppra"):
        assert stats[name].violations == (), name
    assert stats["lspb_auto"].velocity_ratio == pytest.approx(1.0, rel=1e-6) or stats[
        "lspb_auto"
    ].acceleration_ratio == pytest.approx(1.0, rel=1e-6)


def test_toppra_follows_the_same_line_within_the_limits() -> None:
    line = line_segment(
        forward_kinematics(Q[0]), forward_kinematics(Q[1]), Q[0], LspbTiming(2, 0.5)
    )
    profile = toppra_profile(line, LIMITS, 1000.0)
    T0, T1 = forward_kinematics(Q[0])[:3, 3], forward_kinematics(Q[1])[:3, 3]
    u = (T1 - T0) / np.linalg.norm(T1 - T0)
    tool = forward_kinematics(profile.q)[:, :3, 3] - T0
    assert np.linalg.norm(np.cross(tool, u), axis=1).max() < 1e-6  # spline through the IK path
    stats = profile_stats("toppra", profile, LIMITS)
    assert stats.velocity_ratio <= TOPPRA_SLACK
    assert stats.acceleration_ratio <= TOPPRA_SLACK
    assert stats.violations == ()
    assert stats.duration < 2.0


def _toppra_ratios(segments, limits, rate: float) -> list[tuple[float, float, float]]:
    """(velocity ratio, acceleration ratio, time scale) of toppra on each segment."""
    out = []
    for segment in segments:
        stats = profile_stats("toppra", toppra_profile(segment, limits, rate), limits)
        out.append((stats.velocity_ratio, stats.acceleration_ratio, stats.time_scale))
    return out


def test_toppra_is_within_the_limits_on_the_ok_task_and_shipped_scenarios() -> None:
    plan = ok_task_plan()
    ratios = _toppra_ratios(plan.segments, plan.limits, 1000.0)
    assert {s.kind for s in plan.segments} == {"free", "line"}
    for name in ("free_motion.yaml", "straight_line.yaml"):
        loaded = load_scenario(SCENARIOS / name)
        scenario = loaded.scenario
        built = loaded.kind.build(scenario)  # type: ignore[attr-defined]
        ratios += _toppra_ratios(built.segments, built.limits, scenario.sample_rate)  # type: ignore[attr-defined]
    peaks = np.array(ratios)
    assert np.all(peaks[:, :2] <= TOPPRA_SLACK), peaks
    # Near time-optimal: on every segment one limit is within 2 % of active.
    assert np.all(peaks[:, :2].max(axis=1) >= retime.TOPPRA_LIMIT_SAFETY * (1 - 0.01))


def test_toppra_overshoot_is_removed_by_a_uniform_slow_down(monkeypatch) -> None:
    line = line_segment(
        forward_kinematics(Q[0]), forward_kinematics(Q[1]), Q[0], LspbTiming(2, 0.5)
    )
    plain = toppra_profile(line, LIMITS, 1000.0)
    # toppra given limits 30 % too high: its raw output overshoots and must be slowed down.
    monkeypatch.setattr(retime, "TOPPRA_LIMIT_SAFETY", 1.3)
    profile = toppra_profile(line, LIMITS, 1000.0)
    stats = profile_stats("toppra", profile, LIMITS)
    assert stats.time_scale > 1.05
    assert stats.velocity_ratio <= TOPPRA_SLACK
    assert stats.acceleration_ratio <= TOPPRA_SLACK
    assert stats.violations == ()
    # Acceleration-limited: slowing by k divides the acceleration by k^2, so the raw peak was
    # about k^2 times the limit (the sampled active limit is met again after the slow-down).
    assert stats.acceleration_ratio == pytest.approx(1.0, abs=1e-3)
    np.testing.assert_allclose(profile.q[[0, -1]], plain.q[[0, -1]], atol=1e-9)
    np.testing.assert_allclose(profile.qd[[0, -1]], 0.0, atol=1e-9)
    # The slowed profile is still consistent: positions are the integral of the velocities
    # (trapezoids; the velocity is piecewise linear).
    steps = 0.5 * (profile.qd[1:] + profile.qd[:-1]) * np.diff(profile.t)[:, None]
    integral = profile.q[0] + np.vstack([np.zeros((1, 5)), np.cumsum(steps, axis=0)])
    np.testing.assert_allclose(integral, profile.q, atol=1e-5)
    assert plain.time_scale == 1.0


def test_profile_stats_report_violations() -> None:
    t = np.linspace(0, 1, 11)
    q = np.zeros((11, 5))
    qd = np.zeros((11, 5))
    qd[5, 1] = 3.3  # 10 % over the 3 rad/s limit
    q[:, 4] = -0.01  # below the q5 >= 0 limit
    stats = profile_stats("lspb", Profile(t, q, qd, np.zeros((11, 5))), LIMITS)
    assert stats.velocity_ratio == pytest.approx(1.1)
    assert "q2 velocity 3.3000 > 3 rad/s" in stats.violations
    assert any(v.startswith("q5 position") for v in stats.violations)


def test_whole_plan_totals() -> None:
    comparison = compare_plan(ok_task_plan(), 200.0)
    assert comparison.total_duration["lspb"] == pytest.approx(26.0)
    assert comparison.segments_covered == {
        "lspb": 13, "lspb_auto": 13, "ruckig": 6, "ruckig_lspb_duration": 6, "toppra": 13
    }  # fmt: skip
    assert comparison.violation_count["lspb"] == 0
    assert comparison.total_duration["lspb_auto"] < 26.0
    per_segment = sum(c.stats["toppra"].duration for c in comparison.segments)
    assert comparison.total_duration["toppra"] == pytest.approx(per_segment)


def test_ruckig_failure_is_a_retiming_error() -> None:
    with pytest.raises(RetimingError, match=r"ruckig found no trajectory: .*target position"):
        ruckig_profile(np.zeros(5), np.array([np.nan, 0, 0, 0, 0]), LIMITS, 100.0)
