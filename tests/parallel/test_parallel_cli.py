"""``lynxplan parallel`` CLI (JSON contract) and the parallel scenario files."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from lynxplan.cli import main
from lynxplan.exceptions import ScenarioError
from lynxplan.parallel.fk import solve_fk
from lynxplan.parallel.geometry import pose_from_mm_deg
from lynxplan.parallel.ik import WORKING_MODES, solve_ik
from lynxplan.parallel.workspace import constant_orientation_workspace
from lynxplan.scenarios import run_scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"


def run_json(capsys: pytest.CaptureFixture[str], *argv: str) -> dict:
    assert main(list(argv)) == 0
    return json.loads(capsys.readouterr().out)


def test_ik_json(capsys: pytest.CaptureFixture[str]) -> None:
    data = run_json(capsys, "parallel", "ik", "260", "180", "30", "--json")
    assert set(data) == {"solutions", "modes"}
    assert data["modes"] == list(WORKING_MODES)
    expected = np.degrees(solve_ik(pose_from_mm_deg(260, 180, 30)))
    np.testing.assert_allclose(data["solutions"], expected, atol=1e-12)
    assert data["solutions"][0] == pytest.approx([58.0030, 159.7404, -64.4231], abs=1e-4)


def test_ik_text_and_negative_numbers(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["parallel", "ik", "260", "180", "-10"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 9
    assert "8 ---" in out


def test_fk_json(capsys: pytest.CaptureFixture[str]) -> None:
    data = run_json(capsys, "parallel", "fk", "58.0030", "159.7404", "-64.4231", "--json")
    assert set(data) == {"poses"}
    poses = np.array(data["poses"])
    assert poses.shape == (6, 3)
    reference = solve_fk(np.radians([58.0030, 159.7404, -64.4231])).poses
    np.testing.assert_allclose(poses[:, :2], reference[:, :2] * 1e3, atol=1e-9)
    assert np.min(np.abs(poses - [260, 180, 30]).max(axis=1)) < 1e-3
    near = run_json(
        capsys,
        "parallel",
        "fk",
        "58.0030",
        "159.7404",
        "-64.4231",
        "--near",
        "250",
        "170",
        "25",
        "--json",
    )
    np.testing.assert_allclose(near["poses"], [[260, 180, 30]], atol=1e-3)


def test_fk_without_assembly_mode(capsys: pytest.CaptureFixture[str]) -> None:
    assert run_json(capsys, "parallel", "fk", "-135", "-45", "90", "--json") == {"poses": []}
    assert main(["parallel", "fk", "-135", "-45", "90"]) == 0
    assert "no assembly mode" in capsys.readouterr().out


def test_workspace_json_and_png(capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    data = run_json(
        capsys,
        "parallel",
        "workspace",
        "--alpha",
        "-10",
        "--step",
        "2",
        "--out",
        str(tmp_path),
        "--json",
    )
    assert set(data) == {"area_mm2", "points"}
    expected = constant_orientation_workspace(math.radians(-10), step=2e-3)
    assert data["points"] == expected.points
    assert data["area_mm2"] == pytest.approx(expected.area_mm2)
    png = tmp_path / "parallel_workspace_alpha-10.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (
        main(
            [
                "parallel",
                "workspace",
                "--alpha",
                "20",
                "--step",
                "4",
                "--mode",
                "2",
                "--out",
                str(tmp_path),
            ]
        )
        == 0
    )
    assert "points" in capsys.readouterr().out
    assert (tmp_path / "parallel_workspace_alpha20_mode2.png").exists()


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["parallel", "ik", "10", "10", "0"], "leg B cannot reach its platform joint"),
        (["parallel", "ik", "nan", "1", "2"], "XC: 'nan' is not a finite number"),
        (["parallel", "fk", "1", "x", "2"], "T2: 'x' is not a number"),
        (
            ["parallel", "fk", "-135", "-45", "90", "--near", "1", "2", "3"],
            "admit no assembly mode",
        ),
        (["parallel", "workspace", "--alpha", "20", "--step", "0"], "--step = 0 is out of range"),
        (["parallel", "workspace", "--alpha", "inf"], "--alpha: 'inf' is not a finite number"),
        (
            ["parallel", "workspace", "--alpha", "20", "--mode", "9"],
            "working mode number must be 1..8",
        ),
        (["parallel", "workspace", "--alpha", "20", "--mode", "+x+"], "unknown working mode"),
    ],
)
def test_cli_errors(
    capsys: pytest.CaptureFixture[str], tmp_path: Path, argv: list[str], message: str
) -> None:
    if argv[1] == "workspace":
        argv = [*argv, "--out", str(tmp_path)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err
    assert err.count("\n") == 1


def test_ik_scenario(tmp_path: Path) -> None:
    outcome = run_scenario(SCENARIOS / "parallel_ik.yaml", tmp_path)
    assert outcome.ok, outcome.failed_expectations
    data = json.loads((tmp_path / "parallel_ik.json").read_text())
    assert [m["assembly_modes"] for m in data["modes"]] == [6, 4, 4, 2, 6, 2, 2, 2]
    assert (tmp_path / "parallel_postures.png").stat().st_size > 10_000


def test_workspace_scenario(tmp_path: Path) -> None:
    outcome = run_scenario(SCENARIOS / "parallel_workspace.yaml", tmp_path, quick=True)
    assert outcome.ok, outcome.failed_expectations
    data = json.loads((tmp_path / "parallel_workspace.json").read_text())
    assert [w["alpha"] for w in data["workspaces"]] == [20, -10]
    assert (
        data["workspaces"][0]["points"] == constant_orientation_workspace(math.radians(20)).points
    )


def test_scenario_expectation_failures(tmp_path: Path) -> None:
    text = (
        (SCENARIOS / "parallel_ik.yaml")
        .read_text()
        .replace("[58.0030, 159.7404, -64.4231]", "[58.1, 159.7404, -64.4231]")
    )
    (tmp_path / "ik.yaml").write_text(text)
    outcome = run_scenario(tmp_path / "ik.yaml", None)
    assert outcome.failed_expectations == (
        "solutions[0]: measured [ 58.003017, 159.740405, -64.423082] deg, expected "
        "[ 58.1   , 159.7404, -64.4231] deg within 0.0001 deg",
    )
    text = (
        (SCENARIOS / "parallel_workspace.yaml")
        .read_text()
        .replace("max_area: 70000", "max_area: 60000")
    )
    (tmp_path / "ws.yaml").write_text(text)
    outcome = run_scenario(tmp_path / "ws.yaml", None)
    assert outcome.failed_expectations == (
        "max_area: measured [58406., 63121.] mm^2, expected 60000",
    )


def test_scenario_validation(tmp_path: Path) -> None:
    (tmp_path / "bad.yaml").write_text("kind: parallel_workspace\nalphas: []\nstep: 1\n")
    with pytest.raises(ScenarioError, match="alphas: List should have at least 1 item"):
        run_scenario(tmp_path / "bad.yaml", None)
    (tmp_path / "bad2.yaml").write_text("kind: parallel_ik\npose: [1, 2]\n")
    with pytest.raises(ScenarioError, match="pose"):
        run_scenario(tmp_path / "bad2.yaml", None)
    (tmp_path / "bad3.yaml").write_text(
        "kind: parallel_ik\npose: [1, 2, 3]\ngeometry: {distal: -1}\n"
    )
    with pytest.raises(ScenarioError, match=r"geometry\.distal: Input should be greater than 0"):
        run_scenario(tmp_path / "bad3.yaml", None)
