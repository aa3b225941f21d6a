"""Sampled workspace of any robot, checked against the AL5's own closed-form estimate."""

from __future__ import annotations

import numpy as np
import pytest

import lynxplan
from lynxplan.arm.model import load_arm
from lynxplan.arm.workspace import estimate_workspace
from lynxplan.exceptions import OutOfRangeError
from lynxplan.robots.workspace import sample_workspace

SAMPLES = 300_000


def test_al5_from_urdf_matches_the_closed_form_estimate() -> None:
    # The same seed draws the same configurations: Pinocchio FK of the URDF robot and the AL5's
    # planar closed form must give the same extremes; voxel grids differ only in their origin.
    sampled = sample_workspace(lynxplan.load_robot("al5"), samples=SAMPLES, voxel_size=0.02, seed=1)
    arm = load_arm()
    closed = estimate_workspace(arm.geometry, arm.limits, samples=SAMPLES, voxel_size=0.02, seed=1)
    assert sampled.max_reach == pytest.approx(closed.max_reach, abs=1e-12)
    assert sampled.z_range == pytest.approx(closed.z_range, abs=1e-12)
    assert sampled.volume_voxels == pytest.approx(closed.volume_voxels, rel=0.03)


def test_so101_points_are_its_fk_and_the_volume_grows_with_samples() -> None:
    robot = lynxplan.load_robot("so101")
    small = sample_workspace(robot, samples=20_000, voxel_size=0.01, seed=2)
    large = sample_workspace(robot, samples=100_000, voxel_size=0.01, seed=2)
    assert small.volume_voxels < large.volume_voxels
    assert large.z_range[0] <= small.z_range[0] and large.z_range[1] >= small.z_range[1]
    # Every kept point is the tool point of a configuration within the limits: no point lies
    # beyond the longest chain of joint offsets plus the tool offset.
    placements = [np.linalg.norm(p.translation) for p in robot.model.jointPlacements[1:]]
    bound = sum(placements) + np.linalg.norm(robot.fk(np.zeros(5))[:3, 3])
    assert np.linalg.norm(large.positions, axis=1).max() <= bound
    assert large.max_reach <= bound


def test_voxel_too_small_is_refused() -> None:
    with pytest.raises(OutOfRangeError, match="voxel_size"):
        sample_workspace(lynxplan.load_robot("so101"), samples=10, voxel_size=1e-7)


def test_workspace_command_takes_a_robot(tmp_path, capsys) -> None:
    from lynxplan.cli import main

    out = tmp_path / "ws"
    assert main(["workspace", "--robot", "so101", "--samples", "5000", "--out", str(out)]) == 0
    assert "workspace of so101" in capsys.readouterr().out
    assert (out / "workspace.json").is_file() and (out / "workspace.html").is_file()
    # A tool frame is never silently ignored: the AL5 has no frame 'pen'.
    commands = (
        ["workspace", "--quick", "--tool", "pen", "--out", str(tmp_path / "x")],
        ["fk", "--tool", "pen", "0", "0", "0", "0", "0"],
    )
    for command in commands:
        capsys.readouterr()
        assert main(command) == 2
        assert "has no frame 'pen'" in capsys.readouterr().err


def test_workspace_scenario_of_a_urdf_robot_reports_what_it_measured(tmp_path) -> None:
    import json

    from lynxplan.scenarios import run_scenario

    body = {
        "kind": "workspace",
        "robot": {"name": "so101"},
        "units": {"length": "m", "angle": "deg"},
        "samples": 20_000,
        "voxel_size": 0.01,
        "expect": {"min_volume_voxels": 0.001, "min_volume": 0.001},
    }
    result = run_scenario(body, tmp_path / "out", quick=True)
    summary = json.loads((tmp_path / "out" / "workspace.json").read_text())
    assert summary["volume_voxels"] == pytest.approx(result.metrics["volume_voxels"], rel=1e-12)
    assert result.expectations[0].passed  # the voxel volume is measured
    # The planar revolution volume is the AL5's: not measured, and the message says why.
    assert not result.expectations[1].passed
    assert "not measured" in result.expectations[1].message
    assert "use volume_voxels" in result.expectations[1].message
