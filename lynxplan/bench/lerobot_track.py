"""Continuity of tracked tool targets: lynxplan's ``track_targets`` against placo, LeRobot's IK.

    python -m lynxplan.bench.lerobot_track [--streams 20] [--fps 30]

Both solvers get the same seeded teleop-like streams (:mod:`lynxplan.lerobot.streams`: smooth
random joint paths through the SO-101's workspace, every other one pushed out of reach over
frames 30..55), the same 4x4 target poses, the same start (the path's first configuration) and
the same URDF (the built-in ``so101``, LeRobot's ``so101_new_calib.urdf`` limits). placo runs in
its own venv (``<peers dir>/placo``, :mod:`lynxplan.bench.peers`), one ``solve`` per frame with
LeRobot 0.4.4's weights (:mod:`lynxplan.bench.peers.placo_track`). Printed per solver: the
largest joint step of a frame, the frames stepping beyond the servo bound (the default
``max_velocity / fps`` of :mod:`lynxplan.lerobot.servo`), and the tool's distance to the
targets that were not pushed out of reach. A benchmark, not a test: it prints figures.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np

from lynxplan.bench.peers import peer_python
from lynxplan.lerobot.servo import DEFAULT_FPS, DEFAULT_MAX_VELOCITY
from lynxplan.lerobot.streams import TargetStream, target_stream

if TYPE_CHECKING:
    from lynxplan.robots.robot import Robot

#: LeRobot 0.4.4's ``RobotKinematics.inverse_kinematics`` defaults.
LEROBOT_POSITION_WEIGHT = 1.0
LEROBOT_ORIENTATION_WEIGHT = 0.01
#: Frames at the end of a stream over which the settled error is taken.
SETTLE_FRAMES = 10
#: A stream whose settled error is beyond this did not get back to its targets, in [m].
LOST = 1e-3


class TrackFigures(NamedTuple):
    """One solver on one stream."""

    max_step: float
    """Largest change of one joint in one frame (the first from the start), in [rad]."""
    over_bound: int
    """Frames with a joint step beyond the servo bound ``max_velocity / fps``."""
    error_median: float
    """Median tool-to-target distance over the frames not pushed out of reach, in [m]."""
    error_end: float
    """Largest tool-to-target distance over the last frames (back in reach), in [m]."""


def figures(robot: Robot, stream: TargetStream, q: np.ndarray, fps: float) -> TrackFigures:
    """The figures of commanded joint angles ``q`` (N, n) [rad] on ``stream``."""
    steps = np.abs(np.diff(np.vstack((stream.q[0], q)), axis=0)).max(axis=1)
    bound = DEFAULT_MAX_VELOCITY / fps
    distance = np.linalg.norm(np.asarray(robot.fk(q))[:, :3, 3] - stream.positions, axis=1)
    return TrackFigures(
        float(steps.max()),
        int((steps > bound * (1 + 1e-9)).sum()),
        float(np.median(distance[~stream.pushed])),
        float(distance[-SETTLE_FRAMES:].max()),
    )


def _urdf_without_shapes(robot: Robot, folder: Path) -> Path:
    """The robot's URDF without <visual>/<collision> (placo's loader resolves no ``package://``
    meshes, and IK needs none)."""
    text = Path(robot.urdf_path).read_text(encoding="utf-8")
    path = folder / "robot.urdf"
    path.write_text(re.sub(r"<(visual|collision)\b.*?</\1>", "", text, flags=re.S), "utf-8")
    return path


def run_placo(
    robot: Robot, streams: list[TargetStream], python: Path, *, update_before_solve: bool = False
) -> dict[str, Any]:
    """placo's frames of every stream (its venv's ``python``): ``{"version", "streams": [{"q",
    "fk"}]}``; ``update_before_solve``: the variant that updates placo's kinematics at the joints
    set before solving (LeRobot does not). Raises ``RuntimeError`` with placo's stderr when it
    fails."""
    script = Path(__file__).parent / "peers" / "placo_track.py"
    with tempfile.TemporaryDirectory() as folder:
        spec = {
            "urdf": str(_urdf_without_shapes(robot, Path(folder))),
            "tool": robot.tool_frame,
            "joints": list(robot.joint_names),
            "position_weight": LEROBOT_POSITION_WEIGHT,
            "orientation_weight": LEROBOT_ORIENTATION_WEIGHT,
            "update_before_solve": update_before_solve,
            "streams": [{"start": s.q[0].tolist(), "poses": s.poses.tolist()} for s in streams],
        }
        out = Path(folder) / "out.json"
        done = subprocess.run(
            [str(python), str(script), str(out)],
            input=json.dumps(spec),
            check=False,
            capture_output=True,
            text=True,
            timeout=600,
        )
        if done.returncode != 0:
            raise RuntimeError(f"placo peer failed: {done.stderr[-2000:]}")
        result: dict[str, Any] = json.loads(out.read_text())
    return result


def run_lynxplan(robot: Robot, stream: TargetStream, fps: float) -> np.ndarray:
    """lynxplan's frames of ``stream``: :func:`~lynxplan.lerobot.track_targets` on its points,
    pitches and rolls (the 5-joint arm's targets), shape (N, n), in [rad]."""
    from lynxplan.lerobot import lerobot_units, track_targets

    track = track_targets(
        robot,
        lerobot_units(robot),
        positions=stream.positions,
        pitches=stream.pitches,
        rolls=stream.rolls,
        start=stream.q[0],
        fps=fps,
    )
    return np.asarray(track.q)


def _row(name: str, rows: list[TrackFigures]) -> str:
    steps = np.degrees([r.max_step for r in rows])
    over = sum(r.over_bound for r in rows)
    median = 1e3 * np.median([r.error_median for r in rows])
    end = 1e3 * max(r.error_end for r in rows)
    lost = sum(r.error_end > LOST for r in rows)
    return (
        f"| {name} | {steps.max():.1f} | {np.median(steps):.1f} | {over} | {median:.2f} | "
        f"{end:.2f} | {lost} |"
    )


def main(argv: list[str] | None = None) -> None:
    import lynxplan

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--streams", type=int, default=20, help="streams (half out of reach)")
    parser.add_argument("--fps", type=float, default=DEFAULT_FPS, help="frames per second")
    args = parser.parse_args(argv)
    robot = lynxplan.load_robot("so101")
    streams = [
        target_stream(robot, seed, out_of_reach=seed % 2 == 1, fps=args.fps)
        for seed in range(args.streams)
    ]
    python = peer_python("placo")
    if not python.is_file():
        raise SystemExit(f"placo peer not installed: no {python} (see lynxplan.bench.peers)")
    ours = [figures(robot, s, run_lynxplan(robot, s, args.fps), args.fps) for s in streams]
    solvers: dict[str, list[TrackFigures]] = {"lynxplan track_targets": ours}
    fk_gap = 0.0
    for update in (False, True):
        placo = run_placo(robot, streams, python, update_before_solve=update)
        name = f"placo {placo['version']}" + (", updated before solve" if update else " as LeRobot")
        solvers[name] = []
        for stream, result in zip(streams, placo["streams"], strict=True):
            q = np.asarray(result["q"])
            fk_gap = max(fk_gap, float(np.abs(np.asarray(robot.fk(q)) - result["fk"]).max()))
            solvers[name].append(figures(robot, stream, q, args.fps))
    _print(solvers, streams, args.fps, fk_gap)


def _print(
    solvers: dict[str, list[TrackFigures]], streams: list[TargetStream], fps: float, gap: float
) -> None:
    bound = np.degrees(DEFAULT_MAX_VELOCITY / fps)
    print(
        f"{len(streams)} streams x {len(streams[0].q)} frames at {fps:g} fps; servo bound "
        f"{bound:.2f} deg/frame; placo's FK - lynxplan's FK: {gap:.1e}"
    )
    print(
        "| solver | max step [deg] | median of max steps [deg] | frames over bound | "
        "median error in reach [mm] | error at end, worst [mm] | streams not back |"
    )
    print("|---|---|---|---|---|---|---|")
    for label, keep in (("in reach", False), ("pushed out of reach", True)):
        pick = [i for i, s in enumerate(streams) if s.pushed.any() == keep]
        for name, rows in solvers.items():
            print(_row(f"{name}, {label} ({len(pick)})", [rows[i] for i in pick]))


if __name__ == "__main__":
    main()
