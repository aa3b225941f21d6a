"""The meshcat HTML export: self-contained file, scene content, server process stopped, errors."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

from lynxplan.collision import CylinderObstacle, axis_aligned_box
from lynxplan.exceptions import InputError, NonFiniteInputError, ShapeError
from lynxplan.viz import WritingPlane, _frame_from_normal, _path_runs, export_html, tilted_plane


def _children() -> set[int]:
    """Process ids whose parent is this process."""
    children = set()
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == os.getpid():
                children.add(int(entry.name))
    return children


def test_export_writes_a_self_contained_file_and_stops_the_server(arm, tmp_path):
    before = _children()
    q = np.linspace(np.zeros(5), np.radians([90.0, 45, -45, 30, 0]), 101)
    t = np.linspace(0.0, 2.0, 101)
    out = export_html(
        arm, q, t, tmp_path / "motion.html", path=arm.fk(q)[:, :3, 3],
        motion=["line"] * 50 + ["free"] * 51,
        obstacles=[axis_aligned_box("wall", [0.1, 0.1, -0.1], [0.05, 0.05, 0.2]),
                   CylinderObstacle("post", [-0.2, 0, 0], 0.02, 0.2)],
        plane=tilted_plane([0.0, 0.2, 0.0]),
    )  # fmt: skip
    html = out.read_text()
    assert html.lstrip().startswith("<!DOCTYPE html>")
    assert "<script src=" not in html.replace(" ", "")  # no external scripts
    assert len(html) > 100_000  # the viewer's JavaScript is inlined
    assert _children() - before == set()


def test_path_runs_split_by_motion_and_share_endpoints():
    path = np.arange(15.0).reshape(5, 3)
    runs = list(_path_runs(path, ["line", "line", "free", "free", "line"]))
    assert [label for label, _ in runs] == ["line", "free", "line"]
    np.testing.assert_array_equal(runs[1][1], path[1:4])  # starts where the line ended
    np.testing.assert_array_equal(runs[2][1], path[3:5])


def test_tilted_plane_rises_along_y():
    plane = tilted_plane([0.0, 0.2, 0.0], tilt_deg=20.0)
    rotation = _frame_from_normal(plane.normal)
    np.testing.assert_allclose(rotation.T @ rotation, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(
        rotation[:, 2], [0.0, -np.sin(np.radians(20)), np.cos(np.radians(20))]
    )
    # The in-plane y axis rises 20 deg along +y.
    assert np.degrees(np.arctan2(rotation[2, 1], rotation[1, 1])) == pytest.approx(20.0)
    assert WritingPlane(np.zeros(3), np.array([0.0, 0, 1])).size == (0.3, 0.3)


def test_tilted_plane_axes_are_x_then_the_rising_direction():
    tilt = np.radians(20.0)
    c, s = np.cos(tilt), np.sin(tilt)
    plane = WritingPlane.tilted([0.0, 0.2, 0.0], tilt, (0.25, 0.2))
    expected = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    np.testing.assert_allclose(plane.rotation, expected, atol=1e-15)
    assert plane.size == (0.25, 0.2)


def test_export_errors(arm, tmp_path):
    q, t = np.zeros((3, 5)), np.array([0.0, 1.0, 2.0])
    out = tmp_path / "x.html"
    with pytest.raises(ShapeError, match=r"q must have shape \(N, 5\). Got: \(3, 4\)"):
        export_html(arm, np.zeros((3, 4)), t, out)
    with pytest.raises(ShapeError, match=r"t must have shape \(3,\)"):
        export_html(arm, q, t[:2], out)
    with pytest.raises(NonFiniteInputError, match="q or t contains NaN"):
        export_html(arm, q, [0.0, np.nan, 2.0], out)
    with pytest.raises(InputError, match="fps must be positive"):
        export_html(arm, q, t, out, fps=0.0)
    with pytest.raises(InputError, match=r"one label per path point: 2 != 3"):
        export_html(arm, q, t, out, path=np.zeros((3, 3)), motion=["line", "free"])
    with pytest.raises(ShapeError, match=r"path must have shape \(M, 3\)"):
        export_html(arm, q, t, out, path=np.zeros((3, 2)))
    with pytest.raises(InputError, match="camera_position must be a finite, non-zero"):
        export_html(arm, q, t, out, camera_position=(0.0, 0.0, 0.0))
    assert not out.exists()
