"""The OK task's own HTML export, as `lynxplan run` writes it, opened in headless Chromium."""

from __future__ import annotations

from pathlib import Path

import pytest
from browser import CHROMIUM, neutral, orange, path_blue, path_red, screenshot

from lynxplan.scenarios import run_scenario

OK_TASK = Path(__file__).resolve().parents[2] / "scenarios" / "ok_task.yaml"
WIDTH, HEIGHT = 1000, 700


def test_ok_task_html_shows_walls_arm_and_pen_path_by_motion(tmp_path: Path) -> None:
    if CHROMIUM is None:
        pytest.skip("chromium is not installed (apt-get install chromium)")
    out = tmp_path / "out"
    assert run_scenario(OK_TASK, out).ok
    image = screenshot(out / "ok_task.html", tmp_path / "ok.png", tmp_path / "profile",
                       WIDTH, HEIGHT)  # fmt: skip
    assert orange(image).sum() > 5_000  # both walls, semi-transparent orange
    assert neutral(image).sum() > 2_000  # the arm (grey, aluminium, black)
    assert path_red(image).sum() >= 10  # straight-line strokes of the letters
    assert path_blue(image).sum() >= 200  # free motions
    # The background alone has none of the path colours.
    corner = image[:80, :250]
    assert not path_red(corner).any() and not path_blue(corner).any()
