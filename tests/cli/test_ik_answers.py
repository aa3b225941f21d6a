"""``lynxplan ik`` / ``fk`` as a script meets them (issue 34, sections 3 and 4): every branch
listed with the limits it breaks when none is within them, ``--strict`` exit codes, top-level
figures of the selected branch, joint angles beyond the limits refused. Run as the installed
command, in a subprocess."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

LYNXPLAN = str(Path(sys.executable).with_name("lynxplan"))
#: The README's SO-101 example: straight down at (0.2, 0, 0.1) m.
SO101_DOWN = (
    "ik",
    "--robot",
    "so101",
    "--position",
    "0.2",
    "0",
    "0.1",
    "--approach",
    "0",
    "0",
    "-1",
)
#: The report's AL5 example pose (inches).
O2_POSE = (
    "[[-0.3196,0.9455,-0.0621,-2.8966],[0.9281,0.3256,0.1804,8.4123],[0.1908,0,-0.9816,0.5472]]"
)
#: A pose 5 m away from the AL5 (and from the SO-101).
FAR_POSE = "[[1,0,0,5],[0,1,0,0],[0,0,1,0]]"
#: q values equal to their limits up to this [deg] (the JSON carries the solver's float64).
DEG_TOL = 1e-9


def lynxplan(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [LYNXPLAN, *args], capture_output=True, text=True, timeout=600, check=False
    )


def _urdf_limits_deg(robot: str) -> dict[str, tuple[float, float]]:
    """Joint limits read from the robot's URDF text (not through lynxplan's model), in [deg]."""
    import xml.etree.ElementTree as ET

    from lynxplan.robots import load_robot

    root = ET.parse(load_robot(robot).urdf_path).getroot()
    limits = {}
    for joint in root.iter("joint"):
        limit = joint.find("limit")
        if joint.get("type") == "revolute" and limit is not None:
            low, high = float(limit.get("lower", "0")), float(limit.get("upper", "0"))
            limits[joint.get("name", "")] = (math.degrees(low), math.degrees(high))
    return limits


def test_so101_lists_every_branch_with_the_limits_it_breaks() -> None:
    done = lynxplan(*SO101_DOWN, "--deg", "--json")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["status"] == "no_solution_within_limits"
    assert data["selected"] is None and data["orientation_residual"] is None
    assert len(data["solutions"]) == 20 and data["outside_limits_not_listed"] == 0
    assert "wrist_flex" in data["message"] and "95 deg" in data["message"]
    assert "no IK branch within the joint limits" in done.stderr  # said on the terminal too
    from lynxplan.robots import load_robot

    limits = _urdf_limits_deg("so101")
    names = load_robot("so101").joint_names
    for row in data["solutions"]:
        assert row["within_limits"] is False and row["violations"]
        broken = {v["joint"] for v in row["violations"]}
        # independent: every joint outside its URDF limit is named, and no other
        expected = {
            name
            for name, value in zip(names, row["q"], strict=True)
            if not limits[name][0] - DEG_TOL <= value <= limits[name][1] + DEG_TOL
        }
        assert broken == expected
        for v in row["violations"]:
            low, high = limits[v["joint"]]
            assert v["limit"] == pytest.approx(high if v["side"] == "upper" else low, abs=1e-9)
    front = next(r for r in data["solutions"] if r["branch"].endswith("elbow-up"))
    wrist = next(v for v in front["violations"] if v["joint"] == "wrist_flex")
    assert wrist["value"] == pytest.approx(99.17, abs=0.01) and wrist["side"] == "upper"
    nearest = data["solutions"][data["nearest"]]
    assert [v["joint"] for v in nearest["violations"]] == ["wrist_flex"]


def test_so101_text_names_the_broken_joint() -> None:
    done = lynxplan(*SO101_DOWN, "--deg")
    assert done.returncode == 0
    assert "no solution: no IK branch within the joint limits" in done.stdout
    assert "wrist_flex = 99.17 deg > upper limit 95 deg" in done.stdout


@pytest.mark.parametrize(
    ("args", "why"),
    [
        (SO101_DOWN, r"no IK branch within the joint limits .* wrist_flex = 1\.731 rad \(99\.17"),
        (
            ("ik", "--robot", "so101", "--position", "2", "0", "0.1", "--approach", "0", "0", "-1"),
            "out of reach",
        ),
        (("ik", "--pose", FAR_POSE), "out of reach"),
        (("ik", "--robot", "so101", "--pose", FAR_POSE), "out of reach"),
        (("ik", "--pose", O2_POSE, "--units", "in"), "exceeds the strict tolerance"),
    ],
)
def test_strict_exits_2_with_one_line_naming_why(args: tuple[str, ...], why: str) -> None:
    done = lynxplan(*args, "--strict", "--json")
    assert done.returncode == 2, done.stdout
    assert done.stdout == ""
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("lynxplan: error:")
    assert re.search(why, lines[0]), lines[0]


@pytest.mark.parametrize("robot", [(), ("--robot", "so101")])
def test_unreachable_without_strict_says_so(robot: tuple[str, ...]) -> None:
    done = lynxplan("ik", *robot, "--pose", FAR_POSE, "--json")
    assert done.returncode == 0
    data = json.loads(done.stdout)
    assert data["status"] == "unreachable" and data["reachable"] is False
    assert data["selected"] is None and "out of reach" in data["message"]
    assert data["distance"] > 4.0  # 5 m away, the arms reach less than 0.6 m


def test_strict_passes_a_reachable_pose() -> None:
    """A pose made by FK (exactly reachable, within limits) passes --strict."""
    from lynxplan.arm import forward_kinematics

    pose = forward_kinematics(np.radians([100, 70, -80, 30, 10]))
    done = lynxplan("ik", "--pose", json.dumps(pose.tolist()), "--strict", "--json", "--deg")
    assert done.returncode == 0, done.stderr
    data = json.loads(done.stdout)
    assert data["status"] == "ok" and data["message"] is None
    np.testing.assert_allclose(
        data["solutions"][data["selected"]]["q"], [100, 70, -80, 30, 10], atol=1e-6
    )


def test_top_level_figures_describe_the_selected_branch() -> None:
    """The report's pose (4 decimals: not exactly reachable): the branches' orientation errors
    differ, and the top-level residual is the selected branch's, not the smallest."""
    done = lynxplan("ik", "--deg", "--units", "in", "--all", "--json", "--pose", O2_POSE)
    assert done.returncode == 0
    data = json.loads(done.stdout)
    selected = data["solutions"][data["selected"]]
    assert selected["branch"] == "front/elbow-up"
    assert data["orientation_residual"] == selected["orientation_error"]
    assert data["position_error"] == selected["position_error"]
    assert min(r["orientation_error"] for r in data["solutions"]) < data["orientation_residual"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ("fk", "90", "45", "-45", "45", "0"),
            r"q1 = 90 is out of range: must be within the joint's limits \[0, 3\.14159\] rad; "
            r"the values look like degrees: add --deg",
        ),
        (
            ("fk", "--robot", "so101", "90", "45", "-45", "45", "0"),
            r"q1 \(joint shoulder_pan\) = 90 is out of range: .*\[-1\.91986, 1\.91986\] rad; "
            r"the values look like degrees: add --deg",
        ),
        (("fk", "--deg", "190", "45", "-45", "45", "0"), r"q1 = 190 .*\[0, 180\] deg"),
    ],
)
def test_fk_beyond_the_limits_is_an_error(args: tuple[str, ...], message: str) -> None:
    done = lynxplan(*args)
    assert done.returncode == 2 and done.stdout == ""
    assert re.search(message, done.stderr), done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_fk_with_deg_and_ignore_limits_still_work() -> None:
    from lynxplan.arm import forward_kinematics

    ok = lynxplan("fk", "90", "45", "-45", "45", "0", "--deg", "--json")
    assert ok.returncode == 0
    np.testing.assert_allclose(
        json.loads(ok.stdout)["T"], forward_kinematics(np.radians([90, 45, -45, 45, 0])), atol=1e-12
    )
    anyway = lynxplan("fk", "90", "45", "-45", "45", "0", "--ignore-limits", "--json")
    assert anyway.returncode == 0
    np.testing.assert_allclose(
        json.loads(anyway.stdout)["T"],
        forward_kinematics(np.array([90, 45, -45, 45, 0.0])),
        atol=1e-9,
    )
