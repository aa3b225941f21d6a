"""Auto-timing: the shortest synchronised LSPB within velocity and acceleration limits."""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.constants import MIN_SEGMENT_DURATION
from lynxplan.exceptions import InputError, ShapeError
from lynxplan.trajectory.lspb import LspbTiming, unit_lspb
from lynxplan.trajectory.timing import auto_timing_linear, auto_timing_path

REL = 1e-9


def _peaks(delta: np.ndarray, timing: LspbTiming) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(0.0, timing.tt, 20001)
    law = unit_lspb(t, timing)
    return np.abs(np.outer(law.velocity, delta)).max(0), np.abs(
        np.outer(law.acceleration, delta)
    ).max(0)


def _feasible(delta: np.ndarray, tt: float, v: np.ndarray, a: np.ndarray) -> bool:
    """Brute force: is there any ta with an LSPB of total time tt within the limits?"""
    ta = np.linspace(1e-6, tt / 2, 200001)[:, None]
    cruise = tt - ta  # the report's T
    peak_v = np.abs(delta) / cruise  # dA / T
    peak_a = np.abs(delta) / (cruise * ta)  # dA / (2 T tau)
    ok = np.all(peak_v <= v * (1 + 1e-12), axis=1) & np.all(peak_a <= a * (1 + 1e-12), axis=1)
    return bool(ok.any())


@pytest.mark.parametrize(
    ("delta", "v", "a"),
    [
        (np.array([1.2, 0.9, -0.68, 1.0, 0.0]), 3.0, 8.0),  # short move: triangular
        (np.array([2.5, -0.3, 0.1, 0.0, 0.2]), 1.0, 8.0),  # long move: cruise at v
        (np.array([0.5, 1.5, -0.2, 0.3, 0.0]), np.array([3, 0.5, 3, 3, 3]), 2.0),
    ],
)
def test_linear_auto_timing_is_within_limits_and_shortest(delta, v, a) -> None:
    v_arr, a_arr = np.broadcast_to(v, 5), np.broadcast_to(a, 5)
    timing = auto_timing_linear(delta, v, a)
    peak_v, peak_a = _peaks(delta, timing)
    assert np.all(peak_v <= v_arr * (1 + REL))
    assert np.all(peak_a <= a_arr * (1 + 1e-6))
    # One limit is active (otherwise it could go faster) ...
    assert (
        np.isclose(peak_v / v_arr, 1, rtol=1e-6).any()
        or np.isclose(peak_a / a_arr, 1, rtol=1e-3).any()
    )
    # ... and a 1 % shorter LSPB of any blend time violates a limit (brute force).
    assert _feasible(delta, timing.tt * 1.001, v_arr, a_arr)
    assert not _feasible(delta, timing.tt * 0.99, v_arr, a_arr)


def test_path_auto_timing_matches_closed_form_on_a_linear_path() -> None:
    delta = np.array([1.2, 0.9, -0.68, 1.0, 0.0])
    s = np.linspace(0, 1, 401)
    tangent = np.tile(delta, (s.size, 1))
    for v in (3.0, 0.5):
        exact = auto_timing_linear(delta, v, 8.0)
        found = auto_timing_path(s, tangent, np.zeros_like(tangent), v, 8.0)
        assert found.tt == pytest.approx(exact.tt, rel=1e-6)
        assert found.ta == pytest.approx(exact.ta, rel=1e-4)


def test_path_auto_timing_respects_curvature() -> None:
    # q(s) = sin(pi s): curvature adds pi^2 sin(pi s) sd^2 to the acceleration.
    s = np.linspace(0, 1, 2001)
    dq, ddq = np.pi * np.cos(np.pi * s)[:, None], -(np.pi**2) * np.sin(np.pi * s)[:, None]
    timing = auto_timing_path(s, dq, ddq, 10.0, 1.0)
    t = np.linspace(0, timing.tt, 40001)
    law = unit_lspb(t, timing)
    path = np.sin(np.pi * law.position)
    acc = np.gradient(np.gradient(path, t), t)
    assert np.abs(acc[5:-5]).max() <= 1.0 * (1 + 2e-3)
    assert np.abs(acc[5:-5]).max() >= 0.97  # tight, not merely safe
    # Ignoring the curvature term gives a shorter timing that breaks the acceleration limit.
    flat = auto_timing_path(s, dq, np.zeros_like(ddq), 10.0, 1.0)
    assert flat.tt < timing.tt * 0.9
    t_flat = np.linspace(0, flat.tt, 40001)
    path_flat = np.sin(np.pi * unit_lspb(t_flat, flat).position)
    assert np.abs(np.gradient(np.gradient(path_flat, t_flat), t_flat)[5:-5]).max() > 1.1


def test_zero_length_move_gets_the_stationary_timing() -> None:
    timing = auto_timing_linear(np.zeros(5), 3.0, 8.0)
    assert timing.tt == MIN_SEGMENT_DURATION
    s = np.linspace(0, 1, 11)
    zero = np.zeros((11, 5))
    assert auto_timing_path(s, zero, zero, 3.0, 8.0).tt == MIN_SEGMENT_DURATION


def test_invalid_limits_and_shapes_are_errors() -> None:
    with pytest.raises(InputError, match="velocity limits must be positive and finite"):
        auto_timing_linear(np.ones(5), 0.0, 8.0)
    with pytest.raises(InputError, match="acceleration limits must be positive and finite"):
        auto_timing_linear(np.ones(5), 3.0, np.nan)
    with pytest.raises(ShapeError, match=r"delta must have shape \(n,\). Got: \(1, 5\)"):
        auto_timing_linear(np.ones((1, 5)), 3.0, 8.0)
    with pytest.raises(ShapeError, match="dq_ds, d2q_ds2 must have shape"):
        auto_timing_path(np.linspace(0, 1, 5), np.ones((4, 5)), np.ones((4, 5)), 3.0, 8.0)
