"""``lynxplan run SCENARIO.yaml``: run a scenario file and write its outputs."""

from __future__ import annotations

import argparse
from typing import Any

from lynxplan.exceptions import LynxplanError, ScenarioError
from lynxplan.runner import run_scenario


def register(subparsers: Any) -> None:
    """Add the ``run`` sub-command."""
    parser = subparsers.add_parser("run", help="run a scenario YAML file")
    parser.add_argument("scenario", help="scenario YAML file")
    parser.add_argument("--out", default="out", help="output folder (default: ./out)")
    parser.add_argument("--quick", action="store_true", help="skip plots and HTML")
    parser.add_argument("--server", help="run on a lynxplan server (URL) instead of locally")
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    """Run the scenario; exit 0 when every expectation holds, 1 otherwise."""
    if args.server:
        from lynxplan.client import run_remote

        return run_remote(args.server, args.scenario, args.out, quick=args.quick)
    try:
        outcome = run_scenario(args.scenario, args.out, quick=args.quick)
    except ScenarioError:
        raise
    except LynxplanError as exc:  # a run-time problem: say which file it came from
        raise ScenarioError(args.scenario, "", str(exc)) from exc
    print(outcome.summary)
    if not outcome.ok:
        print("failed expectations:")
        for failure in outcome.failed_expectations:
            print(f"  - {failure}")
        return 1
    return 0
