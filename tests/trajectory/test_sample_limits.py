"""The samples a time law implies, bounded before anything is allocated (issue 35): the pure
lower bound of a motion's duration, the sample count, and the checks in front of the samplers."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lynxplan import guards
from lynxplan.exceptions import ResourceLimitError, ShapeError
from lynxplan.trajectory.retime import sample_times
from lynxplan.trajectory.timing import (
    auto_timing_linear,
    min_rest_to_rest_duration,
    samples_implied,
)


def test_min_duration_is_the_slowest_joint_bang_coast_bang() -> None:
    # joint 0: 1 rad at v = 1, a = 4 reaches v (needs 0.25 rad): 1/1 + 1/4 = 1.25 s
    # joint 1: 0.1 rad at v = 1, a = 4 does not (triangle): 2 sqrt(0.1 / 4) = 0.316 s
    # joint 2: 2 rad at v = 4, a = 1 does not reach v (needs 16 rad): 2 sqrt(2) = 2.83 s
    delta = np.array([1.0, -0.1, 2.0, 0.0, 0.0])
    velocity = np.array([1.0, 1.0, 4.0, 1.0, 1.0])
    acceleration = np.array([4.0, 4.0, 1.0, 1.0, 1.0])
    bound = min_rest_to_rest_duration(delta, velocity, acceleration)
    assert bound == pytest.approx(2 * math.sqrt(2.0), rel=1e-15)


@pytest.mark.parametrize("seed", range(5))
def test_min_duration_never_exceeds_the_synchronised_lspb(seed: int) -> None:
    rng = np.random.default_rng(seed)
    delta = rng.uniform(-2, 2, 5)
    velocity, acceleration = rng.uniform(0.1, 5, 5), rng.uniform(0.1, 20, 5)
    bound = min_rest_to_rest_duration(delta, velocity, acceleration)
    assert 0 < bound <= auto_timing_linear(delta, velocity, acceleration).tt * (1 + 1e-12)


def test_min_duration_overflows_to_infinity_without_raising() -> None:
    # 10 rad at 1e-308 rad/s: 1e309 s, beyond the float range
    assert min_rest_to_rest_duration(np.full(5, 10.0), 1e-308, 1e-308) == math.inf
    assert min_rest_to_rest_duration(np.full(5, 0.1), 1.0, 1e-300) == pytest.approx(
        2 * math.sqrt(0.1 / 1e-300), rel=1e-12
    )
    assert min_rest_to_rest_duration(np.zeros(5), 1.0, 1.0) == 0.0


def test_samples_implied() -> None:
    assert samples_implied(1.0, 100.0) == 102.0
    assert samples_implied(1e300, 1e10) == math.inf
    assert samples_implied(math.inf, 1.0) == math.inf


def test_sample_times_refuses_before_allocating() -> None:
    """5e10 samples (the issue's 125-byte request) is a ResourceLimitError, not a MemoryError
    or numpy's 'Maximum allowed size exceeded'."""
    with pytest.raises(ResourceLimitError, match="trajectory samples"):
        sample_times(5e6, 1e4)
    with pytest.raises(ResourceLimitError):
        sample_times(6.3e149, 100.0)
    with guards.raised_limits(max_samples=1000), pytest.raises(ResourceLimitError):
        sample_times(10.0, 100.0)
    assert len(sample_times(1.0, 100.0)) == 101


def test_planner_option_of_the_wrong_length_is_a_shape_error() -> None:
    from lynxplan.arm.model import load_arm
    from lynxplan.planning import PlannerOptions, plan

    start, goal = np.zeros(5), np.array([0.5, 0.5, -0.5, 0.5, 0.5])
    for name, value in (("max_jerk", (1.0, 2.0)), ("max_acceleration", (1.0, 2.0, 3.0))):
        options = PlannerOptions(**{name: value})  # type: ignore[arg-type]
        with pytest.raises(ShapeError, match=f"planner option {name}"):
            plan(load_arm(), [], start, goal, options=options)
