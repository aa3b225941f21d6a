"""``lynxplan ik --poses FILE.npy --out FILE.npz``: every IK branch of N poses, optionally in
chunks on Dask (``--dask-local N`` / ``--dask-scheduler ADDRESS``; the same answers).

The poses file holds an (N, 4, 4) float array in [m]; the answers file holds the arrays of
``Robot.ik_batch`` (SI: m, rad): ``q`` (N, B, n), ``valid``, ``within_limits``,
``position_error``, ``orientation_error`` (N, B), ``reachable``, ``distance`` (N,), and
``branch_names`` (B,).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.exceptions import InputError, ShapeError

#: Options of a single target that a batch does not take.
_SINGLE_TARGET = ("pose", "position", "approach", "pitch", "roll", "reference")


def add_batch_options(parser: Any) -> None:
    """``--poses`` and ``--out`` on the ``ik`` parser (the Dask options come with them)."""
    from lynxplan.commands._fanout import add_dask_options

    parser.add_argument(
        "--poses", metavar="FILE.npy", help="batch: tool poses, (N, 4, 4) in m (see --out)"
    )
    parser.add_argument(
        "--out", metavar="FILE.npz", help="batch: the answers (every branch; m and rad)"
    )
    add_dask_options(parser)


def load_poses(path: str) -> np.ndarray:
    """The (N, 4, 4) finite poses of a .npy file, in [m].

    Raises:
        InputError / ShapeError: a missing or unreadable file, another shape, a non-finite value.
    """
    try:
        poses = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as error:
        raise InputError(f"ik --poses {path}: not a readable .npy array ({error})") from None
    if poses.ndim != 3 or poses.shape[1:] != (4, 4) or poses.shape[0] < 1:
        raise ShapeError("ik --poses", "(N, 4, 4) with N >= 1", poses.shape)
    if not np.issubdtype(poses.dtype, np.number) or not np.isfinite(poses).all():
        raise InputError(f"ik --poses {path}: every value must be a finite number")
    return np.ascontiguousarray(poses, dtype=float)


def handle(args: argparse.Namespace) -> int:
    """Solve every pose of ``--poses``; write the answers to ``--out``; print a summary."""
    from lynxplan.commands import robots as robots_cmd
    from lynxplan.commands._fanout import cluster_of

    given = [f"--{name}" for name in _SINGLE_TARGET if getattr(args, name, None) is not None]
    if given:
        raise InputError(f"ik --poses: {', '.join(given)} is for one target; not with --poses")
    if args.deg or args.units != "m":
        raise InputError("ik --poses: poses and answers are in m and rad; drop --deg / --units")
    if args.out is None or not args.out.endswith(".npz"):
        raise InputError(f"ik --poses needs --out FILE.npz for the answers. Got: {args.out}")
    cluster = cluster_of(args)
    poses = load_poses(args.poses)
    robot = robots_cmd._load(args)
    if cluster is None:
        batch = robot.ik_batch(poses)
    else:
        from lynxplan.fanout.ik import ik_batch_on_dask
        from lynxplan.progress import progress_bar

        with progress_bar(f"IK of {poses.shape[0]:,} poses") as progress:
            batch = ik_batch_on_dask(robot, poses, cluster=cluster, progress=progress)
    write_answers(Path(args.out), batch)
    summary = {
        "robot": robot.name,
        "poses": int(poses.shape[0]),
        "reachable": int(batch.reachable.sum()),
        "within_limits": int((batch.valid & batch.within_limits).any(axis=1).sum()),
        "out": args.out,
    }
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"{robot.name}: {summary['poses']:,} poses, {summary['reachable']:,} reachable, "
              f"{summary['within_limits']:,} with a branch within the limits; answers in "
              f"{args.out}")  # fmt: skip
    return 0


def write_answers(path: Path, batch: Any) -> None:
    """The batch's arrays in an .npz file (``branch_names`` as strings)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    arrays: dict[str, Any] = {name: np.asarray(value) for name, value in batch._asdict().items()}
    save: Any = np.savez
    save(path, **arrays)
