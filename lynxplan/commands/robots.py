"""``lynxplan robots``, ``lynxplan robot info``, and ``--robot``/``--urdf`` for ``fk``/``ik``.

JSON output is a contract: angles in the requested angle unit, lengths in the requested length
unit, orientation errors always in radians.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import asdict
from typing import Any

import numpy as np

from lynxplan.commands._output import (
    check_joint_limits,
    parse_finite,
    parse_pose,
    print_json,
)
from lynxplan.exceptions import InputError
from lynxplan.units import angle_factor, length_factor

CALIBRATION_HELP = (
    "LeRobot calibration JSON of the arm (SO-100/SO-101): joint limits from its calibrated ranges"
)


def register(subparsers: Any) -> None:
    """Add the ``robots`` and ``robot`` sub-commands."""
    robots = subparsers.add_parser("robots", help="list the built-in robots")
    robots.add_argument("--json", action="store_true", help="print JSON")
    robots.set_defaults(handler=handle_robots)

    robot = subparsers.add_parser("robot", help="describe a robot (built-in name or URDF)")
    actions = robot.add_subparsers(dest="action", metavar="ACTION", parser_class=type(robot))
    actions.required = True
    info = actions.add_parser("info", help="joints, limits, kinematic family, IK solver")
    info.add_argument("robot", metavar="NAME|URDF", help="built-in robot name or URDF path")
    info.add_argument("--tool", help="tool frame (default: the robot's tool)")
    info.add_argument("--calibration", help=CALIBRATION_HELP)
    info.add_argument("--deg", action="store_true", help="limits in degrees (default radians)")
    info.add_argument("--json", action="store_true", help="print JSON")
    info.set_defaults(handler=handle_robot_info)


def add_robot_options(parser: argparse.ArgumentParser) -> None:
    """``--robot NAME`` / ``--urdf PATH --tool FRAME`` on a kinematics command."""
    group = parser.add_mutually_exclusive_group()
    group.add_argument("--robot", help="a built-in robot (see `lynxplan robots`); default: the AL5")
    group.add_argument("--urdf", help="URDF file of the robot (with --tool)")
    parser.add_argument("--tool", help="tool frame name (default: the robot's tool)")
    parser.add_argument("--calibration", help=CALIBRATION_HELP)


def wants_robot(args: argparse.Namespace) -> bool:
    """Whether a command was given a robot or a tool frame (then it runs through
    lynxplan.robots: a ``--tool`` of the AL5 is checked, never ignored)."""
    return bool(
        getattr(args, "robot", None)
        or getattr(args, "urdf", None)
        or getattr(args, "tool", None)
        or getattr(args, "calibration", None)
    )


def _load(args: argparse.Namespace) -> Any:
    return _load_robot(args.urdf or args.robot or "al5", args.tool, args.calibration)


def _load_robot(name: str, tool: str | None, calibration: str | None) -> Any:
    """load_robot; a LeRobot calibration's one-line warning (a range past the URDF's limits)
    printed on stderr (the CLI silences library warnings)."""
    import sys
    import warnings

    from lynxplan.lerobot.errors import CalibrationWarning
    from lynxplan.robots import load_robot

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", CalibrationWarning)
        robot = load_robot(name, tool=tool, calibration=calibration)
    for warning in caught:
        if issubclass(warning.category, CalibrationWarning):
            print(f"warning: {warning.message}", file=sys.stderr)
    return robot


def handle_robots(args: argparse.Namespace) -> int:
    """List the built-in robots."""
    from lynxplan.robots.loading import builtin_robots

    robots = builtin_robots()
    if args.json:
        print_json(
            [
                {"name": r.name, "description": r.description, "urdf": str(r.urdf), "tool": r.tool}
                for r in robots.values()
            ]
        )
        return 0
    for r in robots.values():
        print(f"{r.name:<7} {r.description}")
    return 0


def _info_dict(robot: Any, scale: float) -> dict[str, Any]:
    info = robot.info()
    family = info.family_parameters
    params = None
    if family is not None:
        params = {k: v for k, v in asdict(family).items() if k != "packed"}
        params["tool_on_roll_axis"] = family.tool_on_roll_axis
    return {
        "name": info.name,
        "urdf": info.urdf,
        "tool_frame": info.tool_frame,
        "joints": [
            {
                "name": j.name,
                "lower": j.lower / scale,
                "upper": j.upper / scale,
                "velocity": j.velocity,
            }
            for j in info.joints
        ],
        "locked_joints": [{"name": n, "value": v} for n, v in info.locked_joints],
        "family": info.family,
        "family_parameters": params,
        "ik_solver": info.ik_solver,
    }


def handle_robot_info(args: argparse.Namespace) -> int:
    """Print joints, limits, the detected family and its parameters, and the IK solver."""

    unit = "deg" if args.deg else "rad"
    scale = angle_factor(unit)
    robot = _load_robot(args.robot, args.tool, args.calibration)
    data = _info_dict(robot, scale)
    if args.json:
        print_json({**data, "units": {"angle": unit, "velocity": "rad/s", "length": "m"}})
        return 0
    print(f"robot {data['name']}  ({data['urdf']})")
    print(f"tool frame: {data['tool_frame']}")
    print(f"joints (limits in {unit}, velocity in rad/s):")
    for j in data["joints"]:
        print(f"  {j['name']:<16} {j['lower']:10.4f} .. {j['upper']:10.4f}   {j['velocity']:.3g}")
    for j in data["locked_joints"]:
        print(f"  {j['name']:<16} locked at {j['value']:.4g} (off the arm chain)")
    print(f"family: {data['family']}")
    params = data["family_parameters"]
    if params is not None:
        print(f"  axis signs: {params['signs']}")
        print(
            f"  link lengths: {params['link_lengths'][0]:.6f} m, {params['link_lengths'][1]:.6f} m"
        )
        print(
            "  built-in link angles: "
            + ", ".join(f"{a / scale:.4f} {unit}" for a in params["built_in_angles"])
        )
        print(f"  lateral offset: {params['lateral_offset']:.6f} m")
        along, off = params["tool_offset"]
        print(f"  tool offset: {along:.6f} m along the roll axis, {off:.6f} m off it")
        print(
            f"  approach axis in the tool frame: {np.round(params['approach_in_tool'], 6).tolist()}"
        )
        print(f"  deviation from the ideal family: {params['deviation']:.3g} rad")
    print(f"IK solver: {data['ik_solver']}")
    return 0


def handle_robot_fk(args: argparse.Namespace) -> int:
    """fk with --robot/--urdf: the tool pose of a robot."""
    robot = _load(args)
    unit_length, unit_angle = args.units, "deg" if args.deg else "rad"
    if len(args.q) != robot.nq:
        raise InputError(f"fk: {robot.name} has {robot.nq} joints; got {len(args.q)} angles")
    q = np.array([parse_finite(t, f"q{i + 1}") for i, t in enumerate(args.q)])
    q = q * angle_factor(unit_angle)
    if not args.ignore_limits:
        check_joint_limits(q, robot.joint_names, robot.limits.lower, robot.limits.upper, unit_angle)
    T = robot.fk(q)
    T[:3, 3] /= length_factor(unit_length)
    if args.json:
        print_json(
            {"robot": robot.name, "T": T, "units": {"length": unit_length, "angle": unit_angle}}
        )
    else:
        print(f"{robot.name} tool pose ({robot.tool_frame}; lengths in {unit_length}):")
        for row in T:
            print("  " + "  ".join(f"{value:12.6f}" for value in row))
    return 0


def handle_robot_ik(args: argparse.Namespace) -> int:
    """ik with --robot/--urdf or --position: every verified branch of a robot's target."""
    from lynxplan import guards
    from lynxplan.commands import _ik_answer as _ik

    tolerance = guards.tolerance("--tolerance", args.tolerance, "rad")
    robot = _load(args)
    unit_length, unit_angle = args.units, "deg" if args.deg else "rad"
    length, scale = length_factor(unit_length), angle_factor(unit_angle)
    reference = None
    if args.reference is not None:
        try:
            reference = np.array(json.loads(args.reference), dtype=float) * scale
        except (json.JSONDecodeError, TypeError, ValueError) as exc:
            raise InputError(
                f"--reference: not a JSON list of {robot.nq} numbers ({exc})"
            ) from None
    roll = None if args.roll is None else parse_finite(args.roll, "--roll") * scale
    if args.position is not None:
        position = np.array([parse_finite(t, "--position") for t in args.position]) * length
        approach = pitch = None
        if args.approach is not None:
            approach = np.array([parse_finite(t, "--approach") for t in args.approach])
        elif args.pitch is not None:
            pitch = parse_finite(args.pitch, "--pitch") * scale
        else:
            raise InputError("ik: --position needs --approach AX AY AZ or --pitch ANGLE")
        result = robot.ik(
            position=position,
            approach=approach,
            pitch=pitch,
            roll=roll,
            q_reference=reference,
            verify=True,
            select=args.select,
        )
    elif args.pose is not None:
        pose = parse_pose(args.pose, unit_length)
        result = robot.ik(pose, q_reference=reference, verify=True, select=args.select)
    else:
        raise InputError(
            "ik: the following arguments are required: --pose"
            " (or --position with --approach or --pitch)"
        )
    answer_units = _ik.Units(unit_angle, unit_length)
    answer = _ik.ik_answer(
        result,
        _ik.JointTable(robot.joint_names, robot.limits.lower, robot.limits.upper),
        answer_units,
        show_all=args.all,
        reachable=result.reachable,
        distance=result.distance,
    )
    for row in answer["solutions"]:
        row["verified"] = True
    if args.strict:
        _ik.check_strict(answer, tolerance, answer_units)
    if not args.json:
        print(f"{robot.name}: {result.solver}")
    _ik.emit(
        answer,
        answer_units,
        as_json=args.json,
        header={"robot": robot.name, "solver": result.solver},
        footer={
            "verification": "every branch: Pinocchio frame placement == solver FK to 1e-12 m",
            "units": {
                "length": unit_length,
                "angle": unit_angle,
                "orientation_error": "rad",
                "position_error": unit_length,
            },
        },
        branch_width=24,
    )
    return 0
