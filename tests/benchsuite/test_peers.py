"""SmallArmBench peers: the collision model a peer builds is lynxplan's (meshes found through
lynxplan's mesh resolver, the same hulls, the same self pairs), for every robot of the suite.

The peers' own planners (OMPL, pyroboplan) live in their own virtual environments; these tests
build the peers' collision model with this environment's Pinocchio, as the peer scripts do.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from lynxplan.bench.peers import peer_urdf, self_pair_names
from lynxplan.bench.peers.common import build, make_validity
from lynxplan.benchsuite.peers import _spec
from lynxplan.benchsuite.problem import suite_robot
from lynxplan.benchsuite.storage import load_shipped
from lynxplan.collision import CollisionWorld


@pytest.mark.parametrize("name", ["al5", "so101", "ur5"])
def test_peer_urdf_meshes_are_files_and_the_model_is_lynxplans(name: str, tmp_path: Path) -> None:
    robot = suite_robot(name)
    urdf = peer_urdf(robot, tmp_path)
    collisions = ET.parse(urdf).iter("collision")
    meshes = [m.get("filename", "") for c in collisions for m in c.iter("mesh")]
    assert all(Path(m).is_absolute() and Path(m).is_file() for m in meshes), meshes
    pairs = self_pair_names(robot)
    model, _data, geometry, _gdata = build(str(urdf), [], pairs)
    assert model.nq == robot.nq
    names = [g.name for g in geometry.geometryObjects]
    assert names == [g.name for g in robot.collision_model.geometryObjects]
    expected = CollisionWorld(robot, (), self_collision=True).self_pairs
    assert len(geometry.collisionPairs) == len(expected) == len(pairs)


def test_ur5_peer_check_agrees_with_lynxplan_on_a_problem(tmp_path: Path) -> None:
    """UR5 (example-robot-data, package:// meshes): the peer's validity check is free at the
    start and goal and in collision half way along the straight motion, as lynxplan's."""
    problem = load_shipped("ur5")[0]
    spec = _spec([problem])
    urdf = peer_urdf(suite_robot("ur5"), tmp_path)
    valid, _model = make_validity(str(urdf), spec["problems"][0]["obstacles"], spec["self_pairs"])
    assert valid(problem.start) and valid(problem.goal)
    line = problem.start + np.linspace(0.0, 1.0, 201)[:, None] * (problem.goal - problem.start)
    assert not all(valid(q) for q in line)


def test_cdf_plot_draws_the_peers_beside_lynxplan(tmp_path: Path) -> None:
    from lynxplan.benchsuite.report import cdf_plot
    from lynxplan.benchsuite.runner import ProblemResult

    ours = [ProblemResult(f"al5_bin_{k:03d}", "al5", "bin", True, "", True, 0.01, 0.01, 1e-3 * k,
                          1e-4, 1e-4, 3.0, 2.0, "x", 2e-3) for k in range(1, 4)]  # fmt: skip
    rows = [{"peer": "ompl", "problem": f"al5_bin_{k:03d}", "solved": k < 3, "plan_time": 0.2,
             "simplify_time": 0.05} for k in range(1, 4)]  # fmt: skip
    path = cdf_plot(ours, tmp_path / "cdf.png", rows)
    assert path.stat().st_size > 1000
