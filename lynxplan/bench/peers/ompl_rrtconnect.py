"""Peer: OMPL 2.x RRTConnect through its Python bindings (``ompl.base``/``ompl.geometric``).

Run by the OMPL venv's python: JSON problems on stdin -> JSON results in the file named by
argv[1] (stdout carries the logs). Per problem and seed: SimpleSetup with a
RealVectorStateSpace over the joint limits, a Python validity callable using
``pinocchio.computeCollisions`` on the same collision model, the state validity checking
resolution set to ``resolution`` [rad] (as a fraction of the space's extent), solve, then
``simplifySolution``; wall times of both.
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np
from common import make_validity, result_row


def main() -> None:
    from ompl import base as ob
    from ompl import geometric as og
    from ompl import util as ou

    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    spec = json.load(sys.stdin)
    results = []
    for problem in spec["problems"]:
        valid, model = make_validity(spec["urdf"], problem["obstacles"], spec.get("self_pairs"))
        nq = model.nq
        lower, upper = np.array(model.lowerPositionLimit), np.array(model.upperPositionLimit)
        for seed in spec["seeds"]:
            ou.RNG.setSeed(int(seed) + 1)
            space = ob.RealVectorStateSpace(nq)
            bounds = ob.RealVectorBounds(nq)
            for j in range(nq):
                bounds.setLow(j, float(lower[j]))
                bounds.setHigh(j, float(upper[j]))
            space.setBounds(bounds)
            setup = og.SimpleSetup(space)
            setup.setStateValidityChecker(
                lambda state, n=nq, check=valid: check(np.array([state[j] for j in range(n)]))
            )
            info = setup.getSpaceInformation()
            info.setStateValidityCheckingResolution(spec["resolution"] / space.getMaximumExtent())
            start = space.allocState()
            for j in range(nq):
                start[j] = float(problem["start"][j])
            goals = ob.GoalStates(info)
            for goal in problem["goals"]:
                state = space.allocState()
                for j in range(nq):
                    state[j] = float(goal[j])
                goals.addState(state)
            setup.setStartState(start)
            setup.setGoal(goals)
            setup.setPlanner(og.RRTConnect(info))
            setup.setup()
            began = time.perf_counter()
            status = setup.solve(spec["time_limit"])
            planned = time.perf_counter()
            solved = bool(status) and str(status) == "Exact solution"
            path = []
            if solved and spec["simplify"]:
                setup.simplifySolution()
            done = time.perf_counter()
            if solved:
                geometric = setup.getSolutionPath()
                path = [
                    [geometric.getState(i)[j] for j in range(nq)]
                    for i in range(geometric.getStateCount())
                ]
            results.append(result_row(problem["name"], seed, solved, (began, planned, done), path))
    with open(sys.argv[1], "w", encoding="utf-8") as out:  # stdout carries the peer's logs
        json.dump(results, out)


if __name__ == "__main__":
    main()
