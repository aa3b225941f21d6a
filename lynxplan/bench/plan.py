"""Bench section ``plan``: planning time on the AL5 problem suite, against OMPL and pyroboplan.

lynxplan: :class:`lynxplan.planning.Planner` built once per problem (collision world, compiled
checker), then ``solve`` per seed; the time is RRT-Connect + shortcutting + exact verification
(wall clock, :attr:`PlanningStats.solve_time`), the path length is in joint space [rad].

Peers, on the same problems (same URDF collision model and obstacles, same start and goal
configurations), each in its own virtual environment (see :mod:`lynxplan.bench.peers`):

- OMPL 2.x RRTConnect through its Python bindings, state validity checking resolution
  ``PEER_RESOLUTION`` [rad], a Python validity callable on ``pinocchio.computeCollisions``,
  then ``simplifySolution``;
- pyroboplan ``RRTPlanner`` (RRT-Connect, bidirectional), edge step ``PEER_RESOLUTION``, then
  ``shortcut_path``.

Every returned path (lynxplan's and the peers') is checked with lynxplan's exact verification
(coal, certified between waypoints): a path is *clean* when nothing touches. The peers plan with
zero clearance (boolean collision checks); lynxplan keeps its required clearance (2 mm).
"""

from __future__ import annotations

import json
import subprocess
import time
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.bench import Figure, not_run, peer_missing
from lynxplan.bench.peers import peer_python
from lynxplan.shipped import scenario_path

#: Edge resolution of the peers, in [rad] (the issue's clean-path resolution).
PEER_RESOLUTION = 0.005
#: Peer planning time limit per query, in [s].
PEER_TIME_LIMIT = 2.0
#: Issue goals: median and p95 planning time of lynxplan, in [s]; speed-up over OMPL.
TARGET_MEDIAN, TARGET_P95, TARGET_SPEEDUP = 1e-3, 10e-3, 50.0
PEERS = {"ompl": "ompl_rrtconnect.py", "pyroboplan": "pyroboplan_rrt.py"}


def _suite() -> list[tuple[str, Any]]:
    """The solvable AL5 problems of the suite (the issue's goals and the peers' problems are
    on the AL5; problems of other robots are run by the tests)."""
    from lynxplan.scenarios import load_scenario
    from lynxplan.scenarios.plan import plan_inputs

    problems = []
    for path in sorted(scenario_path("planning").glob("*.yaml")):
        scenario: Any = load_scenario(path).scenario
        robot = scenario.robot
        if robot.urdf is not None or robot.name not in (None, "al5"):
            continue
        inputs = plan_inputs(scenario)
        if inputs.solvable:
            problems.append((scenario.name, inputs))
    return problems


def _obstacle_json(obstacle: Any) -> dict[str, Any]:
    entry: dict[str, Any] = {
        "name": obstacle.name,
        "centre": np.asarray(obstacle.centre).tolist(),
        "rotation": np.asarray(obstacle.rotation).tolist(),
    }
    if hasattr(obstacle, "size"):
        entry.update(type="box", size=np.asarray(obstacle.size).tolist())
    elif hasattr(obstacle, "length"):
        entry.update(type="cylinder", radius=obstacle.radius, length=obstacle.length)
    else:
        entry.update(type="sphere", radius=obstacle.radius)
    return entry


def _run_peer(name: str, spec: dict[str, Any]) -> list[dict[str, Any]]:
    """The peer's results on the problems of ``spec``.

    Raises:
        RuntimeError: the peer failed (its last stderr line is quoted).
    """
    import tempfile

    script = Path(__file__).parent / "peers" / PEERS[name]
    with tempfile.TemporaryDirectory() as folder:
        output = Path(folder) / "results.json"
        done = subprocess.run(
            [str(peer_python(name)), str(script), str(output)],
            input=json.dumps(spec),
            capture_output=True,
            text=True,
            check=False,
            timeout=3600,
        )
        if done.returncode != 0 or not output.is_file():
            tail = (done.stderr.strip().splitlines() or ["no output"])[-1][:200]
            raise RuntimeError(f"exited {done.returncode}: {tail}")
        result: list[dict[str, Any]] = json.loads(output.read_text(encoding="utf-8"))
    return result


def _clean(world: Any, path: list[list[float]]) -> bool:
    from lynxplan.exceptions import PathVerificationError
    from lynxplan.planning.verify import verify_path

    try:
        return verify_path(world, np.array(path), 0.0).collision_free
    except PathVerificationError:
        return False


def _figures(
    label: str, times: list[float], solved: int, total: int, lengths: list[float], clean: int
) -> list[Figure]:
    array = np.array(times) if times else np.array([np.nan])
    median, p95 = float(np.median(array)), float(np.percentile(array, 95))
    is_lynxplan = label == "lynxplan"
    return [
        Figure("plan", f"{label}: median planning time", median * 1e3, "ms",
               target=f"<= {TARGET_MEDIAN * 1e3:g}" if is_lynxplan else "",
               met=median <= TARGET_MEDIAN if is_lynxplan else None),
        Figure("plan", f"{label}: p95 planning time", p95 * 1e3, "ms",
               target=f"<= {TARGET_P95 * 1e3:g}" if is_lynxplan else "",
               met=p95 <= TARGET_P95 if is_lynxplan else None),
        Figure("plan", f"{label}: success", 100.0 * solved / max(total, 1), "%",
               target=">= 99" if is_lynxplan else "",
               met=solved >= 0.99 * total if is_lynxplan else None),
        Figure("plan", f"{label}: clean paths (exact check, no contact)",
               100.0 * clean / max(solved, 1), "%"),
        Figure("plan", f"{label}: median path length", float(np.median(lengths or [np.nan])),
               "rad"),
    ]  # fmt: skip


def run(quick: bool) -> list[Figure]:
    """lynxplan on the suite (20 seeds, 5 quick), then the peers (5 seeds, 2 quick)."""
    from lynxplan.planning import Planner
    from lynxplan.planning.problem import goal_configurations
    from lynxplan.planning.verify import closest_contact

    seeds = range(5 if quick else 20)
    peer_seeds = list(range(2 if quick else 5))
    times: list[float] = []
    calls: list[float] = []  # the whole solve() call: what a user of plan() waits for
    lengths: list[float] = []
    ratios: list[float] = []
    solved = total = clean = 0
    spec: dict[str, Any] = {
        "problems": [],
        "seeds": peer_seeds,
        "resolution": PEER_RESOLUTION,
        "time_limit": PEER_TIME_LIMIT,
    }
    worlds = {}
    suite = _suite()
    if not suite:
        raise RuntimeError(f"no solvable AL5 problem in {scenario_path('planning')}")
    for name, inputs in suite:
        planner = Planner(inputs.robot, inputs.obstacles, inputs.options)
        planner.solve(inputs.start, inputs.goal, seed=0, time_limit=inputs.time_limit)  # JIT
        per_seed = []
        for seed in seeds:
            total += 1
            began = time.perf_counter()
            trajectory = planner.solve(
                inputs.start, inputs.goal, seed=seed, time_limit=inputs.time_limit
            )
            calls.append(time.perf_counter() - began)
            solved += 1
            clean += trajectory.verification.collision_free
            times.append(trajectory.stats.solve_time)
            per_seed.append(trajectory.path_length)
        lengths += per_seed
        ratios.append(float(np.median(per_seed) / np.min(per_seed)))
        goals = goal_configurations(inputs.robot, planner.space, inputs.goal).configurations
        free = [g.tolist() for g in goals if closest_contact(planner.world, g)[0] > 0]
        spec["urdf"] = str(inputs.robot.urdf_path)
        spec["problems"].append(
            {
                "name": name,
                "start": inputs.start.tolist(),
                "goals": free,
                "obstacles": [_obstacle_json(o) for o in inputs.obstacles],
            }
        )
        worlds[name] = planner.world
    figures = _figures("lynxplan", times, solved, total, lengths, clean)
    figures.append(Figure("plan", "lynxplan: median path length / best of the seeds",
                          float(np.median(ratios)), "x", target="<= 1.2",
                          met=float(np.median(ratios)) <= 1.2))  # fmt: skip
    figures.append(Figure("plan", "lynxplan: median whole solve() call (start/goal checks, IK "
                          "goals, plan, shortcut, verify, ruckig timing)",
                          float(np.median(calls)) * 1e3, "ms"))  # fmt: skip
    return figures + _peer_figures(spec, worlds, times)


def _peer_figures(spec: dict[str, Any], worlds: dict[str, Any], times: list[float]) -> list[Figure]:
    """Each peer on the problems of ``spec`` (its paths checked in ``worlds``), against
    lynxplan's planning ``times``; a peer not installed or failing says so."""
    figures: list[Figure] = []
    for peer in PEERS:
        if not peer_python(peer).is_file():
            figures.append(peer_missing("plan", peer, peer_python(peer)))
            continue
        try:
            results = _run_peer(peer, {**spec, "simplify": True})
        except (RuntimeError, subprocess.TimeoutExpired, ValueError) as error:
            figures.append(not_run("plan", peer, f"peer {peer} failed: {error}"))
            continue
        ok = [r for r in results if r["solved"] and np.ndim(r["path"]) == 2 and len(r["path"]) > 1]
        peer_times = [r["plan_time"] + r["simplify_time"] for r in ok]
        peer_lengths = [float(np.linalg.norm(np.diff(r["path"], axis=0), axis=1).sum())
                        for r in ok]  # fmt: skip
        peer_clean = sum(_clean(worlds[r["problem"]], r["path"]) for r in ok)
        figures += _figures(f"{peer} (+simplify)", peer_times, len(ok), len(results),
                            peer_lengths, peer_clean)  # fmt: skip
        speedup = float(np.median(peer_times) / np.median(times)) if peer_times else float("nan")
        is_ompl = peer == "ompl"
        figures.append(Figure("plan", f"speed-up of lynxplan over {peer} (median times)", speedup,
                              "x", target=f">= {TARGET_SPEEDUP:g}" if is_ompl else "",
                              met=speedup >= TARGET_SPEEDUP if is_ompl else None))  # fmt: skip
    return figures
