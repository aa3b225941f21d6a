"""Headless Chromium screenshots of exported HTML, and colour masks, for the browser tests."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np

CHROMIUM = shutil.which("chromium") or shutil.which("chromium-browser")


def screenshot(html: Path, png: Path, profile: Path, width: int, height: int) -> np.ndarray:
    """Render ``html`` (8 s of virtual time) and return the screenshot, shape (H, W, 3), int."""
    from PIL import Image

    command = [
        str(CHROMIUM), "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
        "--enable-unsafe-swiftshader", "--no-first-run", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", f"--user-data-dir={profile}",
        "--virtual-time-budget=8000", f"--window-size={width},{height}",
        f"--screenshot={png}", html.as_uri(),
    ]  # fmt: skip
    subprocess.run(command, check=True, capture_output=True, timeout=120)
    return np.asarray(Image.open(png).convert("RGB"), dtype=int)


def orange(pixels: np.ndarray) -> np.ndarray:
    """Obstacle orange."""
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    return (r > 150) & (r - b > 80) & (g > 50) & (g < r - 30)


def neutral(pixels: np.ndarray) -> np.ndarray:
    """Grey, black or aluminium (the arm); meshcat's sky-blue background has b - r >= 87."""
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    return (np.abs(r - b) < 40) & (np.abs(r - g) < 40)


def path_red(pixels: np.ndarray) -> np.ndarray:
    """Red pen-path lines, also where seen through the translucent plane (not orange: g ~ b)."""
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    return (r > 120) & (r - g > 55) & (np.abs(g - b) < 25)


def path_blue(pixels: np.ndarray) -> np.ndarray:
    """Saturated blue pen-path lines (the sky gradient never has r < 60 with b > 200)."""
    r, g, b = pixels[..., 0], pixels[..., 1], pixels[..., 2]
    return (b > 200) & (r < 60) & (g < 110)
