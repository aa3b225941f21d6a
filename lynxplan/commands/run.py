"""``lynxplan run SCENARIO.yaml``: run a scenario file and write its outputs."""

from __future__ import annotations

import argparse
from typing import Any


def register(subparsers: Any) -> None:
    """Add the ``run`` sub-command."""
    parser = subparsers.add_parser(
        "run",
        help="run a scenario YAML file",
        description="Run a scenario and write report.json and its artifacts into --out. The "
        "folder is replaced as a whole when the run completes (an interrupted or failed run "
        "leaves the previous one intact). Exit 0: every expectation holds; 1: an expectation "
        "failed (the report is still written); 2: bad input.",
    )
    parser.add_argument("scenario", help="scenario YAML file")
    parser.add_argument("--out", default="out", help="output folder (default: ./out)")
    parser.add_argument(
        "--quick", action="store_true", help="skip plots, HTML and the ruckig/toppra comparisons"
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="replace --out even if it holds files lynxplan did not write",
    )
    parser.add_argument("--server", help="run on a lynxplan server (URL) instead of locally")
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    """Run the scenario; exit 0 when every expectation holds, 1 otherwise."""
    if args.server:
        from lynxplan.client import run_remote

        return run_remote(args.server, args.scenario, args.out, quick=args.quick)
    from lynxplan.scenarios import run_scenario

    result = run_scenario(args.scenario, args.out, quick=args.quick, force=args.force)
    print(result.summary)
    held = sum(e.passed for e in result.expectations)
    if result.expectations:
        print(f"expectations: {held} of {len(result.expectations)} hold")
    print(f"outputs in {args.out}/: {', '.join(result.artifacts)}")
    if not result.ok:
        print("failed expectations:")
        for failure in result.failed_expectations:
            print(f"  - {failure}")
        return 1
    return 0
