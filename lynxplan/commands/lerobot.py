"""``lynxplan lerobot export|check``: a motion as frames an SO-101 replays; recordings checked.

- ``export SCENARIO --calibration CAL --out DIR``: the motion of a task, trajectory or plan
  scenario (sampled at its rate; a plan is planned with its seed) as servo-safe LeRobot frames
  at ``--fps`` (:func:`lynxplan.lerobot.servo_frames`), written as ``DIR/frames.csv`` and the
  LeRobot dataset ``DIR/dataset`` (one episode);
- ``check SOURCE --calibration CAL [--scene SCENARIO] [--out DIR]``: a LeRobot dataset's episode
  (or a frames CSV) -> FK -> tool path, limit, servo and collision checks against the scene's
  obstacles (a task or plan scenario file), figures and meshcat HTML in ``DIR``. Exit 1 when a
  frame is outside the limits or touches an obstacle.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path
from typing import Any

from lynxplan.commands.robots import CALIBRATION_HELP, _load_robot

#: Exit code of ``check`` when the recorded motion fails a check (as a failed expectation).
EXIT_CHECK_FAILED = 1


def register(subparsers: Any) -> None:
    """Add the ``lerobot`` sub-command and its ``export`` and ``check`` actions."""
    parser = subparsers.add_parser(
        "lerobot", help="LeRobot (SO-100/SO-101): export frames and a dataset, check recordings"
    )
    actions = parser.add_subparsers(dest="action", metavar="ACTION")
    actions.required = True
    export = actions.add_parser(
        "export",
        help="a task, trajectory or plan scenario as servo-safe frames (CSV) and a LeRobot dataset",
    )
    export.add_argument(
        "scenario",
        help="task, trajectory or plan scenario file of the same robot (e.g. so101_writing.yaml)",
    )
    export.add_argument("--out", default="out/lerobot_frames", help="output folder")
    export.add_argument("--fps", default="30", help="frame rate, a whole number (default 30)")
    export.add_argument("--gripper", default=None, help="gripper channel 0..100 of every frame")
    export.add_argument("--task", default=None, help="the dataset's task text (default: scenario)")
    export.add_argument("--no-dataset", action="store_true", help="write frames.csv only")
    export.add_argument("--overwrite", action="store_true", help="replace what lynxplan wrote")
    check = actions.add_parser(
        "check", help="recorded joint positions: tool path, limits, collisions, plots, HTML"
    )
    check.add_argument("source", help="a LeRobot dataset folder, or a frames CSV")
    check.add_argument("--episode", default="0", help="episode of a dataset (default 0)")
    check.add_argument(
        "--key",
        default="observation.state",
        choices=("observation.state", "action"),
        help="the dataset feature read (default observation.state: the recorded positions)",
    )
    check.add_argument("--scene", default=None, help="task or plan scenario: its obstacles")
    check.add_argument("--out", default=None, help="folder for the figures and HTML")
    for sub in (export, check):
        sub.add_argument("--calibration", help=CALIBRATION_HELP)
        sub.add_argument("--robot", default="so101", choices=("so101", "so100"))
        sub.add_argument(
            "--range-units",
            action="store_true",
            help="LeRobot values in -100..100 (use_degrees=False; needs --calibration); "
            "default: degrees",
        )
    export.set_defaults(handler=handle_export)
    check.set_defaults(handler=handle_check)


def _whole(text: str, option: str, smallest: int) -> int:
    from lynxplan.exceptions import InputError

    try:
        value = float(text)
    except ValueError:
        raise InputError(f"{option}: {text!r} is not a number") from None
    if not (math.isfinite(value) and value == round(value) and value >= smallest):
        raise InputError(f"{option} = {text}: must be a whole number >= {smallest}")
    return round(value)


def _robot_and_units(args: argparse.Namespace) -> tuple[Any, Any]:
    from lynxplan.lerobot.units import lerobot_units

    robot = _load_robot(args.robot, None, args.calibration)
    return robot, lerobot_units(robot, args.calibration, use_degrees=not args.range_units)


def _scenario(path: str, kinds: tuple[str, ...]) -> Any:
    """The scenario file's validated model (one of ``kinds``)."""
    from lynxplan.exceptions import InputError
    from lynxplan.scenarios import load_scenario

    loaded = load_scenario(path)
    kind = loaded.scenario.kind
    if kind not in kinds:
        raise InputError(f"{path}: kind {kind!r}; lynxplan lerobot takes {' or '.join(kinds)}")
    return loaded


def _motion(path: str, robot_name: str) -> tuple[Any, Any, Any]:
    """The scenario (task, trajectory or plan) and its motion's samples: ``t`` (T,) [s] and
    ``q`` (T, n) [rad] — a task's timed plan, a trajectory's samples, a plan's planned and
    time-parameterised path (planned with the scenario's seed, so the same frames each time).

    Raises:
        InputError: the scenario's robot is not the one the frames are for, or its plan was
            not solved (nothing to export).
    """
    from lynxplan.exceptions import InputError, ScenarioValueError
    from lynxplan.scenarios.registry import kind_module

    loaded = _scenario(path, ("task", "trajectory", "plan"))
    scenario = loaded.scenario
    named = scenario.robot.name or ("al5" if scenario.robot.urdf is None else None)
    if named is not None and named != robot_name:
        hint = (
            f"pass --robot {named}" if named in ("so100", "so101") else "LeRobot drives so100/so101"
        )
        raise InputError(f"{path}: robot {named!r}, frames for --robot {robot_name}; {hint}")
    try:
        if scenario.kind == "task":
            from lynxplan.task.setup import resolve

            samples = resolve(scenario).plan.sample(scenario.sample_rate)
            return scenario, samples.t, samples.q
        output = kind_module(scenario.kind, path).run(scenario, quick=True)
    except ScenarioValueError as exc:
        raise loaded.located(exc) from None
    if scenario.kind == "trajectory":
        samples = output.payload[1]
        return scenario, samples.t, samples.q
    if output.payload is None:  # the plan was not solved
        raise InputError(f"{path}: {output.summary}; nothing to export")
    trajectory = output.payload["trajectory"]
    return scenario, trajectory.t, trajectory.q


def _scene(path: str) -> tuple[list[Any], bool]:
    """The obstacles [m] of a task or plan scenario, and whether it checks self-collision."""
    from lynxplan.task.setup import _obstacle
    from lynxplan.units import angle_factor, length_factor

    scenario = _scenario(path, ("task", "plan")).scenario
    length, angle = length_factor(scenario.units.length), angle_factor(scenario.units.angle)
    obstacles = [
        _obstacle(entry, entry.name or f"obstacle_{i}", length, angle)
        for i, entry in enumerate(scenario.obstacles)
    ]
    return obstacles, bool(getattr(scenario, "self_collision", True))


def handle_export(args: argparse.Namespace) -> int:
    """Write the scenario's motion as servo-safe frames and a LeRobot dataset."""
    from lynxplan.commands._output import parse_finite
    from lynxplan.exceptions import InputError
    from lynxplan.lerobot.dataset import write_dataset
    from lynxplan.lerobot.export import servo_frames, write_csv

    fps = _whole(args.fps, "--fps", 1)
    gripper = None if args.gripper is None else parse_finite(args.gripper, "--gripper")
    if gripper is not None and not 0 <= gripper <= 100:
        raise InputError(f"--gripper = {args.gripper}: must be within 0..100")
    robot, units = _robot_and_units(args)
    scenario, t, q = _motion(args.scenario, args.robot)
    frames = servo_frames(robot, units, t, q, gripper=gripper, fps=fps)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    csv = write_csv(frames, out / "frames.csv", overwrite=args.overwrite)
    written = [csv]
    if not args.no_dataset:
        provenance = {
            "scenario": str(args.scenario),
            "calibration": None if args.calibration is None else str(args.calibration),
            "units": units.unit,
            "time_scale": frames.time_scale,
        }
        written.append(
            write_dataset(
                out / "dataset",
                frames,
                tasks=args.task or scenario.description or scenario.name or "lynxplan task",
                robot_type=f"{args.robot}_follower",
                provenance=provenance,
                overwrite=args.overwrite,
            )
        )
    duration = frames.t[-1]
    print(
        f"{len(frames.t)} frames at {fps} fps ({duration:.2f} s, {frames.time_scale:.3g}x the "
        f"scenario's {t[-1]:.2f} s); values in {units.unit}"
    )
    print(
        f"peak joint speed {math.degrees(float(frames.peak_velocity.max())):.1f} deg/s, "
        f"acceleration {math.degrees(float(frames.peak_acceleration.max())):.0f} deg/s^2 "
        "(within the STS3215 bounds of lynxplan/lerobot/servo.py)"
    )
    for path in written:
        print(f"wrote {path}")
    return 0


def _recorded(args: argparse.Namespace, units: Any) -> tuple[Any, Any]:
    """Times [s] and joint frames of the source (a dataset folder or a frames CSV)."""
    from lynxplan.lerobot.dataset import read_episode
    from lynxplan.lerobot.export import read_csv
    from lynxplan.lerobot.recorded import joints_of

    source = Path(args.source)
    if source.is_dir():
        episode = read_episode(source, _whole(args.episode, "--episode", 0), args.key)
        return episode.t, joints_of(units, episode)
    t, frames = read_csv(source)
    return t, joints_of(units, frames)


def handle_check(args: argparse.Namespace) -> int:
    """Check recorded joint positions against the limits and the scene; figures and HTML."""
    from lynxplan.lerobot.recorded import check_recorded, write_recorded

    robot, units = _robot_and_units(args)
    obstacles, self_collision = _scene(args.scene) if args.scene is not None else ([], True)
    t, joints = _recorded(args, units)
    check = check_recorded(robot, t, joints.q, obstacles=obstacles, self_collision=self_collision)
    for line in check.summary():
        print(line)
    if args.out is not None:
        for path in write_recorded(robot, check, args.out, obstacles=obstacles):
            print(f"wrote {path}")
    ok = check.within_limits and check.collision_free is not False
    if not ok:
        print("lynxplan: the recorded motion fails a check (see above)", file=sys.stderr)
    return 0 if ok else EXIT_CHECK_FAILED
