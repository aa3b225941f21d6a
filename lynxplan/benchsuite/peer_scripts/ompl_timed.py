"""Peer: OMPL RRTConnect + simplifySolution, its Python validity callback timed and counted.

Run by the OMPL venv's python (see lynxplan.bench.peers): JSON problems on stdin (as
lynxplan/bench/peers/ompl_rrtconnect.py) -> JSON rows in the file argv[1], each with
``checks`` (validity calls), ``check_time`` [s] (time inside the callback, plan+simplify) and
``status`` (OMPL's PlannerStatus: "Exact solution", "Timeout", "Invalid start", ...).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "bench" / "peers"))
from common import make_validity


def solve_one(spec: Any, problem: Any, valid: Any, model: Any, seed: int) -> Any:
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    nq = model.nq
    counter = {"checks": 0, "time": 0.0}

    def check(state: Any) -> bool:
        began = time.perf_counter()
        ok = bool(valid(np.array([state[j] for j in range(nq)])))
        counter["time"] += time.perf_counter() - began
        counter["checks"] += 1
        return ok

    ou.RNG.setSeed(int(seed) + 1)
    space = ob.RealVectorStateSpace(nq)
    bounds = ob.RealVectorBounds(nq)
    for j in range(nq):
        bounds.setLow(j, float(model.lowerPositionLimit[j]))
        bounds.setHigh(j, float(model.upperPositionLimit[j]))
    space.setBounds(bounds)
    setup = og.SimpleSetup(space)
    setup.setStateValidityChecker(check)
    info = setup.getSpaceInformation()
    info.setStateValidityCheckingResolution(spec["resolution"] / space.getMaximumExtent())
    start, goal = space.allocState(), space.allocState()
    for j in range(nq):
        start[j], goal[j] = float(problem["start"][j]), float(problem["goals"][0][j])
    setup.setStartAndGoalStates(start, goal)
    setup.setPlanner(og.RRTConnect(info))
    setup.setup()
    began = time.perf_counter()
    status = setup.solve(spec["time_limit"])
    planned = time.perf_counter()
    solved = bool(status) and str(status) == "Exact solution"
    path = []
    if solved:
        setup.simplifySolution()
        geometric = setup.getSolutionPath()
        path = [
            [geometric.getState(i)[j] for j in range(nq)] for i in range(geometric.getStateCount())
        ]
    done = time.perf_counter()
    return {
        "problem": problem["name"],
        "seed": seed,
        "solved": solved,
        "plan_time": planned - began,
        "simplify_time": done - planned,
        "path": path,
        "checks": counter["checks"],
        "check_time": counter["time"],
        "status": str(status),
    }


def main() -> None:
    from ompl import util as ou

    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    spec = json.load(sys.stdin)
    rows = []
    for problem in spec["problems"]:
        valid, model = make_validity(spec["urdf"], problem["obstacles"], spec.get("self_pairs"))
        rows += [solve_one(spec, problem, valid, model, seed) for seed in spec["seeds"]]
    with open(sys.argv[1], "w", encoding="utf-8") as out:
        json.dump(rows, out)


if __name__ == "__main__":
    main()
