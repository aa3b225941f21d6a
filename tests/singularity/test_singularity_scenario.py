"""The ``singularity`` scenario kind: the shipped file runs and its expectations hold."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from lynxplan.exceptions import ScenarioError
from lynxplan.scenarios import load_scenario, run_scenario

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "singularity_line.yaml"


def test_shipped_scenario_runs_and_meets_expectations(tmp_path: Path) -> None:
    outcome = run_scenario(SCENARIO, tmp_path / "out", quick=True)
    assert outcome.ok, outcome.failed_expectations
    report = json.loads((tmp_path / "out" / "report.json").read_text())
    assert set(report["details"]["metrics"]) == {"pinv", "speed_limit", "dls", "tr"}
    assert report["details"]["metrics"]["pinv"]["speed_limit_exceeded"] is True
    assert report["details"]["line_distance_to_base_axis_m"] == pytest.approx(1e-3, abs=1e-12)
    assert "tool_on_base_axis" in report["details"]["singular_conditions"]
    assert "pinv" in outcome.summary


def test_failed_expectation_is_reported(tmp_path: Path) -> None:
    text = SCENARIO.read_text().replace(
        "max_distance_to_singularity: 1.0", "max_distance_to_singularity: 0.5"
    )
    path = tmp_path / "s.yaml"
    path.write_text(text)
    outcome = run_scenario(path, None, quick=True)
    assert outcome.failed_expectations == (
        "max_distance_to_singularity: measured 1 mm, expected 0.5",
    )


@pytest.mark.parametrize(
    ("old", "new", "match"),
    [
        (
            "  sigma_fraction: 0.05",
            "  sigma_fraction: 0.05\n  sigma: 0.001",
            "exactly one of sigma",
        ),
        ("  sigma_fraction: 0.05", "  sigma_fraction: 0.0", "tr.sigma_fraction"),
        ("  k_r: 20.0", "  k_r: -1.0", "tr.k_r"),
        ("task: position_pitch", "task: orientation", "task"),
        ("  blend: 1.5 ", "  blend: 1.5\n  extra: 1 ", "timing.extra"),
    ],
)
def test_invalid_scenarios(tmp_path: Path, old: str, new: str, match: str) -> None:
    text = SCENARIO.read_text()
    assert old in text
    path = tmp_path / "bad.yaml"
    path.write_text(text.replace(old, new, 1))
    with pytest.raises(ScenarioError, match=match):
        load_scenario(path)


def test_full_run_writes_the_plots(tmp_path: Path) -> None:
    outcome = run_scenario(SCENARIO, tmp_path / "full", quick=False)
    assert outcome.ok
    for name in ("manipulability", "joint_speeds", "tracking_error", "tool_paths"):
        png = tmp_path / "full" / f"{name}.png"
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert png.stat().st_size > 10_000
