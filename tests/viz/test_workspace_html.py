"""The workspace HTML view: axes, the robot at a reference pose, points coloured by height."""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np
import pytest
from browser import CHROMIUM, screenshot

import lynxplan
from lynxplan.arm.workspace_report import reference_skeleton, write_html


def test_reference_skeleton_ends_at_the_tool_point_of_the_mid_range_pose(arm) -> None:
    skeleton = reference_skeleton(arm)
    lower, upper = arm.model.lowerPositionLimit, arm.model.upperPositionLimit
    q = 0.5 * (np.clip(lower, -np.pi, np.pi) + np.clip(upper, -np.pi, np.pi))
    np.testing.assert_allclose(skeleton[0], np.zeros(3), atol=1e-12)
    np.testing.assert_allclose(skeleton[-1], arm.fk(q)[:3, 3], atol=1e-12)
    assert (np.linalg.norm(np.diff(skeleton, axis=0), axis=1) > 1e-6).all()
    so101 = lynxplan.load_robot("so101")
    assert reference_skeleton(so101).shape[0] >= 4


def _dark(pixels: np.ndarray) -> np.ndarray:
    return pixels.max(axis=-1) < 60


def _axis_red(pixels: np.ndarray) -> np.ndarray:
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    return (r > 170) & (g < 90) & (b < 90)


def test_page_draws_robot_axes_and_height_colours(arm, tmp_path: Path) -> None:
    rng = np.random.default_rng(0)
    points = rng.uniform(-0.3, 0.3, size=(5_000, 3))
    skeleton = reference_skeleton(arm)
    with_robot, bare = tmp_path / "robot.html", tmp_path / "bare.html"
    write_html(points, with_robot, "mm", skeleton)
    write_html(points, bare, "mm")
    text = with_robot.read_text()
    robot = json.loads(re.search(r"const ROBOT = (\[.*?\]);", text).group(1))
    np.testing.assert_allclose(robot, skeleton * 1e3, atol=1e-3)  # in the page's unit (mm)
    zlo = float(re.search(r"ZLO = ([-0-9.]+)", text).group(1))
    assert zlo == pytest.approx(points[:, 2].min() * 1e3, abs=1e-3)
    if CHROMIUM is None:
        pytest.skip("chromium is not installed (apt-get install chromium)")
    image = screenshot(with_robot, tmp_path / "robot.png", tmp_path / "p1", 800, 600)
    plain = screenshot(bare, tmp_path / "bare.png", tmp_path / "p2", 800, 600)
    assert _dark(image).sum() > _dark(plain).sum() + 300  # the robot's thick dark polyline
    assert _axis_red(plain).sum() > 50  # the x axis
    # Coloured by height: the top rows of the cloud are yellow, the bottom ones purple.
    r, g, b = (image[..., k] for k in range(3))
    yellow, purple = (r > 200) & (g > 200) & (b < 100), (r > 50) & (g < 40) & (b > 70)
    rows_yellow, rows_purple = np.nonzero(yellow)[0], np.nonzero(purple)[0]
    assert len(rows_yellow) > 100 and len(rows_purple) > 100
    assert rows_yellow.mean() < rows_purple.mean()
