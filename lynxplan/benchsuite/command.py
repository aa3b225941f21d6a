"""``lynxplan bench suite``: run SmallArmBench and print its table, unsolved problems and goals.

Options (added to ``lynxplan bench`` by :func:`add_arguments`): ``--suite-robot`` (repeatable;
default al5, so101, ur5), ``--per-family N`` (the first N problems of each family: a slice;
``--quick``: 3), ``--dask-local N`` / ``--dask-scheduler ADDRESS`` (fan-out),
``--peers`` (OMPL and pyroboplan on the same problems), ``--out DIR`` (``results.json`` and
``cdf_total_time.png``; default ``out/smallarmbench``).
Exit 0: every goal met; 1: a goal missed (the table says which); 2: bad input.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from pathlib import Path
from typing import Any

from lynxplan.benchsuite.families import FAMILIES, ROBOT_FRAMES
from lynxplan.benchsuite.problem import Problem
from lynxplan.benchsuite.runner import ProblemResult
from lynxplan.exceptions import InputError

#: Problems per family of ``--quick``.
QUICK_PER_FAMILY = 3


def add_arguments(parser: Any) -> None:
    """The ``bench suite`` options, on the ``bench`` parser."""
    group = parser.add_argument_group("bench suite (SmallArmBench)")
    group.add_argument("--suite-robot", action="append", choices=sorted(ROBOT_FRAMES),
                       help="robots of the suite to run (default: all)")  # fmt: skip
    group.add_argument("--per-family", type=int, metavar="N",
                       help="the first N problems of each family only (a slice)")  # fmt: skip
    group.add_argument("--dask-local", type=int, metavar="N",
                       help="run on a local Dask cluster of N worker processes")  # fmt: skip
    group.add_argument("--dask-scheduler", metavar="ADDRESS",
                       help="run on the Dask scheduler at ADDRESS (tcp://host:8786)")  # fmt: skip
    group.add_argument("--peers", action="store_true",
                       help="also OMPL and pyroboplan on the same problems")  # fmt: skip
    group.add_argument("--out", type=Path, default=Path("out/smallarmbench"),
                       help="folder of results.json and the CDF plot")  # fmt: skip


def select(robots: list[str], per_family: int | None) -> list[Problem]:
    """The shipped problems of ``robots``, the first ``per_family`` of each family."""
    from lynxplan.benchsuite.storage import load_shipped

    if per_family is not None and per_family < 1:
        raise InputError(f"--per-family must be at least 1. Got: {per_family}")
    problems = [
        problem
        for robot in robots
        for problem in load_shipped(robot)
        if per_family is None or problem.index < per_family
    ]
    return sorted(problems, key=lambda p: (p.robot, FAMILIES.index(p.family), p.index))


def run_suite(args: argparse.Namespace) -> int:
    """Run the suite as ``args`` say; print the table; write results.json and the plot."""
    from lynxplan.benchsuite import report
    from lynxplan.progress import progress_bar

    if args.dask_local is not None and args.dask_scheduler is not None:
        raise InputError("give one of --dask-local N and --dask-scheduler ADDRESS, not both")
    quick = QUICK_PER_FAMILY if args.quick else None
    per_family = args.per_family if args.per_family is not None else quick
    problems = select(args.suite_robot or list(ROBOT_FRAMES), per_family)
    with progress_bar(f"SmallArmBench: {len(problems)} problems") as progress:
        if args.dask_local is not None or args.dask_scheduler is not None:
            from lynxplan.benchsuite.distributed import run_on_dask

            results = run_on_dask(problems, scheduler=args.dask_scheduler,
                                  local_workers=args.dask_local, progress=progress)  # fmt: skip
        else:
            from lynxplan.benchsuite.runner import run_serial

            results = run_serial(problems, progress=progress)
    summaries = report.summarize(results)
    print(report.table(summaries))
    for line in report.cpu_lines(results):
        print(line)
    for line in report.unsolved(results):
        print(f"unsolved: {line}")
    peers: dict[str, Any] = {}
    if args.peers:
        from lynxplan.benchsuite.peers import compare_peers

        peers = compare_peers(problems, results)
        for line in peers["lines"]:
            print(line)
    plot = report.cdf_plot(results, args.out / "cdf_total_time.png", peers.get("rows", ()))
    _write_results(args.out / "results.json", results, peers)
    print(f"outputs in {args.out}/: results.json, {plot.name}")
    misses = report.goal_misses(summaries) + list(peers.get("misses", []))
    for line in misses:
        print(f"goal missed: {line}", file=sys.stderr)
    return 1 if misses else 0


def _write_results(path: Path, results: list[ProblemResult], peers: dict[str, Any]) -> None:
    rows = [{**dataclasses.asdict(r), "total_time": r.total_time} for r in results]
    path.parent.mkdir(parents=True, exist_ok=True)
    body = {"results": rows, "peers": {k: v for k, v in peers.items() if k != "lines"}}
    path.write_text(json.dumps(body, indent=1, default=float), encoding="utf-8")
