"""``lynxplan bench``: performance figures measured side by side in one run.

Each section module exposes ``run(quick: bool) -> list[Figure]``. Figures are medians over
repeats (the machine is shared and noisy); ratios between figures of one run are what to quote.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable
from typing import NamedTuple

#: Section name -> module with ``run(quick) -> list[Figure]``.
SECTIONS: dict[str, str] = {
    "arm": "lynxplan.bench.arm",
    "singularity": "lynxplan.bench.singularity",
    "parallel": "lynxplan.bench.parallel",
    "trajectory": "lynxplan.bench.trajectory",
    "collision": "lynxplan.bench.collision",
    "task": "lynxplan.bench.task",
    "cold": "lynxplan.bench.cold",
    "plan": "lynxplan.bench.plan",
    "serve": "lynxplan.bench.serve",
    "robots": "lynxplan.bench.robots",
}


class Figure(NamedTuple):
    """One measured figure."""

    section: str
    """Bench section, e.g. ``"arm"``."""
    name: str
    """What was measured."""
    value: float
    """The measured value (median over repeats)."""
    unit: str
    """Unit of ``value``, e.g. ``"poses/s"``, ``"us"``, ``"x"`` for ratios."""
    target: str = ""
    """The target from the issue, e.g. ``">= 3e6"``, or empty."""
    met: bool | None = None
    """Whether the target is met, or None when there is no target."""


def median_seconds(
    fn: Callable[[], object],
    *,
    repeats: int = 7,
    number: int = 1,
    clock: Callable[[], float] = time.thread_time,
) -> float:
    """Median time of one call of ``fn``, in [s], over ``repeats`` batches of ``number`` calls.

    The default clock is the calling thread's CPU time: every kernel measured here runs on that
    one thread, so the figure is one core's throughput even when other processes share the
    machine (wall time would count the time the thread waits for a core). Pass
    ``clock=time.perf_counter`` for wall time.
    """
    fn()  # warm-up: JIT compilation, caches
    samples = []
    for _ in range(repeats):
        start = clock()
        for _ in range(number):
            fn()
        samples.append((clock() - start) / number)
    samples.sort()
    return samples[len(samples) // 2]


def run_sections(names: list[str] | None = None, *, quick: bool = False) -> list[Figure]:
    """Run the named sections (all by default) and collect their figures."""
    figures: list[Figure] = []
    for name in names or list(SECTIONS):
        module = importlib.import_module(SECTIONS[name])
        figures.extend(module.run(quick))
    return figures
