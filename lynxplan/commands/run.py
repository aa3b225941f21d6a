"""``lynxplan run SCENARIO.yaml``: run a scenario file and write its outputs."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from lynxplan import _jit


def register(subparsers: Any) -> None:
    """Add the ``run`` sub-command."""
    parser = subparsers.add_parser(
        "run",
        help="run a scenario YAML file",
        description="Run a scenario and write report.json and its artifacts into --out "
        "(default: out/<scenario name>). lynxplan's previous outputs there are replaced as a "
        "whole when the run completes (an interrupted, killed or failed run leaves them intact); "
        "files lynxplan did not write are never deleted or overwritten: a folder holding some is "
        "refused unless --force, which keeps them. Exit 0: every expectation holds; 1: an "
        "expectation failed (the report is still written); 2: bad input.",
    )
    parser.add_argument("scenario", help="scenario YAML file")
    parser.add_argument(
        "--out", help="output folder (default: out/<scenario name>, e.g. out/ok_task)"
    )
    parser.add_argument(
        "--quick", action="store_true", help="skip plots, HTML and the ruckig/toppra comparisons"
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="use --out even if it holds files lynxplan did not write (they stay untouched; "
        "only lynxplan's own outputs are replaced)",
    )
    parser.add_argument("--server", help="run on a lynxplan server (URL) instead of locally")
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    """Run the scenario; exit 0 when every expectation holds, 1 otherwise."""
    from lynxplan.scenarios.folders import folder_name
    from lynxplan.scenarios.source import read_source

    if args.server:
        from lynxplan.client import run_remote

        out = (
            args.out
            or f"out/{folder_name(read_source(args.scenario).data.get('name'), args.scenario)}"
        )
        return run_remote(args.server, args.scenario, out, quick=args.quick, force=args.force)
    if read_source(args.scenario).data.get("kind") == "plan":
        _jit.plan_as_python_if_cold()  # a first plan: seconds as Python, not minutes compiling
    from lynxplan.scenarios.runner import execute, load_scenario

    loaded = load_scenario(args.scenario)
    out = args.out or f"out/{folder_name(loaded.scenario.name, args.scenario)}"
    try:
        result = execute(loaded, out, quick=args.quick, force=args.force)
    except _jit.PythonPlanTooSlowError:  # nothing written: the compiled planner's verdict instead
        return _jit.rerun_compiled(sys.argv[1:])
    print(result.summary)
    held = sum(e.passed for e in result.expectations)
    if result.expectations:
        print(f"expectations: {held} of {len(result.expectations)} hold")
    print(f"outputs in {out}/: {', '.join(result.artifacts)}")
    if not result.ok:
        print("failed expectations:")
        for failure in result.failed_expectations:
            print(f"  - {failure}")
        return 1
    return 0
