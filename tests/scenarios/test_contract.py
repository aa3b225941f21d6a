"""The scenario contract: registry (a new kind is one module + one line), validation without
computation, located errors, one result type, all-or-nothing output folders, trajectory.csv."""

from __future__ import annotations

import json
import os
import socket
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from lynxplan.cli import main
from lynxplan.exceptions import ScenarioError
from lynxplan.scenarios import load_scenario, run_scenario
from lynxplan.scenarios.outputs import MARKER, OutputFolderError
from lynxplan.scenarios.registry import KIND_MODULES, register_kind

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"

TOY_KIND = '''
"""A toy scenario kind: squares a number."""
from pathlib import Path
from typing import ClassVar, Literal

from lynxplan.scenarios.base import KindOutput, ScenarioModel

NAME = "toy"


class Input(ScenarioModel):
    metrics: ClassVar = {"square": "count", "positive": "bool"}
    kind: Literal["toy"]
    x: float


def run(scenario: Input, *, quick: bool = False) -> KindOutput:
    return KindOutput({"square": scenario.x**2, "positive": scenario.x > 0}, f"{scenario.x}^2")


def write_outputs(scenario: Input, output: KindOutput, out_dir: Path, *, quick: bool) -> list[str]:
    (out_dir / "square.txt").write_text(str(output.metrics["square"]))
    return ["square.txt"]
'''


@pytest.fixture
def toy_kind(tmp_path, monkeypatch):
    (tmp_path / "toy_kind.py").write_text(TOY_KIND)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.setitem(KIND_MODULES, "toy", "toy_kind")
    yield
    sys.modules.pop("toy_kind", None)


def test_a_new_kind_is_one_module_and_one_registration_line(toy_kind, tmp_path):
    register_kind("toy", "toy_kind")
    result = run_scenario(
        {"kind": "toy", "x": 3, "expect": {"max_square": 10, "positive": True}}, tmp_path / "out"
    )
    assert result.ok and result.metrics == {"square": 9.0, "positive": True}
    assert result.artifacts == ("report.json", "square.txt")
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["expectations"][0]["name"] == "max_square"
    failed = run_scenario({"kind": "toy", "x": -4, "expect": {"max_square": "< 10"}})
    assert failed.failed_expectations == ("max_square: measured 16, expected < 10",)
    with pytest.raises(ScenarioError, match=r"expect\.cube: unknown expectation 'cube'"):
        load_scenario({"kind": "toy", "x": 1, "expect": {"cube": 1}})


def test_unknown_and_missing_kinds_list_the_registered_ones(tmp_path):
    with pytest.raises(ScenarioError, match="unknown kind 'nope'; valid kinds: parallel_ik"):
        load_scenario({"kind": "nope"})
    with pytest.raises(ScenarioError, match="kind: missing; valid kinds"):
        load_scenario({"name": "no kind"})


def test_validation_errors_name_the_key_path_and_the_line(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(
        textwrap.dedent(
            """\
            kind: trajectory
            start: [0, 0, 0, 0, 0]
            limits:
              acceleration: [1, 2]
            segments:
              - {motion: free, to_q: [0, 1, -1, 0, 0]}
            """
        )
    )
    with pytest.raises(ScenarioError) as info:
        load_scenario(path)
    assert info.value.location.startswith("limits.acceleration")
    assert info.value.line == 4
    assert str(info.value).endswith("(line 4)")


def test_validation_never_computes(tmp_path):
    # An unreachable waypoint is valid input; the run (IK) finds the problem and names its line.
    text = (SCENARIOS / "ok_task.yaml").read_text()
    text = text.replace(
        "I: {q: [0, 0, 0, 0, 0]}", "I: {position: [0, 90, 0], approach: [0, 0, -1]}"
    )
    path = tmp_path / "far.yaml"
    path.write_text(text)
    assert load_scenario(path).scenario.kind == "task"
    with pytest.raises(ScenarioError, match=r"waypoints\.I\.position: unreachable waypoint.*line"):
        run_scenario(path, None, quick=True)


@pytest.mark.parametrize("name", ["straight_line", "free_motion", "ok_task"])
def test_trajectory_csv_reloads_to_the_in_memory_trajectory(name, tmp_path):
    loaded = load_scenario(SCENARIOS / f"{name}.yaml")
    output = loaded.kind.run(loaded.scenario)
    written = loaded.kind.write_outputs(loaded.scenario, output, tmp_path, quick=True)
    assert "trajectory.csv" in written
    header = (tmp_path / "trajectory.csv").read_text().splitlines()[0].split(",")
    assert header == [
        "t",
        *(f"{p}{j}" for p in ("q", "qd", "qdd") for j in range(1, 6)),
        "x",
        "y",
        "z",
    ]
    table = np.loadtxt(tmp_path / "trajectory.csv", delimiter=",", skiprows=1)
    samples = output.payload.samples if name == "ok_task" else output.payload[1]
    assert table.shape == (len(samples.t), 19)
    # The values are written in their shortest exact form: they read back bit for bit.
    np.testing.assert_array_equal(table[:, 0], samples.t)
    np.testing.assert_array_equal(table[:, 1:6], samples.q)
    np.testing.assert_array_equal(table[:, 6:11], samples.qd)
    np.testing.assert_array_equal(table[:, 11:16], samples.qdd)
    np.testing.assert_array_equal(table[:, 16:], samples.tool[:, :3, 3])


def test_a_quick_run_replaces_the_whole_folder(tmp_path):
    out = tmp_path / "out"
    assert main(["run", str(SCENARIOS / "straight_line.yaml"), "--out", str(out)]) == 0
    assert (out / "joint_profiles.png").is_file()
    assert main(["run", str(SCENARIOS / "straight_line.yaml"), "--out", str(out), "--quick"]) == 0
    assert sorted(p.name for p in out.iterdir()) == [MARKER, "report.json", "trajectory.csv"]
    assert [p.name for p in tmp_path.iterdir()] == ["out"]  # no staging debris


def test_a_failed_expectation_still_writes_the_report_and_exits_1(tmp_path, capsys):
    text = (SCENARIOS / "free_motion.yaml").read_text() + "  max_duration: 1.0\n"
    path = tmp_path / "strict.yaml"
    path.write_text(text)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quick"]) == 1
    assert "max_duration: measured 3 s, expected 1.0" in capsys.readouterr().out
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert report["passed"] is False


def test_foreign_folders_are_refused_unless_forced(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    with pytest.raises(OutputFolderError, match=r"holds thesis\.tex, which lynxplan did not write"):
        run_scenario(SCENARIOS / "parallel_ik.yaml", out, quick=True)
    assert main(["run", str(SCENARIOS / "parallel_ik.yaml"), "--out", str(out), "--quick"]) == 2
    assert "--force" in capsys.readouterr().err
    assert (out / "thesis.tex").read_text() == "precious"
    run_scenario(SCENARIOS / "parallel_ik.yaml", out, quick=True, force=True)
    assert (out / "report.json").is_file() and (out / "thesis.tex").read_text() == "precious"


def test_stale_staging_of_dead_runs_is_cleaned_and_a_displaced_output_restored(tmp_path):
    out = tmp_path / "out"
    run_scenario(SCENARIOS / "parallel_ik.yaml", out, quick=True)
    dead = 2**22 + 12345  # above pid_max on Linux: no such process
    stale = tmp_path / f".out.staging-{dead}-abcd0123"
    stale.mkdir()
    (stale / "half.png").write_text("partial")
    identity = {"pid": dead, "host": socket.gethostname(), "state": "staging"}
    (stale / MARKER).write_text(json.dumps(identity))
    os.replace(out, tmp_path / f".out.previous-{dead}-ef012345")  # killed between the renames
    run_scenario(SCENARIOS / "parallel_ik.yaml", out, quick=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]


def test_schema_report_command_prints_the_published_schema(capsys):
    assert main(["schema", "report"]) == 0
    schema = json.loads(capsys.readouterr().out)
    assert set(schema["required"]) >= {"kind", "schema_version", "inputs", "metrics", "artifacts"}


@pytest.mark.parametrize("kind", ["task", "plan", "trajectory", "workspace"])
def test_schema_command_lists_the_metrics_expect_may_name(capsys, kind):
    from lynxplan.scenarios.registry import kind_module

    assert main(["schema", kind]) == 0
    expect = json.loads(capsys.readouterr().out)["properties"]["expect"]
    metrics = kind_module(kind, "<test>").Input.metrics
    assert set(expect["properties"]) == set(metrics)
    for name in metrics:
        assert name in expect["description"]
