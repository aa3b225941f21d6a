"""SmallArmBench figures: per robot and family, a table, the unsolved problems, a CDF plot."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.benchsuite.runner import ProblemResult

#: The issue's goals: share solved within the time limit, share clean, median total [s].
GOAL_SOLVED, GOAL_CLEAN, GOAL_MEDIAN_TOTAL = 0.99, 1.0, 2e-3


@dataclass(frozen=True)
class Spread:
    """Median, 95th percentile and maximum of a quantity (NaN when there is no value)."""

    median: float
    p95: float
    max: float

    @classmethod
    def of(cls, values: Sequence[float]) -> Spread:
        finite = np.array([v for v in values if math.isfinite(v)])
        if finite.size == 0:
            return cls(math.nan, math.nan, math.nan)
        return cls(float(np.median(finite)), float(np.percentile(finite, 95)), float(finite.max()))


@dataclass(frozen=True)
class GroupSummary:
    """The figures of one robot and family (``family`` "all": the robot's whole suite).

    Attributes:
        problems: How many problems; ``solved``: how many got a path within the node budget;
            ``in_time``: how many of those within the time limit (``runner.TIME_LIMIT``, the
            goal's); ``clean``: how many of those solved passed the dense check.
        plan, simplify, total: Times in [s]; ``raw_length``, ``length``: joint-space path
            lengths before and after simplification, in [rad].
    """

    robot: str
    family: str
    problems: int
    solved: int
    in_time: int
    clean: int
    plan: Spread
    simplify: Spread
    total: Spread
    raw_length: Spread
    length: Spread


def summarize(results: Sequence[ProblemResult]) -> list[GroupSummary]:
    """One summary per robot and family, then one per robot (family "all")."""
    groups: dict[tuple[str, str], list[ProblemResult]] = {}
    for result in results:
        groups.setdefault((result.robot, result.family), []).append(result)
        groups.setdefault((result.robot, "all"), []).append(result)
    ordered = sorted(groups, key=lambda k: (k[0], k[1] == "all"))
    return [_summary(robot, family, groups[(robot, family)]) for robot, family in ordered]


def _summary(robot: str, family: str, results: list[ProblemResult]) -> GroupSummary:
    solved = [r for r in results if r.solved]
    return GroupSummary(
        robot,
        family,
        len(results),
        len(solved),
        sum(r.solved_in_time for r in solved),
        sum(r.clean for r in solved),
        Spread.of([r.plan_time for r in solved]),
        Spread.of([r.simplify_time for r in solved]),
        Spread.of([r.total_time for r in solved]),
        Spread.of([r.raw_length for r in solved]),
        Spread.of([r.length for r in solved]),
    )


def _ms(spread: Spread) -> str:
    return f"{spread.median * 1e3:7.2f} {spread.p95 * 1e3:7.2f} {spread.max * 1e3:8.2f}"


def table(summaries: Sequence[GroupSummary]) -> str:
    """The table: one line per robot and family, times in [ms] (median p95 max), lengths in
    [rad] (median before -> after simplification)."""
    head = (
        f"{'robot':<6} {'family':<12} {'solved':>8} {'<= 1 s':>6} {'clean':>6} |"
        f" {'plan ms: med p95 max':>24} |"
        f" {'simplify ms: med p95 max':>24} | {'total ms: med p95 max':>24} | length rad"
    )
    lines = [head, "-" * len(head)]
    lines += [
        f"{s.robot:<6} {s.family:<12} {s.solved:>3}/{s.problems:<4} {s.in_time:>6} {s.clean:>6} | "
        f"{_ms(s.plan)} | {_ms(s.simplify)} | {_ms(s.total)} | "
        f"{s.raw_length.median:5.2f} -> {s.length.median:5.2f}"
        for s in summaries
    ]
    return "\n".join(lines)


def cpu_lines(results: Sequence[ProblemResult]) -> list[str]:
    """Per robot, the thread CPU time of the whole ``solve`` call (median, p95): the table's
    wall times also hold the waits for a core of a loaded machine, this does not."""
    lines = []
    for robot in sorted({r.robot for r in results}):
        cpu = Spread.of([r.solve_cpu for r in results if r.robot == robot and r.solved])
        lines.append(f"{robot}: whole solve() call, thread CPU time: median "
                     f"{cpu.median * 1e3:.2f} ms, p95 {cpu.p95 * 1e3:.2f} ms")  # fmt: skip
    return lines


def unsolved(results: Sequence[ProblemResult]) -> list[str]:
    """One line per unsolved problem (by robot and family): its name and the reason."""
    return [f"{r.robot} {r.family}: {r.name}: {r.reason}" for r in results if not r.solved]


def goal_misses(summaries: Sequence[GroupSummary]) -> list[str]:
    """The issue's goals (solved, clean, median total) each robot misses, one line each."""
    misses = []
    for s in (s for s in summaries if s.family == "all"):
        if s.in_time < GOAL_SOLVED * s.problems:
            misses.append(f"{s.robot}: {s.in_time}/{s.problems} solved within 1 s (goal >= 99 %)")
        if s.clean < GOAL_CLEAN * s.solved:
            misses.append(f"{s.robot}: {s.clean}/{s.solved} clean (goal 100 %)")
        if not s.total.median <= GOAL_MEDIAN_TOTAL:
            misses.append(f"{s.robot}: median total {s.total.median * 1e3:.2f} ms (goal <= 2 ms)")
    return misses


def cdf_plot(
    results: Sequence[ProblemResult],
    path: Path,
    peer_rows: Sequence[dict[str, Any]] = (),
) -> Path:
    """A PNG of the CDF of the total time per robot, log time axis: lynxplan's (plan + simplify
    + verify, solid) and, from ``peer_rows`` (:func:`lynxplan.benchsuite.peers.compare_peers`),
    each peer's (plan + simplify, dashed: OMPL, dotted: pyroboplan) on the same problems. An
    unsolved problem counts as never done (the curve stays below 1)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, axes = plt.subplots(figsize=(8, 5))
    styles = {"ompl": "--", "pyroboplan": ":"}
    for k, robot in enumerate(sorted({r.robot for r in results})):
        colour = f"C{k}"
        mine = [r for r in results if r.robot == robot]
        times = np.sort([r.total_time * 1e3 for r in mine if r.solved])
        share = np.arange(1, len(times) + 1) / len(mine)
        axes.step(times, share, where="post", color=colour,
                  label=f"{robot} lynxplan ({len(times)}/{len(mine)})")  # fmt: skip
        for peer, style in styles.items():
            rows = [r for r in peer_rows
                    if r["peer"] == peer and r["problem"].startswith(f"{robot}_")]  # fmt: skip
            if not rows:
                continue
            done = np.sort([(r["plan_time"] + r["simplify_time"]) * 1e3
                            for r in rows if r["solved"]])  # fmt: skip
            label = f"{robot} {peer} ({len(done)}/{len(rows)})"
            axes.step(done, np.arange(1, len(done) + 1) / len(rows), where="post", color=colour,
                      linestyle=style, label=label)  # fmt: skip
    axes.axvline(GOAL_MEDIAN_TOTAL * 1e3, color="grey", linestyle="-.", label="2 ms")
    axes.set_xscale("log")
    axes.set_xlabel("total time per problem [ms] (lynxplan: plan + simplify + verify)")
    axes.set_ylabel("share of problems solved")
    axes.set_ylim(0, 1.02)
    axes.set_title("SmallArmBench: total planning time, CDF per robot and planner")
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(loc="upper left", fontsize="small")
    figure.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path
