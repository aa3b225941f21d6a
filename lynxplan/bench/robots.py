"""Bench section ``robots``: IK of the built-in robots (round trips, throughput, latency) and
Pinocchio's CLIK on the same SO-101 poses.

Round trips: random configurations within the limits -> FK -> all-branch IK; a trip succeeds
when the start configuration is among the branches and every branch reaches the position to
1e-9 m. The full run uses 1e6 trips per robot (the issue's count); ``--quick`` uses 1e4.
Peers with conflicting requirements (placo needs pin 3.8) are not run in-process.
"""

from __future__ import annotations

import json
import os
import subprocess
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from lynxplan.bench import Figure, median_seconds

if TYPE_CHECKING:
    from lynxplan.robots import Robot

#: Round trips per robot in the full and the quick run.
FULL_TRIPS, QUICK_TRIPS = 1_000_000, 10_000
#: SO-101 full poses solved by both lynxplan and Pinocchio CLIK (zero start), full / quick.
FULL_PEER_POSES, QUICK_PEER_POSES = 1_000, 50


def _round_trips(robot: object, count: int, seed: int) -> tuple[float, float, float]:
    """(success fraction, worst position error [m], seconds per pose) over ``count`` trips."""
    chunk = 50_000
    solved, worst, seconds = 0, 0.0, 0.0
    for start in range(0, count, chunk):
        q = robot.random_configurations(min(chunk, count - start), seed=seed + start)  # type: ignore[attr-defined]
        poses = robot.fk(q)  # type: ignore[attr-defined]
        begin = time.thread_time()
        batch = robot.ik_batch(poses)  # type: ignore[attr-defined]
        seconds += time.thread_time() - begin
        gap = np.abs(batch.q - q[:, None, :])
        gap = np.minimum(gap, 2 * np.pi - gap % (2 * np.pi))
        found = np.where(batch.valid[..., None], gap, np.inf).max(axis=2).min(axis=1) < 1e-7
        errors = np.where(batch.valid, batch.position_error, 0.0).max(axis=1)
        solved += int(np.count_nonzero(found & (errors <= 1e-9)))
        worst = max(worst, float(errors.max()))
    return solved / count, worst, seconds / count


#: Peers run in their own virtual environments: PEERS_DIR/<peer>/bin/python (placo, pink, ikpy;
#: placo 0.10 needs pin 3.8, which conflicts with lynxplan's pin 4).
PEERS_DIR = os.environ.get("LYNXPLAN_PEERS_DIR", "/work/peers")


def _peers(robot: Robot, poses: np.ndarray, ours: float) -> list[Figure]:
    """Run each peer found in PEERS_DIR on the same poses (its own venv; JSON back)."""
    figures = []
    script = Path(__file__).with_name("peer_ik.py")
    with tempfile.TemporaryDirectory() as folder:
        poses_path = Path(folder) / "poses.npy"
        np.save(poses_path, poses)
        for peer in ("placo", "pink", "ikpy"):
            python = Path(PEERS_DIR) / peer / "bin" / "python"
            if not python.is_file():
                continue
            out = Path(folder) / f"{peer}.json"
            args = [
                str(python),
                str(script),
                peer,
                str(robot.urdf_path),
                robot.tool_frame,
                str(poses_path),
                str(out),
            ]
            done = subprocess.run(args, capture_output=True, text=True, timeout=3600, check=False)
            if done.returncode != 0 or not out.is_file():
                continue
            result = json.loads(out.read_text())
            name = f"{peer} {result['version']}"
            figures += [
                Figure(
                    "robots",
                    f"so101 {name} success ({result['count']}, zero start)",
                    100 * result["success"],
                    "%",
                ),
                Figure(
                    "robots", f"so101 {name} median time per pose (wall)", result["median_us"], "us"
                ),
                Figure(
                    "robots",
                    f"so101 lynxplan speed-up over {peer}",
                    result["median_us"] * 1e-6 / ours,
                    "x",
                ),
            ]
    return figures


def run(quick: bool) -> list[Figure]:
    """Measure the robot figures."""
    from lynxplan.arm.clik import solve_clik
    from lynxplan.robots import load_robot

    figures: list[Figure] = []
    trips = QUICK_TRIPS if quick else FULL_TRIPS
    for name in ("al5", "so100", "so101"):
        robot = load_robot(name)
        success, worst, per_pose = _round_trips(robot, trips, seed=1)
        figures += [
            Figure(
                "robots",
                f"{name} round trips solved ({trips:,})",
                100 * success,
                "%",
                "100",
                success == 1.0,
            ),
            Figure(
                "robots",
                f"{name} worst branch position error",
                worst,
                "m",
                "<= 1e-9",
                worst <= 1e-9,
            ),
            Figure(
                "robots",
                f"{name} batch IK (full pose, all branches)",
                1 / per_pose,
                "poses/s",
                ">= 3e6" if name == "so101" else "",
                None if name != "so101" else 1 / per_pose >= 3e6,
            ),
        ]
        single = robot.fk(robot.random_configurations(1, seed=2))[0]

        def solve_one(r: object = robot, p: np.ndarray = single) -> object:
            return r.ik(p)  # type: ignore[attr-defined]

        seconds = median_seconds(solve_one, repeats=5, number=200 if quick else 2000)
        figures.append(
            Figure(
                "robots",
                f"{name} single-pose IK",
                seconds * 1e6,
                "us",
                "<= 20" if name == "so101" else "",
                None if name != "so101" else seconds * 1e6 <= 20,
            )
        )

    robot = load_robot("so101")
    count = QUICK_PEER_POSES if quick else FULL_PEER_POSES
    poses = robot.fk(robot.random_configurations(count, seed=3))
    begin = time.thread_time()
    batch = robot.ik_batch(poses)
    ours = (time.thread_time() - begin) / count
    ours_success = float(
        np.mean(
            batch.reachable
            & (np.where(batch.valid, batch.orientation_error, np.inf).min(axis=1) < 1e-9)
        )
    )
    zero = np.zeros(robot.nq)
    begin = time.thread_time()
    clik = [solve_clik(robot.model, robot.data, robot.tool_frame_id, p, zero) for p in poses]
    clik_seconds = (time.thread_time() - begin) / count
    clik_success = float(np.mean([r.success for r in clik]))
    figures += _peers(robot, poses, ours)
    figures += [
        Figure(
            "robots", f"so101 lynxplan IK success ({count} full poses)", 100 * ours_success, "%"
        ),
        Figure("robots", "so101 lynxplan IK time per pose (all branches)", ours * 1e6, "us"),
        Figure(
            "robots", f"so101 Pinocchio CLIK success ({count}, zero start)", 100 * clik_success, "%"
        ),
        Figure("robots", "so101 Pinocchio CLIK time per pose", clik_seconds * 1e6, "us"),
        Figure("robots", "so101 speed-up over Pinocchio CLIK", clik_seconds / ours, "x"),
    ]
    return figures
