"""Peer: pyroboplan's RRTPlanner (RRT-Connect, bidirectional) and its shortcut_path.

Run by the pyroboplan venv's python: JSON problems on stdin -> JSON results in the file named
by argv[1] (stdout carries the logs). The
collision model is the same as lynxplan's (robot + obstacles, non-adjacent self pairs); the
planner's edge step is ``resolution`` [rad]. pyroboplan takes one goal configuration: the
first of the problem's goals. Note (measured, pyroboplan 4.0.0): its ``shortcut_path`` joins
the waypoint before a shortcut's first point straight to its second point, a segment it never
checked, so its shortened paths often collide: the dense check of the paths says so.
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np
from common import build, result_row


def main() -> None:
    from pyroboplan.planning.path_shortcutting import shortcut_path
    from pyroboplan.planning.rrt import RRTPlanner, RRTPlannerOptions

    spec = json.load(sys.stdin)
    results = []
    for problem in spec["problems"]:
        model, _data, geometry, _geometry_data = build(
            spec["urdf"], problem["obstacles"], spec.get("self_pairs")
        )
        for seed in spec["seeds"]:
            options = RRTPlannerOptions(
                max_step_size=spec["resolution"],
                max_connection_dist=spec.get("max_connection_dist", 0.6),
                rrt_connect=True,
                bidirectional_rrt=True,
                max_planning_time=spec["time_limit"],
                rng_seed=int(seed),
                goal_biasing_probability=0.1,
            )
            planner = RRTPlanner(model, geometry, options)
            began = time.perf_counter()
            path = planner.plan(np.array(problem["start"]), np.array(problem["goals"][0]))
            planned = time.perf_counter()
            solved = path is not None and len(path) > 1  # a timeout returns [] (4.0), not None
            if solved and spec["simplify"]:
                path = shortcut_path(model, geometry, path, max_step_size=spec["resolution"])
            done = time.perf_counter()
            rows = [list(map(float, q)) for q in path] if solved else []
            times = (began, planned, done)
            results.append(result_row(problem["name"], seed, solved, times, rows))
    with open(sys.argv[1], "w", encoding="utf-8") as out:  # stdout carries the peer's logs
        json.dump(results, out)


if __name__ == "__main__":
    main()
