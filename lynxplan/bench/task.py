"""Bench section ``task``: ``lynxplan run scenarios/ok_task.yaml --quick`` timed in-process.

The whole run is load + validate (robot, waypoints, plan), sampling at 1 kHz, the joint-limit
check, the collision check (every link, both walls, every sample and between samples), the
ruckig/toppra comparison and report.json. Times are medians of warm runs (numba kernels compiled,
models loaded once per process); each stage's median comes from the run's own stage timer.
"""

from __future__ import annotations

import tempfile
import time
from pathlib import Path
from typing import Any

from lynxplan.bench import Figure, median_seconds
from lynxplan.shipped import scenario_path

#: Target of the issue for the whole run without HTML/plots, in [s].
TARGET_SECONDS = 3.0


def ok_task_path() -> Path:
    """The shipped scenarios/ok_task.yaml (package data, or the checkout's file)."""
    return scenario_path("ok_task.yaml")


def run(quick: bool) -> list[Figure]:
    """Median wall times of the OK task run and of its stages."""
    from lynxplan.scenarios import load_scenario, run_scenario
    from lynxplan.task.run import execute
    from lynxplan.task.setup import resolve

    path = ok_task_path()
    repeats = 3 if quick else 5
    with tempfile.TemporaryDirectory(prefix="lynxplan-bench-") as folder:
        out = Path(folder) / "out"
        whole = median_seconds(
            lambda: run_scenario(path, out, quick=True, force=True), repeats=repeats
        )
        load = median_seconds(lambda: load_scenario(path), repeats=repeats)
        scenario: Any = load_scenario(path).scenario
        setup = resolve(scenario)
        runs = [execute(scenario, setup).stage_seconds for _ in range(repeats)]
        stages = {name: sorted(r[name] for r in runs)[len(runs) // 2] for name in runs[0]}
        figures = [
            Figure(
                "task",
                "OK task: whole run --quick (plan, checks, comparison, report)",
                whole,
                "s",
                f"<= {TARGET_SECONDS:g}",
                whole <= TARGET_SECONDS,
            ),
            Figure("task", "  load + validate (schema only)", load * 1e3, "ms"),
        ]
        figures += [
            Figure("task", f"  stage: {name}", seconds * 1e3, "ms")
            for name, seconds in stages.items()
        ]
        if not quick:
            start = time.perf_counter()
            run_scenario(path, Path(folder) / "full", quick=False)
            figures.append(
                Figure(
                    "task",
                    "OK task: full run with plots and HTML (one run)",
                    time.perf_counter() - start,
                    "s",
                )
            )
    return figures
