"""``lynxplan workspace``: sample the arm's workspace; plots, HTML view and workspace.json."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from lynxplan.units import LENGTH_UNITS


def register(subparsers: Any) -> None:
    """Add the ``workspace`` sub-command."""
    parser = subparsers.add_parser("workspace", help="workspace of the arm: volume, plots, HTML")
    parser.add_argument("--samples", type=int, default=2_000_000, help="random configurations")
    parser.add_argument("--out", default="out/workspace", help="output folder")
    parser.add_argument("--units", choices=tuple(LENGTH_UNITS), default="in", help="length unit")
    parser.add_argument("--cell", type=float, default=1.0, help="planar grid cell in mm")
    parser.add_argument("--voxel", type=float, default=10.0, help="voxel edge in mm")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--json", action="store_true", help="print workspace.json to stdout")
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    """Run the workspace analysis with the command-line settings."""
    from lynxplan.exceptions import InputError
    from lynxplan.scenarios import workspace as workspace_scenario
    from lynxplan.scenarios.base import Units
    from lynxplan.scenarios.outputs import staged_outputs

    if args.samples < 1:
        raise InputError(f"workspace --samples: must be at least 1. Got: {args.samples}")
    for option, value, smallest in (("--cell", args.cell, 0.1), ("--voxel", args.voxel, 0.1)):
        if not (math.isfinite(value) and value >= smallest):
            raise InputError(f"workspace {option}: must be at least {smallest} mm. Got: {value}")
    mm_to_unit = 1e-3 / LENGTH_UNITS[args.units]
    scenario = workspace_scenario.Input(
        kind="workspace",
        samples=args.samples,
        cell=args.cell * mm_to_unit,
        voxel_size=args.voxel * mm_to_unit,
        seed=args.seed,
        units=Units(length=args.units, angle="deg"),
    )
    out = Path(args.out)
    with staged_outputs(out, force=getattr(args, "force", False)) as staging:
        outcome = workspace_scenario.run(scenario)
        workspace_scenario.write_outputs(scenario, outcome, staging, quick=False)
        summary = (staging / "workspace.json").read_text(encoding="utf-8")
    if args.json:
        print(summary, end="")
    else:
        print(outcome.summary)
        print(f"outputs in {out}/")
    return 0
