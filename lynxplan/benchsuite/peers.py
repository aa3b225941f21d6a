"""OMPL and pyroboplan on SmallArmBench problems, side by side with lynxplan.

Each peer runs from its own virtual environment (:mod:`lynxplan.bench.peers`: ``ompl`` and
``pyroboplan`` under ``LYNXPLAN_PEERS_DIR``), on the same start, goal configuration and boxes,
with a Pinocchio/coal collision model of the robot as lynxplan's (the URDF's collision meshes
found by lynxplan's mesh resolver and replaced by the same convex hulls, the same self pairs:
:func:`lynxplan.bench.peers.peer_urdf`; boolean checks at a joint resolution of
:data:`PEER_RESOLUTION`); its paths are checked by the same dense check as
lynxplan's. OMPL's validity checker is a Python callback: its share of OMPL's time and its
number of calls are reported. A peer that is not installed says so.
"""

from __future__ import annotations

import json
import subprocess
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.benchsuite.families import FAMILIES
from lynxplan.benchsuite.problem import Problem, suite_robot, yaw_rotation
from lynxplan.benchsuite.runner import TIME_LIMIT, ProblemResult, dense_check

#: Peers' joint resolution of edge checks, in [rad]; the issue's speed-up goal over OMPL.
PEER_RESOLUTION, GOAL_SPEEDUP = 0.005, 50.0
_SCRIPTS = {
    "ompl": Path(__file__).parent / "peer_scripts" / "ompl_timed.py",
    "pyroboplan": Path(__file__).parents[1] / "bench" / "peers" / "pyroboplan_rrt.py",
}


def _spec(problems: Sequence[Problem]) -> dict[str, Any]:
    """The peers' JSON problem set (its ``urdf`` is written by :func:`_run`)."""
    from lynxplan.bench.peers import self_pair_names

    return {
        "robot": problems[0].robot,
        "self_pairs": self_pair_names(suite_robot(problems[0].robot)),
        "seeds": [0],
        "resolution": PEER_RESOLUTION,
        "time_limit": TIME_LIMIT,
        "simplify": True,
        "problems": [
            {"name": p.name, "start": p.start.tolist(), "goals": [p.goal.tolist()],
             "obstacles": [{"name": n, "type": "box", "centre": c.tolist(), "size": s.tolist(),
                            "rotation": yaw_rotation(float(y)).tolist()}
                           for n, c, s, y in zip(p.names, p.centres, p.sizes, p.yaws,
                                                 strict=True)]}
            for p in problems
        ],
    }  # fmt: skip


def _run(peer: str, spec: dict[str, Any]) -> list[dict[str, Any]]:
    from lynxplan.bench.peers import peer_python, peer_urdf

    with tempfile.TemporaryDirectory() as folder:
        output = Path(folder) / "rows.json"
        urdf = peer_urdf(suite_robot(spec["robot"]), Path(folder))
        done = subprocess.run(
            [str(peer_python(peer)), str(_SCRIPTS[peer]), str(output)],
            input=json.dumps({**spec, "urdf": str(urdf)}), capture_output=True, text=True,
            check=False, timeout=7200,
        )  # fmt: skip
        if done.returncode != 0 or not output.is_file():
            tail = (done.stderr.strip().splitlines() or ["no output"])[-1][:200]
            raise RuntimeError(f"peer {peer} exited {done.returncode}: {tail}")
        rows: list[dict[str, Any]] = json.loads(output.read_text(encoding="utf-8"))
    return rows


def compare_peers(problems: Sequence[Problem], results: Sequence[ProblemResult]) -> dict[str, Any]:
    """Per robot, peer and family (then family "all"): solved, clean, median total, speed-up of
    lynxplan; for OMPL the callback's share of the time and its calls. ``lines`` (to print),
    ``misses`` (goals), ``figures`` and ``rows`` (per problem, without the path, with ``clean``)."""
    from lynxplan.bench.peers import peer_python

    out: dict[str, Any] = {"lines": [], "misses": [], "figures": [], "rows": []}
    by_name = {p.name: p for p in problems}
    for robot in sorted({p.robot for p in problems}):
        mine = [p for p in problems if p.robot == robot]
        for peer in _SCRIPTS:
            if not peer_python(peer).is_file():
                out["lines"].append(f"peer {peer}: peer not installed ({peer_python(peer)})")
                continue
            try:
                rows = _run(peer, _spec(mine))
            except (RuntimeError, subprocess.TimeoutExpired) as error:
                out["lines"].append(f"peer {peer} {robot}: could not run: {error}")
                continue
            rows = [_checked(peer, row, by_name[row["problem"]]) for row in rows]
            out["rows"] += rows
            families = [f for f in FAMILIES if any(p.family == f for p in mine)]
            for family in [*families, "all"]:
                picked = [r for r in rows if family in ("all", by_name[r["problem"]].family)]
                ours = [r.total_time for r in results if r.robot == robot and r.solved
                        and family in ("all", r.family)]  # fmt: skip
                figure = _figures(peer, robot, family, picked, _median(ours))
                out["figures"].append(figure)
                out["lines"].append(_line(figure))
            if peer == "ompl" and not figure["speedup"] >= GOAL_SPEEDUP:
                out["misses"].append(f"{robot}: {figure['speedup']:.1f}x the OMPL median "
                                     f"(goal >= {GOAL_SPEEDUP:g}x)")  # fmt: skip
    return out


def _median(values: Sequence[float]) -> float:
    return float(np.median(values)) if len(values) else float("nan")


def _checked(peer: str, row: dict[str, Any], problem: Problem) -> dict[str, Any]:
    """``row`` less its path, with ``peer``, ``family`` and ``clean`` (the dense check)."""
    path = np.array(row.pop("path"))
    solved = bool(row["solved"]) and len(path) > 1
    clean = solved and dense_check(suite_robot(problem.robot), problem, path) > 0.0
    return {**row, "peer": peer, "family": problem.family, "solved": solved, "clean": clean}


def _figures(peer: str, robot: str, family: str, rows: list[dict[str, Any]],
             lynx_median: float) -> dict[str, Any]:  # fmt: skip
    solved = [r for r in rows if r["solved"]]
    median = _median([r["plan_time"] + r["simplify_time"] for r in solved])
    figure = {"peer": peer, "robot": robot, "family": family, "problems": len(rows),
              "solved": len(solved), "clean": sum(r["clean"] for r in solved),
              "median_total": median, "lynxplan_median_total": lynx_median,
              "speedup": median / lynx_median}  # fmt: skip
    if peer == "ompl":
        spent = sum(r["plan_time"] + r["simplify_time"] for r in rows)
        figure["callback_share"] = sum(r["check_time"] for r in rows) / spent if spent else 0.0
        figure["median_checks"] = _median([r["checks"] for r in rows])
    return figure


def _line(f: dict[str, Any]) -> str:
    text = (f"peer {f['peer']:<10} {f['robot']:<6} {f['family']:<12} solved "
            f"{f['solved']}/{f['problems']}, clean {f['clean']}, median total "
            f"{f['median_total'] * 1e3:.2f} ms; lynxplan {f['speedup']:.1f}x faster")  # fmt: skip
    if "callback_share" in f:
        text += (f"; Python validity callback {100 * f['callback_share']:.0f} % of OMPL's time, "
                 f"median {f['median_checks']:.0f} checks/problem")  # fmt: skip
    return text
