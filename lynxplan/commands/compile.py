"""``lynxplan compile``: compile every numba kernel once, ahead of the first run.

numba compiles lynxplan's kernels on their first use and keeps them in its on-disk cache (next
to the sources, or under ``NUMBA_CACHE_DIR``). The first run after an installation waits for
that compile (minutes on a small machine). ``lynxplan compile`` runs one small workload per
area of the library (the scenario kinds with both shipped robots, the IK entry points with
every argument type the library passes them), so that later runs only load the kernels: for a
Dockerfile after ``pip install``, or once after installation. Running it again loads the
kernels from the cache and takes seconds. The workloads are written here (the repository's
``scenarios/`` folder is not part of an installed package).
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from typing import Any

from lynxplan import _jit, guards
from lynxplan.commands._output import parse_finite

_WALL = {"name": "wall", "type": "box", "centre": [0.0, 0.25, 0.04], "size": [0.12, 0.12, 0.26]}
_TABLE = {"name": "table", "type": "box", "centre": [0.0, 0.1, -0.105], "size": [0.9, 0.7, 0.03]}
_CHECKS = {"collision_free": True, "within_limits": True}
#: What the shipped plan scenarios check (the clearance and duration metrics run kernels too).
_PLAN_CHECKS = {**_CHECKS, "solved": True, "min_clearance": ">= 1 mm", "max_duration": "<= 60 s"}

#: Small scenarios, one per kind and robot: their runs compile the kernels the kinds use.
SCENARIOS: dict[str, dict[str, Any]] = {
    "trajectory (AL5)": {
        "kind": "trajectory", "units": {"length": "in", "angle": "deg"},
        "start": [120, 0, 0, 0, 0], "sample_rate": 100,
        "segments": [{"motion": "line", "to_q": [75, 30, -30, 0, 0],
                      "orientation": "consistent", "tt": 1.0, "ta": 0.3}],
    },
    "plan (AL5)": {
        "kind": "plan", "units": {"length": "m", "angle": "deg"}, "robot": {},
        "obstacles": [_TABLE, _WALL], "start": [30, 45, -70, 90, 0],
        "goal": {"q": [150, 45, -70, 90, 0]}, "planner": {"seed": 0, "time_limit": 30.0},
        "expect": _PLAN_CHECKS,
    },
    "plan (SO-101)": {
        "kind": "plan", "units": {"length": "m", "angle": "deg"}, "robot": {"name": "so101"},
        "obstacles": [
            {"name": "table", "type": "box", "centre": [0.2, 0.0, -0.02], "size": [0.5, 0.6, 0.02]},
            {"name": "wall", "type": "box", "centre": [0.23, 0.0, 0.06],
             "size": [0.14, 0.02, 0.12]},
        ],
        "start": [38.9, 4.3, 5.4, 80.3, -90],
        "goal": {"position": [0.2, 0.12, 0.05], "approach": [0, 0, -1]},
        "planner": {"seed": 0, "time_limit": 30.0}, "expect": _PLAN_CHECKS,
    },
    "task (AL5)": {
        "kind": "task", "units": {"length": "in", "angle": "deg"}, "robot": {},
        "sample_rate": 200, "timing": {"tt": 1.0, "ta": 0.25},
        "obstacles": [{"name": "wall", "type": "box", "min_corner": [5, 4.5, -2],
                       "size": [10, 1, 8]}],
        "waypoints": {"A": {"q": [104, 57, -59, 40, 0]}, "B": {"q": [109, 79, -93, 25, 0]},
                      "C": {"q": [90, 90, -30, 0, 0]}},
        "segments": [{"from": "A", "to": "B", "motion": "line"}, {"to": "C", "motion": "free"}],
        "expect": _CHECKS,
    },
    "task (SO-101)": {
        "kind": "task", "units": {"length": "mm", "angle": "deg"}, "robot": {"name": "so101"},
        "sample_rate": 200, "timing": {"tt": 1.0, "ta": 0.25}, "self_collision": True,
        "obstacles": [{"name": "wall", "type": "box", "min_corner": [290, -120, 0],
                       "size": [20, 240, 120]}],
        "waypoints": {
            "H": {"q": [0, -60, 60, 60, -90]},
            "A": {"position": [170, 50, 60], "approach": [0, 0, -1], "ik": "nearest",
                  "q_reference": [0, 0, 0, 0, -90]},
            "B": {"position": [240, 50, 60], "approach": [0, 0, -1], "ik": "nearest",
                  "q_reference": [0, 0, 0, 0, -90]},
        },
        "segments": [{"from": "H", "to": "A", "motion": "free"}, {"to": "B", "motion": "line"}],
        "expect": _CHECKS,
    },
    "singularity (AL5)": {
        "kind": "singularity", "units": {"length": "mm", "angle": "deg"},
        "task": "position_pitch",
        "line": {"start": [110.0, 1.0, 380.0], "end": [-110.0, 1.0, 380.0], "pitch": 180.0},
        "timing": {"duration": 2.0, "blend": 0.5, "hold": 0.5},
        "q_reference": [0.0, 90.0, -40.0, 130.0, 0.0], "control": {"dt": 0.01, "gain": 1.0},
        "tr": {"m_bar_fraction": 0.05, "sigma_fraction": 0.05, "k_r": 20.0},
        "dls": {"lambda_max": 0.02, "lambda_min": 0.0001},
    },
    "parallel robot": {
        "kind": "parallel_ik", "units": {"length": "mm", "angle": "deg"}, "pose": [260, 180, 30],
    },
    "parallel workspace": {
        "kind": "parallel_workspace", "units": {"length": "mm", "angle": "deg"}, "alphas": [20],
        "step": 10, "region": {"x": [70, 420], "y": [0, 320]}, "loci_mode": "+++",
    },
    "workspace (AL5)": {
        "kind": "workspace", "units": {"length": "in", "angle": "deg"}, "samples": 20_000,
        "cell": 0.4, "voxel_size": 1.0, "seed": 0, "report_grid": False,
    },
}  # fmt: skip


def _al5_ik() -> None:
    """The AL5's IK entry points with the argument types the library passes them."""
    import numpy as np

    import lynxplan
    from lynxplan.arm import Arm
    from lynxplan.arm.ik import solve_ik_batch

    arm = Arm()
    q = np.radians([30.0, 60.0, -45.0, 45.0, 10.0])
    pose = arm.fk(q)
    pose.setflags(write=False)  # the library's results are read-only
    arm.ik(pose)
    arm.ik(pose, q_reference=q, limit_tolerance=0.0)
    batch = np.stack([pose, pose])
    solve_ik_batch(batch)
    solve_ik_batch(batch, q_reference=q, limit_tolerance=0.0)
    batch.setflags(write=False)
    solve_ik_batch(batch)
    lynxplan.load_robot("al5").ik(position=pose[:3, 3], pitch=1.0)  # the roll search


def _so101_ik() -> None:
    """The SO-101's (URDF family) IK entry points: one pose, a batch, position and approach."""
    import numpy as np

    import lynxplan

    robot = lynxplan.load_robot("so101")
    rng = np.random.default_rng(1)
    poses = robot.fk(rng.uniform(robot.limits.lower, robot.limits.upper, size=(50, 5)))
    poses.setflags(write=False)
    robot.ik(poses[0])
    robot.ik_batch(poses)
    robot.ik_batch(np.array(poses))
    robot.ik(position=poses[0, :3, 3], approach=poses[0, :3, 2])


def _scenario(data: dict[str, Any]) -> Callable[[], None]:
    def run() -> None:
        from lynxplan.scenarios import run_scenario

        run_scenario({"name": "compile", **data}, None, quick=True)

    return run


#: The stages of ``lynxplan compile``, in order: (what, workload).
STAGES: tuple[tuple[str, Callable[[], None]], ...] = (
    ("IK (AL5)", _al5_ik),
    ("IK (SO-101)", _so101_ik),
    *((name, _scenario(data)) for name, data in SCENARIOS.items()),
)


#: The stages that compile most (descending: 135, 131, 38, 16 and 6 s of CPU on the 2-core
#: machine, 2026-12-07), and little in common: with ``--jobs`` above 1 they run in parallel
#: processes first; the other stages then mostly load what these compiled.
HEAVY = ("IK (SO-101)", "plan (AL5)", "IK (AL5)", "singularity (AL5)", "parallel robot")


def _run_stage(what: str) -> float:
    """Run the stage named ``what`` (in a worker process); returns its seconds."""
    started = time.perf_counter()
    dict(STAGES)[what]()
    return time.perf_counter() - started


def register(subparsers: Any) -> None:
    """Add the ``compile`` sub-command."""
    parser = subparsers.add_parser(
        "compile",
        help="compile every numba kernel once (first runs then start in seconds)",
        description="Compile lynxplan's numba kernels into numba's on-disk cache (next to the "
        "sources, or under NUMBA_CACHE_DIR): for a Dockerfile after `pip install`, or once "
        "after installation. Idempotent: a second run loads the kernels and takes seconds.",
    )
    parser.add_argument(
        "--jobs",
        metavar="N",
        help="processes compiling at once (default: the CPU count, at most "
        f"{len(HEAVY)}; about 1 GB of memory each)",
    )
    parser.set_defaults(handler=handle)


def _jobs(text: str | None) -> int:
    if text is None:
        return max(1, min(os.cpu_count() or 1, len(HEAVY)))
    return guards.count("--jobs", parse_finite(text, "--jobs"), minimum=1, limit=64)


def handle(args: argparse.Namespace) -> int:
    """Run every stage under a progress bar (stderr); one summary line on stdout. With more than
    one job, the :data:`HEAVY` stages first, in that many processes, then the others here."""
    from rich.console import Console
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    jobs = _jobs(args.jobs)
    _jit.disable_notices()  # the progress bar says it
    console = Console(stderr=True)
    began = time.perf_counter()
    columns = (TextColumn("compiling {task.description:<22}"), BarColumn(),
               TextColumn("{task.completed}/{task.total}"), TimeElapsedColumn())  # fmt: skip
    with Progress(*columns, console=console, transient=not console.is_terminal) as progress:
        task = progress.add_task("", total=len(STAGES))

        def done(what: str, seconds: float) -> None:
            progress.advance(task)
            if not console.is_terminal:  # a build log: one line per stage
                console.print(f"compiled {what} ({seconds:.1f} s)")

        first = HEAVY if jobs > 1 else ()
        if first:
            progress.update(task, description=f"{len(first)} stages in {jobs} processes")
            context = multiprocessing.get_context("spawn")
            with ProcessPoolExecutor(max_workers=jobs, mp_context=context) as pool:
                running = {pool.submit(_run_stage, what): what for what in first}
                for future in as_completed(running):
                    done(running[future], future.result())
        for what, stage in STAGES:
            if what in first:
                continue
            progress.update(task, description=what)
            started = time.perf_counter()
            stage()
            done(what, time.perf_counter() - started)
    cold = _jit.cold_kernels()
    seconds = time.perf_counter() - began
    where = _jit.cache_folder()
    print(f"lynxplan: kernels compiled in {seconds:.0f} s (numba cache: {where})")
    if cold:  # a kernel that the workloads above no longer reach: a bug in this module
        print(f"lynxplan: not compiled: {', '.join(cold)}")
        return 3
    return 0
