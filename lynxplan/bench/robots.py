"""Bench section ``robots``: IK of the built-in robots (round trips, throughput, latency) and
Pinocchio's CLIK on the same SO-101 poses.

Round trips: random configurations within the limits -> FK -> all-branch IK; a trip succeeds
when the start configuration is among the branches and every branch reaches the position to
1e-9 m. The same for position + approach targets with the roll free. The full run uses 1e6
trips per robot (the issue's count); ``--quick`` uses 1e4. Batch throughput: the median over
chunks of 50,000 trips (the mean over all of them is shown too).
Peers with conflicting requirements (placo needs pin 3.8) are not run in-process; EAIK (analytical
IK, :mod:`lynxplan.bench.eaik_peer`) is, on the same poses as lynxplan's batch. The targets are
the guards of issue 36 (:data:`GOALS`), shown in ``lynxplan bench robots``.
"""

from __future__ import annotations

import json
import subprocess
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from lynxplan.bench import Figure, median_seconds, meets, not_run, peer_missing
from lynxplan.bench.peers import peers_dir

if TYPE_CHECKING:
    from lynxplan.robots import Robot

#: Round trips per robot in the full and the quick run.
FULL_TRIPS, QUICK_TRIPS = 1_000_000, 10_000
#: Poses solved by the numerical fallback (other chains) in the full and the quick run.
NUMERICAL_TRIPS, NUMERICAL_QUICK_TRIPS = 2_000, 200
#: Position + approach round trips (roll free) per family robot in the full and the quick run.
FULL_APPROACH_TRIPS, QUICK_APPROACH_TRIPS = 100_000, 2_000
#: SO-101 full poses solved by both lynxplan and Pinocchio CLIK (zero start), full / quick.
FULL_PEER_POSES, QUICK_PEER_POSES = 1_000, 50
#: The guards of issue 36 (one core): robot -> figure -> target. "batch": full-pose batch IK
#: [poses/s], "single": one ``Robot.ik`` [us], "eaik": lynxplan's batch speed-up over EAIK's.
GOALS: dict[str, dict[str, str]] = {
    "so101": {"batch": ">= 2e6", "single": "<= 15", "eaik": ">= 5"},
    "al5": {"batch": ">= 6e6"},
}


def _warm_up(robot: object) -> None:
    """Solve a few poses first: a kernel's first call may compile it or load it from numba's
    cache, which is not the throughput measured (64 poses: the vectorised kernel of a batch)."""
    q = robot.random_configurations(64, seed=99)  # type: ignore[attr-defined]
    poses = robot.fk(q)  # type: ignore[attr-defined]
    poses[0, :3, 3] *= 5.0  # out of reach: the general kernel too
    robot.ik_batch(poses)  # type: ignore[attr-defined]


def _round_trips(robot: object, count: int, seed: int) -> tuple[float, float, float, float]:
    """(success fraction, worst position error [m], seconds per pose, the same over all trips)
    over ``count`` trips, in chunks of 50,000: the seconds per pose are the median over the
    chunks (the machine is shared: a chunk slowed by another job moves the mean, not the
    median), the last value their total over the count."""
    chunk = 50_000
    solved, worst, seconds = 0, 0.0, []
    _warm_up(robot)
    for start in range(0, count, chunk):
        q = robot.random_configurations(min(chunk, count - start), seed=seed + start)  # type: ignore[attr-defined]
        poses = robot.fk(q)  # type: ignore[attr-defined]
        begin = time.thread_time()
        batch = robot.ik_batch(poses)  # type: ignore[attr-defined]
        seconds.append(time.thread_time() - begin)
        gap = np.abs(batch.q - q[:, None, :]) % (2 * np.pi)
        gap = np.minimum(gap, 2 * np.pi - gap)
        found = np.where(batch.valid[..., None], gap, np.inf).max(axis=2).min(axis=1) < 1e-7
        errors = np.where(batch.valid, batch.position_error, 0.0).max(axis=1)
        solved += int(np.count_nonzero(found & (errors <= 1e-9)))
        worst = max(worst, float(errors.max()))
    sizes = np.diff([*range(0, count, chunk), count])
    per_pose = float(np.median(np.array(seconds) / sizes))
    return solved / count, worst, per_pose, sum(seconds) / count


def _approach_round_trips(robot: Robot, count: int, seed: int) -> tuple[float, float]:
    """(fraction, seconds per target) of position + approach targets with the roll free whose
    start configuration is among the branches: to 1e-7 rad, or to 1e-4 rad on a double root of
    the roll equation (there the branch found reaches the target to 1e-12 as well). A tool on
    the roll axis leaves the roll to the reference: the other joints are compared."""
    q = robot.random_configurations(count, seed=seed)
    poses = robot.fk(q)
    approach = np.einsum("nij,j->ni", poses[:, :3, :3], robot.approach_in_tool)
    robot.ik_batch(positions=poses[:64, :3, 3], approaches=approach[:64])
    begin = time.thread_time()
    batch = robot.ik_batch(positions=poses[:, :3, 3], approaches=approach)
    seconds = time.thread_time() - begin
    joints = 4 if robot.family is not None and robot.family.tool_on_roll_axis else 5
    gap = np.abs(batch.q[..., :joints] - q[:, None, :joints]) % (2 * np.pi)
    gap = np.minimum(gap, 2 * np.pi - gap).max(axis=2)
    gap = np.where(batch.valid, gap, np.inf)
    exact = (batch.position_error <= 1e-12) & (batch.orientation_error <= 1e-12)
    found = (gap < 1e-7).any(axis=1) | ((gap < 1e-4) & exact).any(axis=1)
    return float(found.mean()), seconds / count


#: Peers run in their own virtual environments: PEERS_DIR/<peer>/bin/python (placo, pink, mink,
#: ikpy; placo 0.10 needs pin 3.8, which conflicts with lynxplan's pin 4).
PEERS_DIR = str(peers_dir())
#: The peers, in the order of the table.
PEERS = ("placo", "pink", "mink", "ikpy")


def urdf_with_tool(robot: Robot) -> str | None:
    """The robot's URDF text with its tool frame added as a link, or None where it has one.

    A tool frame lynxplan defines itself (the SO-100's, between the jaws) or one named after a
    joint is no URDF link, so the peers cannot target it. The added link hangs on a fixed joint
    from the child link of the tool's parent joint: that link's frame is the joint's frame, in
    which Pinocchio places the tool (``frame.placement``). A base given to ``load_robot`` is not
    written.
    """
    import xml.etree.ElementTree as ET

    import pinocchio as pin

    root = ET.fromstring(robot.urdf_path.read_text())
    if any(link.get("name") == robot.tool_frame for link in root.iter("link")):
        return None
    frame = robot.model.frames[robot.tool_frame_id]
    parent_joint = str(robot.model.names[int(frame.parentJoint)])
    child_links = {
        joint.get("name"): child.get("link")
        for joint in root.iter("joint")
        if (child := joint.find("child")) is not None
    }
    parent_link = child_links.get(parent_joint)
    if parent_link is None:  # the tool is on the base: the root link's frame is the world's
        children = set(child_links.values())
        parent_link = next(
            str(link.get("name")) for link in root.iter("link") if link.get("name") not in children
        )
    joints = {joint.get("name") for joint in root.iter("joint")}
    joint_name = f"{robot.tool_frame}_joint"
    while joint_name in joints:
        joint_name += "_"
    placement = frame.placement
    ET.SubElement(root, "link", name=robot.tool_frame)
    joint = ET.SubElement(root, "joint", name=joint_name, type="fixed")
    ET.SubElement(joint, "parent", link=str(parent_link))
    ET.SubElement(joint, "child", link=robot.tool_frame)
    ET.SubElement(
        joint,
        "origin",
        xyz=" ".join(repr(float(v)) for v in placement.translation),
        rpy=" ".join(repr(float(v)) for v in pin.rpy.matrixToRpy(placement.rotation)),
    )
    return ET.tostring(root, encoding="unicode")


def _peer_urdf(robot: Robot, folder: Path) -> Path:
    """A URDF of ``robot`` with its tool frame as a link: its own, or a copy written to
    ``folder``."""
    text = urdf_with_tool(robot)
    if text is None:
        return robot.urdf_path
    path = folder / f"{robot.urdf_path.stem}_{robot.tool_frame}.urdf"
    path.write_text(text)
    return path


def _peers(robot: Robot, poses: np.ndarray, ours: float) -> list[Figure]:
    """Run each peer found in PEERS_DIR on the same poses (its own venv; JSON back)."""
    figures = []
    script = Path(__file__).with_name("peer_ik.py")
    with tempfile.TemporaryDirectory() as folder:
        poses_path = Path(folder) / "poses.npy"
        np.save(poses_path, poses)
        urdf = _peer_urdf(robot, Path(folder))
        for peer in PEERS:
            python = Path(PEERS_DIR) / peer / "bin" / "python"
            if not python.is_file():
                figures.append(peer_missing("robots", f"{robot.name} {peer}", python))
                continue
            out = Path(folder) / f"{peer}.json"
            args = [
                str(python),
                str(script),
                peer,
                str(urdf),
                robot.tool_frame,
                str(poses_path),
                str(out),
            ]
            done = subprocess.run(args, capture_output=True, text=True, timeout=3600, check=False)
            if done.returncode != 0 or not out.is_file():
                lines = (done.stderr or done.stdout or "no output").strip().splitlines()
                reason = lines[-1][:120] if lines else "no output"
                figures.append(not_run("robots", f"{robot.name} {peer}", f"peer failed: {reason}"))
                continue
            result = json.loads(out.read_text())
            name = f"{peer} {result['version']}"
            figures += [
                Figure(
                    "robots",
                    f"{robot.name} {name} success ({result['count']}, zero start)",
                    100 * result["success"],
                    "%",
                ),
                Figure(
                    "robots",
                    f"{robot.name} {name} median time per pose (wall)",
                    result["median_us"],
                    "us",
                ),
                Figure(
                    "robots",
                    f"{robot.name} lynxplan speed-up over {peer}",
                    result["median_us"] * 1e-6 / ours,
                    "x",
                ),
            ]
    return figures


def _robot_figures(robot: Robot, quick: bool, goals: bool) -> list[Figure]:
    """Round trips, batch throughput and single-pose latency of one robot; ``goals``: show the
    robot's targets (:data:`GOALS`)."""
    name = robot.name
    goal = GOALS.get(name, {}) if goals else {}
    if robot.family is None:  # the numerical fallback: ~1 ms a pose
        trips = NUMERICAL_QUICK_TRIPS if quick else NUMERICAL_TRIPS
        success, worst, per_pose = _verified_solves(robot, trips, seed=1)
        mean = None  # one batch: no chunks
        label = f"{name} random reachable poses solved and verified ({trips:,})"
    else:
        trips = QUICK_TRIPS if quick else FULL_TRIPS
        success, worst, per_pose, mean = _round_trips(robot, trips, seed=1)
        label = f"{name} round trips solved ({trips:,})"
    figures = [
        Figure("robots", label, 100 * success, "%", "100", success == 1.0),
        Figure(
            "robots", f"{name} worst branch position error", worst, "m", "<= 1e-9", worst <= 1e-9
        ),
        Figure(
            "robots",
            f"{name} batch IK (full pose, all branches; median over chunks)",
            1 / per_pose,
            "poses/s",
            goal.get("batch", ""),
            meets(1 / per_pose, goal["batch"]) if "batch" in goal else None,
        ),
    ]
    if mean is not None:
        figures.append(
            Figure("robots", f"{name} batch IK, mean over all round trips", 1 / mean, "poses/s")
        )
    if robot.family is not None:
        count = QUICK_APPROACH_TRIPS if quick else FULL_APPROACH_TRIPS
        found, per_target = _approach_round_trips(robot, count, seed=5)
        figures += [
            Figure(
                "robots",
                f"{name} approach targets, roll free: start branch found ({count:,})",
                100 * found,
                "%",
                "100",
                found == 1.0,
            ),
            Figure("robots", f"{name} approach-target IK (all branches)", per_target * 1e6, "us"),
        ]
    single = robot.fk(robot.random_configurations(1, seed=2))[0]
    repeats = 20 if robot.family is None else (200 if quick else 2000)
    seconds = median_seconds(lambda: robot.ik(single), repeats=5, number=repeats)
    figures.append(
        Figure(
            "robots",
            f"{name} single-pose IK",
            seconds * 1e6,
            "us",
            goal.get("single", ""),
            meets(seconds * 1e6, goal["single"]) if "single" in goal else None,
        )
    )
    return figures


def _verified_solves(robot: Robot, count: int, seed: int) -> tuple[float, float, float]:
    """(fraction reached exactly, worst position error [m], seconds per pose) of the IK of
    ``count`` FK poses of random configurations (a numerical solver need not return the start)."""
    poses = robot.fk(robot.random_configurations(count, seed=seed))
    _warm_up(robot)
    begin = time.thread_time()
    batch = robot.ik_batch(poses)
    seconds = time.thread_time() - begin
    exact = batch.valid & (batch.position_error <= 1e-9) & (batch.orientation_error <= 1e-9)
    errors = np.where(batch.valid, batch.position_error, 0.0)
    return float(exact.any(axis=1).mean()), float(errors.max()), seconds / count


def _comparison(robot: Robot, quick: bool, goals: bool = False) -> list[Figure]:
    """lynxplan, the peers (EAIK in this process) and Pinocchio's CLIK on the same full poses of
    ``robot``; ``goals``: show the issue's target of the speed-up over EAIK."""
    from lynxplan.arm.clik import solve_clik
    from lynxplan.bench import eaik_peer

    name = robot.name
    count = QUICK_PEER_POSES if quick else FULL_PEER_POSES
    poses = robot.fk(robot.random_configurations(count, seed=3))
    _warm_up(robot)
    batch = robot.ik_batch(poses)
    ours = median_seconds(lambda: robot.ik_batch(poses), repeats=5) / count
    ours_success = float(
        np.mean(
            batch.reachable
            & (np.where(batch.valid, batch.orientation_error, np.inf).min(axis=1) < 1e-9)
        )
    )
    zero = np.clip(np.zeros(robot.nq), robot.limits.lower, robot.limits.upper)
    begin = time.thread_time()
    clik = [solve_clik(robot.model, robot.data, robot.tool_frame_id, p, zero) for p in poses]
    clik_seconds = (time.thread_time() - begin) / count
    clik_success = float(np.mean([r.success for r in clik]))
    eaik_goal = GOALS.get(robot.name, {}).get("eaik", "") if goals else ""
    return [
        *_peers(robot, poses, ours),
        *eaik_peer.figures(robot, poses, ours, eaik_goal),
        Figure(
            "robots", f"{name} lynxplan IK success ({count} full poses)", 100 * ours_success, "%"
        ),
        Figure("robots", f"{name} lynxplan IK time per pose (all branches)", ours * 1e6, "us"),
        Figure(
            "robots",
            f"{name} Pinocchio CLIK success ({count}, zero start)",
            100 * clik_success,
            "%",
        ),
        Figure("robots", f"{name} Pinocchio CLIK time per pose", clik_seconds * 1e6, "us"),
        Figure("robots", f"{name} speed-up over Pinocchio CLIK", clik_seconds / ours, "x"),
    ]


def run(quick: bool) -> list[Figure]:
    """Measure the figures of the built-in robots, and the SO-101 against the peers."""
    from lynxplan.robots import load_robot

    figures: list[Figure] = []
    for name in ("al5", "so100", "so101"):
        figures += _robot_figures(load_robot(name), quick, goals=True)
    figures += _comparison(load_robot("so101"), quick, goals=True)
    return figures


def run_robot(robot: Robot, quick: bool) -> list[Figure]:
    """The figures of one robot (``lynxplan bench --robot/--urdf``), peers included."""
    return _robot_figures(robot, quick, goals=False) + _comparison(robot, quick)
