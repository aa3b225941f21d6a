"""The CLI: fk, ik, workspace and run; JSON contracts and one-line errors."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest

from lynxplan.cli import main

O2_POSE = (
    "[[-0.3196, 0.9455, -0.0621, -2.8966], [0.9281, 0.3256, 0.1804, 8.4123],"
    " [0.1908, 0, -0.9816, 0.5472]]"
)


def run_cli(capsys, *args: str) -> tuple[int, str, str]:
    code = main(list(args))
    captured = capsys.readouterr()
    return code, captured.out, captured.err


def test_fk_json_with_negative_angles(capsys) -> None:
    code, out, _ = run_cli(
        capsys, "fk", "120", "60", "-45", "45", "0", "--deg", "--units", "in", "--json"
    )
    assert code == 0
    data = json.loads(out)
    assert data["units"] == {"length": "in", "angle": "deg"}
    np.testing.assert_allclose(np.array(data["T"])[:3, 3], [-6.4608, 11.1904, 5.2009], atol=6e-5)


def test_ik_json_contract(capsys) -> None:
    code, out, _ = run_cli(
        capsys, "ik", "--pose", O2_POSE, "--deg", "--units", "in", "--json", "--all"
    )
    assert code == 0
    data = json.loads(out)
    assert len(data["solutions"]) == 4
    selected = data["solutions"][data["selected"]]
    np.testing.assert_allclose(selected["q"], [109, 79, -93, 25, 0], atol=0.01)
    assert selected["within_limits"] is True
    assert set(selected) >= {"q", "within_limits", "orientation_error"}


def test_ik_without_all_lists_only_solutions_within_limits(capsys) -> None:
    code, out, _ = run_cli(capsys, "ik", "--pose", O2_POSE, "--deg", "--units", "in", "--json")
    data = json.loads(out)
    assert code == 0
    assert all(s["within_limits"] for s in data["solutions"])
    assert data["selected"] == 0


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("fk", "1", "2", "3"), "expected 5 joint angles q1..q5, got 3"),
        (("fk", "1", "2", "3", "4", "nan"), "q5: 'nan' is not a finite number"),
        (("fk", "1", "2", "3", "4", "5", "--units", "ft"), "invalid choice: 'ft'"),
        (("ik", "--pose", "[[1, 0, 0]"), "--pose: not a JSON 4x4"),
        (("ik", "--pose", "[[1, 0], [0, 1]]"), r"--pose must have shape \(4, 4\) or \(3, 4\)"),
        (("ik", "--pose", "[[2,0,0,0.1],[0,1,0,0],[0,0,1,0]]"), "not a rigid transform"),
        (("ik", "--pose", "[[1,0,0,NaN],[0,1,0,0],[0,0,1,0]]"), r"--pose contains NaN .*3\] = nan"),
        (("ik", "--pose", "[[1,0,0,5],[0,1,0,0],[0,0,1,0]]", "--strict"), "out of reach"),
        (("ik", "--pose", O2_POSE, "--units", "in", "--strict"), "exceeds the strict tolerance"),
        (("run", "/nonexistent/scenario.yaml"), "file not found"),
        (("workspace", "--samples", "0"), "--samples = 0 is out of range: must be an integer >= 1"),
        (("workspace", "--cell", "-3"), "--cell: must be at least 0.1 mm. Got: -3.0"),
        (("workspace", "--voxel", "1e-9"), "--voxel: must be at least 0.1 mm"),
        (
            ("workspace", "--samples", "100", "--out", "/dev/null/x"),
            r"output folder /dev/null/x: cannot be created \(File exists\)",
        ),
        (("bench", "--section", "nope"), "invalid choice: 'nope'"),
    ],
)
def test_bad_input_is_one_line_and_nonzero(capsys, args: tuple[str, ...], message: str) -> None:
    try:
        code = main(list(args))
    except SystemExit as exit_:  # argparse usage errors
        code = exit_.code
    err = capsys.readouterr().err
    assert code != 0
    assert err.count("\n") == 1
    assert "Traceback" not in err
    assert re.search(message, err), err


def test_run_workspace_scenario_quick(capsys, tmp_path: Path) -> None:
    scenario = tmp_path / "ws.yaml"
    scenario.write_text(
        "kind: workspace\nsamples: 100000\ncell: 0.2\nvoxel_size: 0.5\n"
        "expect: {max_reach: 16.5, min_volume: 8000}\n"
    )
    code, out, _ = run_cli(capsys, "run", str(scenario), "--out", str(tmp_path / "out"), "--quick")
    assert code == 0, out
    data = json.loads((tmp_path / "out" / "workspace.json").read_text())
    assert data["units"]["length"] == "in"
    assert data["volume"] > 8000


def test_failed_expectation_exits_one(capsys, tmp_path: Path) -> None:
    scenario = tmp_path / "ws.yaml"
    scenario.write_text("kind: workspace\nsamples: 20000\ncell: 0.4\nexpect: {max_reach: 10}\n")
    code, out, _ = run_cli(capsys, "run", str(scenario), "--out", str(tmp_path / "o"), "--quick")
    assert code == 1
    assert "max_reach" in out


def test_invalid_scenario_names_key_and_writes_nothing(capsys, tmp_path: Path) -> None:
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    (out_dir / "workspace.json").write_text("earlier run")
    scenario = tmp_path / "bad.yaml"
    scenario.write_text("kind: workspace\nsamples: many\n")
    code, _, err = run_cli(capsys, "run", str(scenario), "--out", str(out_dir))
    assert code == 2
    assert "bad.yaml, samples:" in err
    assert (out_dir / "workspace.json").read_text() == "earlier run"
    scenario.write_text("kind: workspace\nsampels: 10\n")
    code, _, err = run_cli(capsys, "run", str(scenario), "--out", str(out_dir))
    assert code == 2
    assert "sampels: Extra inputs are not permitted" in err
    scenario.write_text("kind: teleport\n")
    code, _, err = run_cli(capsys, "run", str(scenario), "--out", str(out_dir))
    assert code == 2
    assert "unknown kind 'teleport'" in err


def test_workspace_command_writes_plots_and_json(capsys, tmp_path: Path) -> None:
    code, out, _ = run_cli(
        capsys,
        "workspace",
        "--samples",
        "50000",
        "--cell",
        "8",
        "--out",
        str(tmp_path / "w"),
        "--json",
    )
    assert code == 0
    assert json.loads(out)["samples"] == 50000
    for name in (
        "workspace_3d.png",
        "workspace_projections.png",
        "workspace_section.png",
        "workspace.html",
        "workspace.json",
    ):
        assert (tmp_path / "w" / name).stat().st_size > 400


def test_every_negative_number_form_is_a_value(capsys) -> None:
    code, out, _ = run_cli(
        capsys, "fk", "-1e-3", "-5.", "-.5", "-0", "0", "--json", "--ignore-limits"
    )
    assert code == 0
    expected = np.array(json.loads(out)["T"])
    from lynxplan.arm import forward_kinematics

    np.testing.assert_allclose(expected, forward_kinematics(np.array([-1e-3, -5.0, -0.5, 0, 0])))


def test_duplicate_yaml_key_is_rejected(capsys, tmp_path: Path) -> None:
    scenario = tmp_path / "dup.yaml"
    scenario.write_text("kind: workspace\nsamples: 10\nsamples: 20\n")
    code, _, err = run_cli(capsys, "validate", str(scenario))
    assert code == 2 and "invalid YAML: duplicate key 'samples' (line 3)" in err


def test_run_time_error_names_the_scenario_file(capsys, tmp_path: Path) -> None:
    scenario = tmp_path / "far.yaml"
    scenario.write_text("kind: parallel_ik\npose: [2000, 180, 30]\n")
    code, _, err = run_cli(capsys, "run", str(scenario), "--quick", "--out", str(tmp_path / "o"))
    assert code == 2
    assert f"scenario {scenario}" in err
    assert "leg" in err


def test_bench_smoke_json(capsys) -> None:
    code, out, _ = run_cli(capsys, "bench", "--section", "parallel", "--quick", "--json")
    assert code == 0
    figures = json.loads(out)["figures"]
    assert figures
    assert all(f["section"] == "parallel" for f in figures)
    assert all(np.isfinite(f["value"]) and f["value"] > 0 for f in figures)
