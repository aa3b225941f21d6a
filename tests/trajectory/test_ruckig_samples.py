"""The vectorised sampling of ruckig trajectories is ruckig's own ``at_time``, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from ruckig import InputParameter, Ruckig, Trajectory

from lynxplan.trajectory.ruckig_samples import ruckig_states


def _trajectory(rng: np.random.Generator, dofs: int, brake: bool = False) -> Trajectory:
    params = InputParameter(dofs)
    params.current_position = rng.uniform(-2, 2, dofs).tolist()
    params.target_position = rng.uniform(-2, 2, dofs).tolist()
    params.current_velocity = params.current_acceleration = [0.0] * dofs
    params.target_velocity = params.target_acceleration = [0.0] * dofs
    params.max_velocity = (10 ** rng.uniform(-1, 1.5, dofs)).tolist()
    params.max_acceleration = (10 ** rng.uniform(-1, 2, dofs)).tolist()
    params.max_jerk = (10 ** rng.uniform(-1, 3, dofs)).tolist()
    if rng.uniform() < 0.5:  # a longer motion than the fastest (time synchronisation)
        params.minimum_duration = float(rng.uniform(0.0, 20.0))
    if brake:  # a start above the velocity limit: ruckig brakes first
        params.current_velocity = [2.0 * v for v in params.max_velocity]
    trajectory = Trajectory(dofs)
    Ruckig(dofs).calculate(params, trajectory)
    return trajectory


def _times(trajectory: Trajectory, rng: np.random.Generator) -> np.ndarray:
    duration = trajectory.duration
    ends = np.cumsum(trajectory.profiles[0][0].t)  # the phase boundaries themselves
    grid = np.linspace(0.0, duration, int(rng.integers(2, 400)))
    return np.concatenate([grid, ends, [duration, 1.01 * duration, 2.0 * duration]])


@pytest.mark.parametrize("dofs", [1, 5])
def test_samples_are_at_time_bit_for_bit(dofs: int) -> None:
    rng = np.random.default_rng(dofs)
    for _ in range(300):
        trajectory = _trajectory(rng, dofs)
        t = _times(trajectory, rng)
        expected = np.array([trajectory.at_time(float(x)) for x in t]).reshape(len(t), 3, dofs)
        got = ruckig_states(trajectory, t)
        for k in range(3):
            assert np.array_equal(got[k], expected[:, k]), k


def test_a_brake_phase_is_sampled_through_at_time() -> None:
    rng = np.random.default_rng(7)
    trajectory = _trajectory(rng, 2, brake=True)
    assert trajectory.profiles[0][0].brake.duration > 0.0
    t = _times(trajectory, rng)
    expected = np.array([trajectory.at_time(float(x)) for x in t]).reshape(len(t), 3, 2)
    got = ruckig_states(trajectory, t)
    for k in range(3):
        assert np.array_equal(got[k], expected[:, k]), k
