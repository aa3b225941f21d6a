"""``lynxplan bench``: print the performance figures of every section."""

from __future__ import annotations

import argparse
from typing import Any

from lynxplan.bench import SECTIONS, run_sections
from lynxplan.commands._output import print_json
from lynxplan.exceptions import InputError


def register(subparsers: Any) -> None:
    """Add the ``bench`` sub-command."""
    parser = subparsers.add_parser("bench", help="measure performance figures side by side")
    parser.add_argument(
        "--section", action="append", choices=sorted(SECTIONS), help="run only these sections"
    )
    parser.add_argument(
        "--cold",
        action="store_true",
        help="fresh-process start-up times only (section cold): fk, run ok_task --quick, "
        "import pinocchio",
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
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    """Run the benchmark and print the figures."""
    unknown = sorted(set(args.sections) - set(SECTIONS))
    if unknown:
        raise InputError(f"unknown bench section {unknown[0]!r}; sections: {', '.join(SECTIONS)}")
    sections = ["cold"] if args.cold else (args.section or []) + args.sections or None
    if args.robot or args.urdf or args.tool:
        if sections or args.cold:
            raise InputError("--robot/--urdf/--tool run the robot section alone; drop the sections")
        from lynxplan.bench.robots import run_robot
        from lynxplan.robots import load_robot

        robot = load_robot(args.urdf or args.robot or "al5", tool=args.tool)
        figures = run_robot(robot, quick=args.quick)
    else:
        figures = run_sections(sections, quick=args.quick)
    if args.json:
        print_json({"figures": [f._asdict() for f in figures]})
        return 0
    width = max(len(f.name) for f in figures) if figures else 10
    for f in figures:
        verdict = "" if f.met is None else ("  ok" if f.met else "  MISSED")
        target = f"  (target {f.target})" if f.target else ""
        print(f"[{f.section}] {f.name:<{width}}  {f.value:>14,.4g} {f.unit}{target}{verdict}")
    return 0
