"""``lynxplan fk`` and ``lynxplan ik``: the arm's kinematics from the command line.

JSON output is a contract: other tools parse it. Angles are in the requested angle unit,
lengths in the requested length unit, orientation errors always in radians.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np

from lynxplan import guards
from lynxplan.commands import _ik_answer as _ik
from lynxplan.commands import _ik_batch
from lynxplan.commands import robots as robots_cmd
from lynxplan.commands._output import (
    check_joint_limits,
    parse_finite,
    parse_json_numbers,
    parse_pose,
    print_json,
)
from lynxplan.exceptions import InputError, ShapeError, UnreachablePoseError
from lynxplan.units import LENGTH_UNITS, angle_factor, length_factor


def register(subparsers: Any) -> None:
    """Add the ``fk`` and ``ik`` sub-commands."""
    fk = subparsers.add_parser("fk", help="forward kinematics: joint angles -> tool pose")
    fk.add_argument(
        "q", nargs="*", metavar="Q", help="joint angles q1..q5 (rad, or deg with --deg)"
    )
    fk.add_argument(
        "--ignore-limits",
        action="store_true",
        help="compute the pose of angles beyond the joint limits (default: an error)",
    )
    _add_unit_options(fk)
    robots_cmd.add_robot_options(fk)
    fk.set_defaults(handler=handle_fk)

    ik = subparsers.add_parser("ik", help="inverse kinematics: tool pose -> joint angles")
    ik.add_argument("--pose", help="tool pose as a JSON 4x4 (or 3x4) nested list")
    ik.add_argument("--position", nargs=3, metavar=("X", "Y", "Z"), help="target tool point")
    ik.add_argument(
        "--approach", nargs=3, metavar=("AX", "AY", "AZ"), help="target approach direction"
    )
    ik.add_argument("--pitch", help="target approach pitch (from straight down, outwards)")
    ik.add_argument("--roll", help="roll joint angle for --position targets (default: free)")
    ik.add_argument(
        "--all", action="store_true", help="list every branch, not only those in limits"
    )
    ik.add_argument(
        "--strict",
        action="store_true",
        help="exit 2 unless a branch within the joint limits reaches the target (orientation"
        " within --tolerance); without it, the JSON status/message say why there is none",
    )
    ik.add_argument(
        "--tolerance", default="1e-6", help="strict orientation tolerance in rad (default 1e-6)"
    )
    ik.add_argument(
        "--select",
        choices=("nearest", "report"),
        default="nearest",
        help="nearest to --reference (default), or the report's rule q2 >= 0, q3 <= 0 (the AL5:"
        " the default arm or --robot al5)",
    )
    ik.add_argument("--reference", help="reference configuration, JSON list of 5 angles")
    _add_unit_options(ik)
    robots_cmd.add_robot_options(ik)
    _ik_batch.add_batch_options(ik)
    ik.set_defaults(handler=handle_ik)


def _add_unit_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--deg", action="store_true", help="angles in degrees (default radians)")
    parser.add_argument(
        "--units", choices=tuple(LENGTH_UNITS), default="m", help="length unit (default m)"
    )
    parser.add_argument("--json", action="store_true", help="print JSON")


def _units(args: argparse.Namespace) -> dict[str, str]:
    return {"length": args.units, "angle": "deg" if args.deg else "rad"}


def handle_fk(args: argparse.Namespace) -> int:
    """Print the tool pose of the given joint angles."""
    from lynxplan.arm import load_arm
    from lynxplan.arm.closed_form import tool_pose  # one pose: no numba import, fast start
    from lynxplan.arm.geometry import JOINT_NAMES

    if robots_cmd.wants_robot(args):
        return robots_cmd.handle_robot_fk(args)
    units = _units(args)
    if len(args.q) != 5:
        raise InputError(f"fk: expected 5 joint angles q1..q5, got {len(args.q)}")
    check = guards.angle_deg if args.deg else guards.angle
    q = np.array([check(f"q{i + 1}", parse_finite(t, f"q{i + 1}")) for i, t in enumerate(args.q)])
    q = q * angle_factor(units["angle"])
    arm = load_arm()
    if not args.ignore_limits:
        check_joint_limits(q, JOINT_NAMES, arm.limits.lower, arm.limits.upper, units["angle"])
    T = tool_pose(q, arm.geometry)
    T[:3, 3] /= length_factor(units["length"])
    if args.json:
        print_json({"T": T, "units": units})
    else:
        print(f"tool pose (lengths in {units['length']}):")
        for row in T:
            print("  " + "  ".join(f"{value:12.6f}" for value in row))
    return 0


def handle_ik(args: argparse.Namespace) -> int:
    """Print every IK branch of a pose and the selected one."""
    from lynxplan.arm import load_arm
    from lynxplan.arm.geometry import JOINT_NAMES
    from lynxplan.arm.ik_result import SOLVER, IkResult

    if args.poses is not None:
        return _ik_batch.handle(args)
    if args.out is not None or args.dask_local is not None or args.dask_scheduler is not None:
        raise InputError("ik: --out, --dask-local and --dask-scheduler go with --poses FILE.npy")
    if robots_cmd.wants_robot(args) or args.position is not None:
        return robots_cmd.handle_robot_ik(args)
    if args.pose is None:
        raise InputError(
            "ik: the following arguments are required: --pose"
            " (or --position with --approach or --pitch)"
        )
    units = _units(args)
    scale = angle_factor(units["angle"])
    pose = parse_pose(args.pose, units["length"])
    reference = None
    if args.reference is not None:
        given = parse_json_numbers(args.reference, "--reference", "a JSON list of 5 numbers")
        if given.shape != (5,):
            raise ShapeError("--reference", "(5,)", given.shape)
        reference = guards.angles("--reference", given * scale)
    tolerance = guards.tolerance("--tolerance", args.tolerance, "rad")
    arm = load_arm()
    answer_units = _ik.Units(units["angle"], units["length"])
    try:
        result = arm.ik(pose, q_reference=reference, select=args.select)
    except UnreachablePoseError as exc:
        if args.strict:
            raise
        result = IkResult((), None, False, exc.distance, float("nan"), SOLVER)
        reachable, distance = False, exc.distance
    else:
        reachable, distance = True, 0.0
    answer = _ik.ik_answer(
        result,
        _ik.JointTable(JOINT_NAMES, arm.limits.lower, arm.limits.upper),
        answer_units,
        show_all=args.all,
        reachable=reachable,
        distance=distance,
    )
    if args.strict:
        _ik.check_strict(answer, tolerance, answer_units)
    _ik.emit(
        answer,
        answer_units,
        as_json=args.json,
        header={},
        footer={"units": {**units, "orientation_error": "rad", "position_error": units["length"]}},
        branch_width=17,
    )
    return 0
