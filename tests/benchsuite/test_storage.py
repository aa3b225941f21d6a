"""SmallArmBench files: round trip, bad files, any problem as a plan scenario lynxplan runs."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from lynxplan.benchsuite.storage import load_shipped, load_suite, save_suite, scenario_yaml
from lynxplan.exceptions import InputError
from lynxplan.scenarios import load_scenario


def test_round_trip(tmp_path: Path) -> None:
    problems = load_shipped("al5")[:5]
    path = tmp_path / "al5.npz"
    save_suite(path, problems, {"seed": 1})
    again, header = load_suite(path)
    assert header["seed"] == 1 and header["robot"] == "al5"
    assert all(a.same_as(b) for a, b in zip(problems, again, strict=True))


def test_not_a_suite_file(tmp_path: Path) -> None:
    path = tmp_path / "x.npz"
    path.write_text("not numpy")
    with pytest.raises(InputError, match=r"x\.npz: not a SmallArmBench suite file"):
        load_suite(path)


@pytest.mark.parametrize("robot", ["al5", "so101", "ur5"])
def test_exported_problem_runs_as_a_plan_scenario(robot: str, tmp_path: Path) -> None:
    problem = load_shipped(robot)[1]
    path = tmp_path / f"{problem.name}.yaml"
    path.write_text(scenario_yaml(problem))
    loaded = load_scenario(path).scenario
    assert loaded.name == problem.name and len(loaded.obstacles) == len(problem.names)
    done = subprocess.run(
        [str(Path(sys.executable).parent / "lynxplan"), "run", str(path), "--quick", "--out",
         str(tmp_path / "out")],
        capture_output=True, text=True, check=False, timeout=600,
    )  # fmt: skip
    assert done.returncode in (0, 1), done.stderr  # 2 would be bad input
    assert json.loads((tmp_path / "out" / "report.json").read_text())
    if robot != "ur5":  # the built-in ur5 has no SRDF (see lynxplan.benchsuite.problem)
        assert done.returncode == 0, done.stdout + done.stderr
        assert "solved" in done.stdout
