"""``lynxplan bench``: print the performance figures of every section.

Exit 0: every figure with a target met it (peers that are not installed are listed, no failure);
1: a figure missed its target; 3: a section, or an installed peer, could not run (the error is
printed with the section; the other sections still run).
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from lynxplan.bench import (
    MISSED,
    NOT_RUN,
    PEER_NOT_INSTALLED,
    SECTIONS,
    Figure,
    run_sections,
    verdict,
)
from lynxplan.commands._output import print_json
from lynxplan.exceptions import InputError

#: Exit codes: a figure missed its target (the measurement completed, like a failed expect:); a
#: section or an installed peer could not run (an error: please report it).
EXIT_MISSED, EXIT_NOT_RUN = 1, 3


def register(subparsers: Any) -> None:
    """Add the ``bench`` sub-command."""
    parser = subparsers.add_parser(
        "bench",
        help="measure performance figures side by side",
        description="Measure the figures of each section and judge those with a target. Exit 0: "
        "every target met (optional peers that are not installed are listed); 1: a figure missed "
        "its target; 3: a section or an installed peer could not run.",
    )
    parser.add_argument(
        "--section", action="append", choices=sorted(SECTIONS), help="run only these sections"
    )
    parser.add_argument(
        "--cold",
        action="store_true",
        help="fresh-process start-up times only (section cold): fk, run ok_task --quick, "
        "import pinocchio; and first runs from an empty numba cache (ik so101/al5, run "
        "planning/p02, compile: minutes; not with --quick)",
    )
    parser.add_argument(
        "sections", nargs="*", metavar="SECTION", help="sections to run, e.g. `bench serve`"
    )
    parser.add_argument("--quick", action="store_true", help="fewer repeats (smoke test)")
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    group = parser.add_mutually_exclusive_group()
    group.add_argument(
        "--robot", help="IK figures of this built-in robot only (al5, so100, so101), with peers"
    )
    group.add_argument("--urdf", help="IK figures of this URDF robot only (with --tool)")
    parser.add_argument("--tool", help="tool frame of --robot/--urdf (default: the robot's tool)")
    from lynxplan.benchsuite.command import add_arguments as add_suite_arguments

    add_suite_arguments(parser)
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    """Run the benchmark and print the figures."""
    unknown = sorted(set(args.sections) - set(SECTIONS))
    if unknown:
        raise InputError(f"unknown bench section {unknown[0]!r}; sections: {', '.join(SECTIONS)}")
    sections = ["cold"] if args.cold else (args.section or []) + args.sections or None
    if sections == ["suite"]:  # SmallArmBench: its own table, plot and options
        from lynxplan.benchsuite.command import run_suite

        return run_suite(args)
    if args.robot or args.urdf or args.tool:
        if sections or args.cold:
            raise InputError("--robot/--urdf/--tool run the robot section alone; drop the sections")
        from lynxplan.bench.robots import run_robot
        from lynxplan.robots import load_robot

        robot = load_robot(args.urdf or args.robot or "al5", tool=args.tool)
        figures = run_robot(robot, quick=args.quick)
    else:
        figures = run_sections(sections, quick=args.quick)
    verdicts = [verdict(f) for f in figures]
    if args.json:
        rows = [{**f._asdict(), "verdict": v} for f, v in zip(figures, verdicts, strict=True)]
        print_json({"figures": rows})
    else:
        _print_table(figures, verdicts)
    return _exit_code(figures, verdicts)


def _print_table(figures: list[Figure], verdicts: list[str]) -> None:
    """One line per figure: section, name, value and unit, target, verdict (or why no value)."""
    width = max(len(f.name) for f in figures) if figures else 10
    for f, v in zip(figures, verdicts, strict=True):
        if f.skipped:
            why = f.skipped if v == PEER_NOT_INSTALLED else f"{v}: {f.skipped}"
            print(f"[{f.section}] {f.name:<{width}}  {why}")
            continue
        target = f"  (target {f.target})" if f.target else ""
        shown = "  MISSED" if v == MISSED else f"  {v}" if v else ""
        print(f"[{f.section}] {f.name:<{width}}  {f.value:>14,.4g} {f.unit}{target}{shown}")


def _exit_code(figures: list[Figure], verdicts: list[str]) -> int:
    """3 when a section (or a peer) could not run, 1 when a figure missed its target, else 0; the
    reason on stderr. A peer that is not installed is no failure (the peers are optional)."""
    failed = [f for f, v in zip(figures, verdicts, strict=True) if v == NOT_RUN]
    missed = [f for f, v in zip(figures, verdicts, strict=True) if v == MISSED]
    absent = [f for f, v in zip(figures, verdicts, strict=True) if v == PEER_NOT_INSTALLED]
    if absent:
        names = ", ".join(f"{f.name} ({f.section})" for f in absent)
        print(f"lynxplan bench: peers not installed, not compared: {names}", file=sys.stderr)
    if missed:
        names = "; ".join(f"[{f.section}] {f.name}" for f in missed)
        print(
            f"lynxplan bench: {len(missed)} figure(s) missed the target: {names}", file=sys.stderr
        )
    if failed:
        names = "; ".join(f"[{f.section}] {f.name}: {f.skipped}" for f in failed)
        print(f"lynxplan bench: could not run: {names}", file=sys.stderr)
        return EXIT_NOT_RUN
    return EXIT_MISSED if missed else 0
