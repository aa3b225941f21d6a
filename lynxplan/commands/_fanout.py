"""``--dask-local N`` / ``--dask-scheduler ADDRESS`` on the commands that fan out on Dask."""

from __future__ import annotations

import argparse
from typing import Any


def add_dask_options(parser: Any) -> None:
    """The two fan-out options (give at most one; neither: the serial run)."""
    group = parser.add_argument_group("Dask fan-out (results identical to the serial run)")
    group.add_argument(
        "--dask-local", type=int, metavar="N", help="run on a local Dask cluster of N processes"
    )
    group.add_argument(
        "--dask-scheduler", metavar="ADDRESS", help="run on the Dask scheduler at ADDRESS"
    )


def cluster_of(args: argparse.Namespace) -> Any:
    """The :class:`lynxplan.fanout.Cluster` the options name, or None (serial).

    Raises:
        InputError: both options, a worker count below 1, an empty address.
    """
    from lynxplan.fanout.cluster import cluster_from_options

    return cluster_from_options(args.dask_scheduler, args.dask_local)
