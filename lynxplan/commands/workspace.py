"""``lynxplan workspace``: sample the arm's workspace; plots, HTML view and workspace.json."""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

from lynxplan import guards
from lynxplan.commands import robots as robots_cmd
from lynxplan.commands._fanout import add_dask_options, cluster_of
from lynxplan.commands._output import parse_finite
from lynxplan.units import LENGTH_UNITS

DEFAULT_SAMPLES = 2_000_000
#: Samples of ``--quick``.
QUICK_SAMPLES = 100_000


def register(subparsers: Any) -> None:
    """Add the ``workspace`` sub-command."""
    parser = subparsers.add_parser("workspace", help="workspace of the arm: volume, plots, HTML")
    parser.add_argument("--samples", default=None, help="random configurations (default 2,000,000)")
    parser.add_argument(
        "--quick",
        action="store_true",
        help=f"smoke run: {QUICK_SAMPLES:,} samples (cannot be combined with --samples)",
    )
    parser.add_argument("--out", default="out/workspace", help="output folder")
    parser.add_argument(
        "--units",
        choices=tuple(LENGTH_UNITS),
        default="m",
        help="length unit of what is printed and plotted (default m, as every command)",
    )
    parser.add_argument("--cell", default="1", help="planar grid cell in mm (default 1)")
    parser.add_argument("--voxel", default="10", help="voxel edge in mm (default 10)")
    parser.add_argument("--seed", default="0", help="random seed, 0 <= seed < 2**63 (default 0)")
    parser.add_argument("--json", action="store_true", help="print workspace.json to stdout")
    robots_cmd.add_robot_options(parser)
    add_dask_options(parser)
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    """Run the workspace analysis with the command-line settings."""
    from lynxplan.exceptions import InputError
    from lynxplan.scenarios import workspace as workspace_scenario
    from lynxplan.scenarios.base import RobotRef, Units
    from lynxplan.scenarios.outputs import staged_outputs

    if args.quick and args.samples is not None:
        raise InputError("workspace: --quick and --samples contradict each other; give one")
    cluster = cluster_of(args)
    samples = QUICK_SAMPLES if args.quick else DEFAULT_SAMPLES
    if args.samples is not None:
        samples = guards.count("workspace --samples", _integer(args.samples, "--samples"))
    seed = guards.seed("workspace --seed", _integer(args.seed, "--seed"))
    cell, voxel = parse_finite(args.cell, "--cell"), parse_finite(args.voxel, "--voxel")
    for option, value, smallest in (("--cell", cell, 0.1), ("--voxel", voxel, 0.1)):
        if not (math.isfinite(value) and value >= smallest):
            raise InputError(f"workspace {option}: must be at least {smallest} mm. Got: {value}")
        guards.positive_length(f"workspace {option}", value, 1e-3, "mm")
    mm_to_unit = 1e-3 / LENGTH_UNITS[args.units]
    scenario = workspace_scenario.Input(
        kind="workspace",
        samples=samples,
        cell=cell * mm_to_unit,
        voxel_size=voxel * mm_to_unit,
        seed=seed,
        units=Units(length=args.units, angle="deg"),
        robot=RobotRef(
            name=args.robot or ("al5" if args.tool and not args.urdf else None),
            urdf=args.urdf,
            tool=args.tool,
        ),
    )
    out = Path(args.out)
    with staged_outputs(out, force=getattr(args, "force", False)) as staging:
        outcome = workspace_scenario.run(scenario, cluster=cluster)
        workspace_scenario.write_outputs(scenario, outcome, staging, quick=args.quick)
        summary = (staging / "workspace.json").read_text(encoding="utf-8")
    if args.json:
        print(summary, end="")
    else:
        print(outcome.summary)
        print(f"outputs in {out}/")
    return 0


def _integer(text: str, name: str) -> int:
    """An integer option (``2000000``, ``2_000_000`` or ``2e6``); InputError naming ``name``."""
    from lynxplan.exceptions import InputError

    try:
        return int(text.replace("_", ""))
    except ValueError:
        pass
    value = parse_finite(text, name)
    if not value.is_integer():
        raise InputError(f"workspace {name}: {text!r} is not an integer")
    return int(value)
