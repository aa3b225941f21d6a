"""``lynxplan robots``, ``robot info`` and the --robot/--urdf forms of ``fk``/``ik``."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lynxplan.cli import main
from lynxplan.robots import load_robot


def _json(capsys: pytest.CaptureFixture[str], argv: list[str]) -> object:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


def test_robots_lists_builtins(capsys: pytest.CaptureFixture[str]) -> None:
    names = [r["name"] for r in _json(capsys, ["robots", "--json"])]  # type: ignore[union-attr]
    assert names == ["al5", "so100", "so101", "ur5", "ur10", "panda"]


def test_robot_info_shows_the_family(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["robot", "info", "so101"]) == 0
    out = capsys.readouterr().out
    assert "family: yaw-pitch-pitch-pitch-roll" in out
    assert "gripper          locked at 0" in out
    assert "IK solver: yaw-pitch3-roll closed form + roll root search" in out
    data = _json(capsys, ["robot", "info", "so101", "--json", "--deg"])
    assert data["family_parameters"]["signs"] == [-1, -1, -1, -1, -1]  # type: ignore[index]
    assert data["joints"][0]["upper"] == pytest.approx(110.0, abs=1e-3)  # type: ignore[index]


def test_ik_json_lists_the_branches_when_none_is_within_the_limits(
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Straight down at (0.2, 0, 0.1) the SO-101 reaches only outside its joint limits: every
    branch is listed anyway, each naming the joints it breaks (issue 34)."""
    argv = ["ik", "--robot", "so101", "--position", "0.2", "0", "0.1", "--approach", "0", "0", "-1"]
    data = _json(capsys, [*argv, "--json"])
    library = load_robot("so101").ik(position=[0.2, 0, 0.1], approach=[0, 0, -1])
    assert not any(s.within_limits for s in library.solutions)
    assert len(data["solutions"]) == len(library.solutions)  # type: ignore[index,arg-type]
    assert data["outside_limits_not_listed"] == 0  # type: ignore[index]
    assert data["status"] == "no_solution_within_limits"  # type: ignore[index]
    assert all(s["violations"] for s in data["solutions"])  # type: ignore[index,union-attr]


def test_ik_position_approach_returns_verified_branches(capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot("so101")
    q = np.array([0.3, -0.4, 0.8, 0.6, 0.2])
    pose = robot.fk(q)
    approach = pose[:3, :3] @ robot.approach_in_tool
    argv = [
        "ik",
        "--robot",
        "so101",
        "--position",
        *map(repr, pose[:3, 3].tolist()),
        "--approach",
        *map(repr, approach.tolist()),
        "--json",
    ]
    data = _json(capsys, argv)
    assert data["reachable"] is True  # type: ignore[index]
    solutions = data["solutions"]  # type: ignore[index]
    assert all(s["verified"] and s["position_error"] < 1e-9 for s in solutions)
    gaps = [np.abs(np.array(s["q"]) - q).max() for s in solutions]
    assert min(gaps) < 1e-9
    for s in solutions:  # independent check: Pinocchio's FK of every branch
        np.testing.assert_allclose(
            robot.frame_placement(np.array(s["q"]))[:3, 3], pose[:3, 3], atol=1e-9
        )


def test_fk_with_urdf_and_tool(capsys: pytest.CaptureFixture[str]) -> None:
    robot = load_robot("so101")
    data = _json(
        capsys,
        [
            "fk",
            "--urdf",
            str(robot.urdf_path),
            "--tool",
            "gripper_frame_link",
            "0.1",
            "0.2",
            "0.3",
            "0.4",
            "0.5",
            "--json",
        ],
    )
    np.testing.assert_allclose(np.array(data["T"]), robot.fk([0.1, 0.2, 0.3, 0.4, 0.5]), atol=1e-15)  # type: ignore[index]


def test_cli_errors(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["robot", "info", "nope"]) == 2
    assert "unknown robot 'nope'" in capsys.readouterr().err
    assert main(["ik", "--robot", "so101", "--position", "0.2", "0", "0.1"]) == 2
    assert "--approach" in capsys.readouterr().err
    assert main(["fk", "--robot", "so101", "0", "0"]) == 2
    assert "so101 has 5 joints; got 2" in capsys.readouterr().err
    assert main(["ik", "--json"]) == 2
    assert "required: --pose (or --position" in capsys.readouterr().err


def test_bench_one_robot(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``lynxplan bench --robot so100 --quick``: that robot's figures only (peers skipped here:
    an empty peers folder), the round trips all solved."""
    import lynxplan.bench.robots as bench_robots

    monkeypatch.setattr(bench_robots, "PEERS_DIR", "/nonexistent-peers")
    figures = _json(capsys, ["bench", "--robot", "so100", "--quick", "--json"])["figures"]  # type: ignore[index]
    names = [f["name"] for f in figures]
    assert all(name.startswith("so100 ") for name in names), names
    trips = next(f for f in figures if "round trips solved" in f["name"])
    assert trips["value"] == 100.0 and trips["met"] is True
    approach = next(f for f in figures if "approach targets" in f["name"])
    assert approach["value"] == 100.0 and approach["met"] is True
    assert any("speed-up over Pinocchio CLIK" in name for name in names)
    assert main(["bench", "--robot", "so100", "--urdf", "x.urdf"]) == 2  # one or the other
    assert main(["bench", "arm", "--robot", "so100"]) == 2
