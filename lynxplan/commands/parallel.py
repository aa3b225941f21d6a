"""``lynxplan parallel ik|fk|workspace``: the planar 3-RRR from the command line (mm, degrees).

JSON output (``--json``) is a contract:

- ``ik XC YC ALPHA`` -> ``{"solutions": [[t1, t2, t3] x 8], "modes": ["+++", ...]}`` in degrees;
- ``fk T1 T2 T3`` -> ``{"poses": [[xc, yc, alpha], ...]}`` in mm and degrees;
- ``workspace --alpha A`` -> ``{"area_mm2": ..., "points": ...}`` (``points``: grid points in the
  workspace), plus a PNG in ``--out``.
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan import guards
from lynxplan.commands._output import parse_finite, print_json
from lynxplan.exceptions import InputError


def register(subparsers: Any) -> None:
    """Add the ``parallel`` sub-command and its ``ik``, ``fk``, ``workspace`` actions."""
    parser = subparsers.add_parser("parallel", help="planar 3-RRR parallel robot (mm, degrees)")
    actions = parser.add_subparsers(dest="action", metavar="ACTION", parser_class=type(parser))
    actions.required = True

    ik = actions.add_parser("ik", help="the 8 working modes of a pose")
    for name in ("xc", "yc"):
        ik.add_argument(name, help=f"platform centre {name[0]} [mm]")
    ik.add_argument("alpha", help="platform orientation [deg]")
    ik.add_argument("--json", action="store_true", help="print JSON")
    ik.set_defaults(handler=handle_ik)

    fk = actions.add_parser("fk", help="every assembly mode for actuated angles")
    for name in ("t1", "t2", "t3"):
        fk.add_argument(name, help=f"actuated angle {name} [deg]")
    fk.add_argument(
        "--near", nargs=3, metavar=("XC", "YC", "ALPHA"), help="keep only the pose nearest this one"
    )
    fk.add_argument("--json", action="store_true", help="print JSON")
    fk.set_defaults(handler=handle_fk)

    ws = actions.add_parser("workspace", help="constant-orientation workspace and its PNG")
    ws.add_argument("--alpha", required=True, help="platform orientation [deg]")
    ws.add_argument("--step", default="1", help="grid step [mm] (default 1)")
    ws.add_argument("--mode", default=None, help="restrict to a working mode (label or 1..8)")
    ws.add_argument(
        "--out",
        default="out/parallel_workspace",
        help="folder for the PNG (default: out/parallel_workspace)",
    )
    ws.add_argument("--json", action="store_true", help="print JSON")
    ws.set_defaults(handler=handle_workspace)


def _angle_deg(text: str, name: str) -> float:
    return guards.angle_deg(name, parse_finite(text, name))


def _length_mm(text: str, name: str) -> float:
    return guards.length(name, parse_finite(text, name), 1e-3, "mm")


def _pose_mm_deg(xc: str, yc: str, alpha: str, prefix: str = "") -> tuple[float, float, float]:
    """``XC YC ALPHA`` from the command line in [mm, mm, deg], each checked against its range."""
    return (
        _length_mm(xc, f"{prefix}XC"),
        _length_mm(yc, f"{prefix}YC"),
        _angle_deg(alpha, f"{prefix}ALPHA"),
    )


def handle_ik(args: argparse.Namespace) -> int:
    """Print the 8 working modes of the pose."""
    from lynxplan.parallel import WORKING_MODES, pose_from_mm_deg, solve_ik

    pose = pose_from_mm_deg(*_pose_mm_deg(args.xc, args.yc, args.alpha))
    solutions = np.degrees(solve_ik(pose))
    if args.json:
        print_json({"solutions": solutions, "modes": list(WORKING_MODES)})
        return 0
    print("mode        theta1      theta2      theta3  [deg]")
    for m, row in enumerate(solutions):
        print(f"{m + 1} {WORKING_MODES[m]}  " + "".join(f"{v:12.4f}" for v in row))
    return 0


def handle_fk(args: argparse.Namespace) -> int:
    """Print every assembly mode (or the one nearest ``--near``)."""
    from lynxplan.parallel import (
        nearest_assembly_mode,
        pose_from_mm_deg,
        pose_to_mm_deg,
        solve_fk,
    )

    theta = np.radians([_angle_deg(getattr(args, n), n.upper()) for n in ("t1", "t2", "t3")])
    if args.near is not None:
        xc, yc, alpha = args.near
        near = _pose_mm_deg(xc, yc, alpha, prefix="--near ")
        poses = nearest_assembly_mode(theta, pose_from_mm_deg(*near))[None]
        labels = [""]
    else:
        result = solve_fk(theta)
        poses, labels = result.poses, result.mode_labels()
    poses_out = pose_to_mm_deg(poses)
    if args.json:
        print_json({"poses": poses_out})
        return 0
    if len(poses_out) == 0:
        print("no assembly mode: the distal links cannot all meet the platform")
        return 0
    print("       xc [mm]     yc [mm]   alpha [deg]  working mode")
    for k, (row, label) in enumerate(zip(poses_out, labels, strict=True)):
        print(f"{k + 1}  " + "".join(f"{v:12.4f}" for v in row) + f"  {label}")
    return 0


def _mode_argument(text: str | None) -> int | None:
    if text is None:
        return None
    from lynxplan.parallel.ik import mode_index

    if text.isdigit():
        number = int(text)
        if not 1 <= number <= 8:
            raise InputError(f"--mode: working mode number must be 1..8. Got: {number}")
        return number - 1
    return mode_index(text)


def handle_workspace(args: argparse.Namespace) -> int:
    """Compute the workspace, write its PNG, print area and point count."""
    from lynxplan.parallel.plots import plot_workspace
    from lynxplan.parallel.workspace import constant_orientation_workspace
    from lynxplan.scenarios.outputs import staged_outputs

    alpha_deg = _angle_deg(args.alpha, "--alpha")
    step = guards.positive_length("--step", parse_finite(args.step, "--step"), 1e-3, "mm")
    mode = _mode_argument(args.mode)
    workspace = constant_orientation_workspace(math.radians(alpha_deg), step=step * 1e-3, mode=mode)
    suffix = "" if mode is None else f"_mode{mode + 1}"
    name = f"parallel_workspace_alpha{alpha_deg:g}{suffix}.png"
    with staged_outputs(args.out) as staging:
        plot_workspace(workspace, staging / name, loci_mode=0 if mode is None else mode)
    png = Path(args.out) / name
    if args.json:
        print_json({"area_mm2": workspace.area_mm2, "points": workspace.points})
        return 0
    print(
        f"alpha {alpha_deg:g} deg, step {step:g} mm: {workspace.points} points, "
        f"area {workspace.area_mm2:.1f} mm^2; plot: {png}"
    )
    return 0
