"""``lynxplan schema [KIND|report]`` and ``lynxplan validate FILE``: schemas and a checker."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from lynxplan.scenarios.registry import kind_module, kinds


def register(subparsers: Any) -> None:
    """Add the ``schema`` and ``validate`` sub-commands."""
    schema = subparsers.add_parser(
        "schema", help="print the JSON Schema of a scenario kind or of report.json"
    )
    schema.add_argument(
        "kind",
        nargs="?",
        default="task",
        help=f"'report', or a scenario kind (default: task): one of {', '.join(kinds())}",
    )
    schema.set_defaults(handler=handle_schema)
    validate = subparsers.add_parser("validate", help="check a scenario file without running it")
    validate.add_argument("scenario", nargs="+", help="scenario YAML file(s)")
    validate.set_defaults(handler=handle_validate)


def handle_schema(args: argparse.Namespace) -> int:
    """Print the JSON Schema of ``args.kind`` (or of ``report.json``)."""
    if args.kind == "report":
        from lynxplan.scenarios.report import report_schema

        document = report_schema()
    else:
        module = kind_module(args.kind, "<command line>")
        document = module.Input.model_json_schema(by_alias=True)
        _list_metrics(document, module.Input.metrics)
    sys.stdout.write(json.dumps(document, indent=2) + "\n")
    return 0


def _list_metrics(document: dict[str, Any], metrics: Any) -> None:
    """Name every metric an ``expect:`` entry may check under ``properties.expect.properties``.

    Each metric also accepts a ``max_``/``min_`` prefix, so ``expect`` stays open to other keys;
    the runner rejects an unknown name with the list of valid ones.
    """
    expect = document.setdefault("properties", {}).setdefault("expect", {})
    expect["properties"] = {
        name: {
            "description": f"{quantity} metric"
            + ("" if quantity in ("bool", "flags") else f" (also as max_{name} / min_{name})")
        }
        for name, quantity in sorted(metrics.items())
    }
    names = ", ".join(sorted(metrics))
    expect["description"] = f"{expect.get('description', '')} Metrics: {names}.".strip()


def handle_validate(args: argparse.Namespace) -> int:
    """Load and validate each file (ScenarioError -> the CLI prints it and exits 2)."""
    from lynxplan.scenarios import load_scenario

    for path in args.scenario:
        loaded = load_scenario(path)
        print(f"{path}: valid {loaded.scenario.kind} scenario")
    return 0
