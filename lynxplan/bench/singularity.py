"""Bench section ``singularity``: resolved-rate steps per strategy, numba kernel vs Python.

Each strategy runs 10,000 steps (10 s at dt = 1 ms, through the singular crossing) of the
shipped ``scenarios/singularity_line.yaml`` problem in the numba loop (closed-form FK, Jacobian,
its derivative for TR, a 4x4 or 5x5 solve per step), and the same algorithm step by step in plain
Python/numpy with Pinocchio's FK, Jacobian and Jacobian time variation
(:func:`lynxplan.singularity.run_reference`).
"""

from __future__ import annotations

from functools import partial
from typing import cast

from lynxplan.bench import Figure, median_seconds
from lynxplan.shipped import scenario_path

#: The issue's target for one resolved-rate step, in [us].
TARGET_US_PER_STEP = 30.0


def run(quick: bool) -> list[Figure]:
    """Measure µs per step for each strategy; ``quick`` shortens the Python reference runs."""
    from lynxplan.arm import load_arm
    from lynxplan.scenarios import load_scenario
    from lynxplan.scenarios.singularity import Scenario, build_problem
    from lynxplan.singularity import (
        STRATEGY_NAMES,
        Strategy,
        run_reference,
        run_resolved_rate,
    )

    scenario = load_scenario(scenario_path("singularity_line.yaml")).scenario
    problem = build_problem(cast(Scenario, scenario))
    arm = load_arm()
    steps = 10_000
    reference_steps = 1_000 if quick else steps
    repeats = 3 if quick else 7
    figures = []
    for strategy in Strategy:
        name = STRATEGY_NAMES[strategy]
        fast = median_seconds(
            partial(run_resolved_rate, problem, strategy, max_steps=steps), repeats=repeats
        )
        slow = median_seconds(
            partial(run_reference, problem, strategy, arm, max_steps=reference_steps), repeats=1
        )
        fast_us = fast / steps * 1e6
        slow_us = slow / reference_steps * 1e6
        figures += [
            Figure(
                "singularity",
                f"resolved rate {name}, numba kernel ({steps:,} steps)",
                fast_us,
                "us/step",
                f"<= {TARGET_US_PER_STEP:g}",
                fast_us <= TARGET_US_PER_STEP,
            ),
            Figure(
                "singularity",
                f"resolved rate {name}, Python/numpy + Pinocchio ({reference_steps:,} steps)",
                slow_us,
                "us/step",
            ),
            Figure("singularity", f"resolved rate {name}, speed-up", slow_us / fast_us, "x"),
        ]
    return figures
