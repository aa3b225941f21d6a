"""``motion: plan`` in a task scenario: the segment is planned around the obstacles."""

from __future__ import annotations

from pathlib import Path

from lynxplan.scenarios import run_scenario


def _task(motion: str) -> dict[str, object]:
    return {
        "kind": "task",
        "name": "around the wall",
        "units": {"length": "m", "angle": "deg"},
        "obstacles": [
            {
                "name": "wall",
                "type": "box",
                "centre": [0.0, 0.285, 0.18],
                "size": [0.02, 0.33, 0.54],
            }
        ],
        "waypoints": {"A": {"q": [45, 30, -30, 60, 0]}, "B": {"q": [135, 30, -30, 60, 0]}},
        "segments": [{"from": "A", "to": "B", "motion": motion}],
        "compare": False,
        "expect": {"collision_free": True, "within_limits": True},
    }


def test_a_free_segment_through_the_wall_collides(tmp_path: Path) -> None:
    result = run_scenario(_task("free"), tmp_path / "out", quick=True)
    assert not result.ok
    assert result.metrics["collision_free"] is False


def test_a_planned_segment_goes_around_the_wall(tmp_path: Path) -> None:
    result = run_scenario(_task("plan"), tmp_path / "out", quick=True)
    assert result.ok, result.failed_expectations
    segments = result.details["segments"]
    assert len(segments) >= 2  # via points were added
    assert segments[0]["from"] == "A" and segments[-1]["to"] == "B"
    assert all(entry["motion"] == "free" for entry in segments)
