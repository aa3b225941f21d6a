"""Bench section ``suite``: SmallArmBench's goals as figures (``lynxplan bench suite`` prints
the whole table; see :mod:`lynxplan.benchsuite`). The full suite, or 3 problems per family
with ``--quick``."""

from __future__ import annotations

from lynxplan.bench import Figure


def run(quick: bool) -> list[Figure]:
    """Per robot: share solved, share clean, median total time."""
    from lynxplan.benchsuite import report
    from lynxplan.benchsuite.command import QUICK_PER_FAMILY, select
    from lynxplan.benchsuite.families import ROBOT_FRAMES
    from lynxplan.benchsuite.runner import run_serial

    results = run_serial(select(list(ROBOT_FRAMES), QUICK_PER_FAMILY if quick else None))
    figures = []
    for s in (s for s in report.summarize(results) if s.family == "all"):
        solved = 100.0 * s.in_time / s.problems
        clean = 100.0 * s.clean / max(s.solved, 1)
        median = s.total.median * 1e3
        figures += [
            Figure("suite", f"{s.robot}: solved within 1 s", solved, "%", ">= 99", solved >= 99),
            Figure("suite", f"{s.robot}: clean (dense exact check)", clean, "%", ">= 100",
                   clean >= 100),
            Figure("suite", f"{s.robot}: median total (plan+simplify+verify)", median, "ms",
                   "<= 2", median <= 2),
        ]  # fmt: skip
    return figures
