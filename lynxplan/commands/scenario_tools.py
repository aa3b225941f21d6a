"""``lynxplan schema [KIND]`` and ``lynxplan validate FILE``: the scenario schemas and a checker."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from lynxplan.scenario import KIND_MODULES, kind_module, load_scenario


def register(subparsers: Any) -> None:
    """Add the ``schema`` and ``validate`` sub-commands."""
    schema = subparsers.add_parser("schema", help="print the JSON Schema of a scenario kind")
    schema.add_argument(
        "kind",
        nargs="?",
        default="task",
        help=f"scenario kind (default: task); one of {', '.join(sorted(KIND_MODULES))}",
    )
    schema.set_defaults(handler=handle_schema)
    validate = subparsers.add_parser("validate", help="check a scenario file without running it")
    validate.add_argument("scenario", nargs="+", help="scenario YAML file(s)")
    validate.set_defaults(handler=handle_validate)


def handle_schema(args: argparse.Namespace) -> int:
    """Print the JSON Schema of ``args.kind``."""
    module = kind_module(args.kind, "<command line>")
    document = module.Scenario.model_json_schema(by_alias=True)
    sys.stdout.write(json.dumps(document, indent=2) + "\n")
    return 0


def handle_validate(args: argparse.Namespace) -> int:
    """Load and validate each file (ScenarioError -> the CLI prints it and exits 2)."""
    for path in args.scenario:
        _, scenario = load_scenario(path)
        kind = getattr(scenario, "kind", "?")
        print(f"{path}: valid {kind} scenario")
    return 0
