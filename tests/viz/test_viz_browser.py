"""The exported meshcat HTML, opened in headless Chromium: the arm and the obstacles are drawn."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from browser import CHROMIUM, neutral, orange, path_red, screenshot

from lynxplan.collision import SphereObstacle, axis_aligned_box
from lynxplan.viz import export_html, tilted_plane

WIDTH, HEIGHT = 800, 600
#: meshcat's default perspective camera: vertical field of view, in [deg].
CAMERA_FOV_DEG = 75.0
CAMERA_POSITION = np.array([0.4, -0.2, 0.3])
#: meshcat's orbit target: the world origin.
CAMERA_TARGET = np.zeros(3)
POSE = np.radians([90.0, 60.0, -60.0, 60.0, 0.0])


def _project(point: np.ndarray) -> tuple[float, float]:
    """Pixel (column, row) of a world point seen by the camera (look-at, z up)."""
    forward = CAMERA_TARGET - CAMERA_POSITION
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    d = point - CAMERA_POSITION
    depth = d @ forward
    scale = np.tan(np.radians(CAMERA_FOV_DEG) / 2.0)
    x = (d @ right) / (depth * scale * WIDTH / HEIGHT)
    y = (d @ up) / (depth * scale)
    return (x + 1.0) / 2.0 * WIDTH, (1.0 - y) / 2.0 * HEIGHT


def _screenshot(html: Path, png: Path, profile: Path) -> np.ndarray:
    return screenshot(html, png, profile, WIDTH, HEIGHT)


_orange, _neutral = orange, neutral


def _window(mask: np.ndarray, centre: tuple[float, float], half: int) -> np.ndarray:
    col, row = round(centre[0]), round(centre[1])
    return mask[max(row - half, 0) : row + half, max(col - half, 0) : col + half]


@pytest.fixture(scope="module")
def screenshots(arm, tmp_path_factory):
    if CHROMIUM is None:
        pytest.skip("chromium is not installed (apt-get install chromium)")
    folder = tmp_path_factory.mktemp("viz")
    ball = SphereObstacle("ball", [0.25, 0.05, 0.05], 0.03)
    wall = axis_aligned_box("wall", [-0.1, 0.3, -0.05], [0.2, 0.02, 0.1])
    q = np.stack([POSE, POSE])
    t = np.array([0.0, 1.0])
    tip = arm.fk(q)[:, :3, 3]
    common = {"camera_position": CAMERA_POSITION, "autoplay": False}
    full = export_html(
        arm, q, t, folder / "scene.html", path=tip + np.array([[0, 0, 0], [0.05, 0, 0]]),
        motion=["line", "line"], obstacles=[ball, wall],
        plane=tilted_plane([0.0, 0.2, -0.08]), **common,
    )  # fmt: skip
    bare = export_html(arm, q, t, folder / "bare.html", **common)
    return (
        _screenshot(full, folder / "scene.png", folder / "profile1"),
        _screenshot(bare, folder / "bare.png", folder / "profile2"),
        (ball, wall),
    )


def test_obstacles_are_drawn_where_they_are(screenshots):
    full, bare, (ball, wall) = screenshots
    assert full.shape == (HEIGHT, WIDTH, 3)
    for obstacle in (ball, wall):
        where = _project(obstacle.centre)
        assert 0 <= where[0] < WIDTH
        assert 0 <= where[1] < HEIGHT
        assert _window(_orange(full), where, 12).mean() > 0.5, obstacle.name
        assert not _window(_orange(bare), where, 12).any(), obstacle.name
    # Nothing orange far from the obstacles (e.g. the top-left corner).
    assert not _orange(full)[:60, :60].any()


def test_arm_is_drawn(arm, screenshots):
    full, bare, _ = screenshots
    points = {
        "base": np.array([0.0, 0.0, -0.05]),
        "upper arm": arm.frame_placement(POSE, "dh_frame_2")[:3, 3] / 2.0,
        "wrist": arm.frame_placement(POSE, "dh_frame_4")[:3, 3],
    }
    for image in (full, bare):
        for name, point in points.items():
            assert _window(_neutral(image), _project(point), 4).mean() > 0.9, name
    # The camera looks at the shoulder: the frame is not all arm.
    assert _neutral(bare).mean() < 0.2
    # Black base housing (r = 48 mm, z -70...-30 mm): its side facing the camera is dark.
    towards_camera = CAMERA_POSITION[:2] / np.linalg.norm(CAMERA_POSITION[:2])
    side = np.array([*(0.047 * towards_camera), -0.05])
    base = _window(bare, _project(side), 3).reshape(-1, 3)
    assert (base.max(axis=1) < 60).all()


def test_animation_plays_to_the_last_pose(arm, tmp_path):
    if CHROMIUM is None:
        pytest.skip("chromium is not installed (apt-get install chromium)")
    end = np.radians([20.0, 60.0, -60.0, 60.0, 0.0])
    q = np.linspace(POSE, end, 31)
    html = export_html(arm, q, np.linspace(0.0, 1.0, 31), tmp_path / "anim.html",
                       camera_position=CAMERA_POSITION)  # fmt: skip
    # 8 s of virtual time: the 1 s clip has played once and stays on its last frame.
    image = _screenshot(html, tmp_path / "anim.png", tmp_path / "profile")
    wrist_end = _project(arm.frame_placement(end, "dh_frame_4")[:3, 3])
    wrist_start = _project(arm.frame_placement(POSE, "dh_frame_4")[:3, 3])
    assert _window(_neutral(image), wrist_end, 4).mean() > 0.9
    assert not _window(_neutral(image), wrist_start, 4).any()


def _floor(pixels: np.ndarray) -> np.ndarray:
    """The floor grid's pale blue (the sky behind the floor, in the lower half, is dark)."""
    r, b = pixels[..., 0], pixels[..., 2]
    return (b - r > 40) & (r > 120)


def test_default_view_frames_the_strokes_over_a_floor_and_through_obstacles(arm, tmp_path):
    """No camera given: the page looks at the pen path, draws a floor grid under the arm, and
    the strokes inside a translucent box stay pure red (drawn over the obstacles)."""
    if CHROMIUM is None:
        pytest.skip("chromium is not installed (apt-get install chromium)")
    square = np.array([[-0.03, 0.22, -0.02], [0.03, 0.22, -0.02], [0.03, 0.28, -0.02],
                       [-0.03, 0.28, -0.02], [-0.03, 0.22, -0.02]])  # fmt: skip
    jar = axis_aligned_box("jar", [-0.06, 0.19, -0.06], [0.12, 0.12, 0.08])
    q = np.stack([POSE, POSE])
    html = export_html(arm, q, np.array([0.0, 1.0]), tmp_path / "task.html", path=square,
                       motion=["line"] * 5, obstacles=[jar], autoplay=False)  # fmt: skip
    image = _screenshot(html, tmp_path / "task.png", tmp_path / "profile")
    red = path_red(image)
    assert red.sum() >= 60  # four 6 cm strokes (~90 px), not tinted by the box
    rows, cols = np.nonzero(red)
    # Framed: the strokes lie around the middle of the picture, not at its edge.
    assert 0.2 * HEIGHT < rows.mean() < 0.8 * HEIGHT
    assert 0.2 * WIDTH < cols.mean() < 0.8 * WIDTH
    assert _floor(image[HEIGHT // 2 :]).sum() >= 500
