"""A small valid task scenario (as a dict) that the tests mutate, and a YAML writer."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import yaml

BASE: dict[str, Any] = {
    "kind": "task",
    "name": "small",
    "units": {"length": "in", "angle": "deg"},
    "sample_rate": 100,
    "timing": {"tt": 2.0, "ta": 0.5},
    "obstacles": [
        {"name": "wall_letters", "type": "box", "min_corner": [-0.2, 8, -2], "size": [0.4, 10, 3.5]}
    ],
    "waypoints": {
        "K3": {"q": [75.5, 57, -59, 41, 0]},
        "K4": {"q": [79, 70, -77, 29, 0]},
        "I3": {"q": [30, 90, -30, 30, 0]},
    },
    "segments": [
        {"from": "K3", "to": "K4", "motion": "line"},
        {"to": "I3", "motion": "free"},
    ],
    "expect": {"collision_free": True, "min_clearance": ">= 0.2 in"},
}


def scenario_dict(**changes: Any) -> dict[str, Any]:
    """A deep copy of :data:`BASE` with top-level keys replaced."""
    data = copy.deepcopy(BASE)
    data.update(changes)
    return data


def write_scenario(path: Path, data: dict[str, Any]) -> Path:
    """Write ``data`` as YAML to ``path``; returns the path."""
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path
