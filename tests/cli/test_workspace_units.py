"""``lynxplan workspace``: every printed and plotted quantity carries the unit it is in, and the
default unit is the metre, as for every command (issue 34, section 4)."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import pytest

LYNXPLAN = str(Path(sys.executable).with_name("lynxplan"))
INCH = 0.0254  # [m], by definition


def _workspace(out: Path, *units: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [LYNXPLAN, "workspace", "--samples", "20000", "--out", str(out), *units],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )


def _png_text(path: Path) -> str:
    """The PNG's Description text chunk (read with Pillow, a matplotlib dependency)."""
    from PIL import Image

    with Image.open(path) as image:
        return str(image.text.get("Description", ""))  # type: ignore[attr-defined]


@pytest.mark.parametrize(("units", "unit"), [((), "m"), (("--units", "in"), "in")])
def test_printed_and_plotted_units_are_the_ones_used(
    tmp_path: Path, units: tuple[str, ...], unit: str
) -> None:
    done = _workspace(tmp_path / "w", *units)
    assert done.returncode == 0, done.stderr
    summary = json.loads((tmp_path / "w" / "workspace.json").read_text())
    assert summary["units"] == {"length": unit, "volume": f"{unit}^3"}
    factor = 1.0 if unit == "m" else INCH
    assert summary["volume"] == pytest.approx(summary["volume_m3"] / factor**3, rel=1e-12)
    printed = re.search(r"volume ([0-9.e+-]+) (\S+)", done.stdout)
    assert printed is not None, done.stdout
    assert printed[2] == f"{unit}^3"
    assert float(printed[1]) == pytest.approx(summary["volume"], rel=1e-3)
    other = "in" if unit == "m" else " m"
    assert f"{other}^3" not in done.stdout
    for name in ("workspace_3d.png", "workspace_projections.png", "workspace_section.png"):
        text = _png_text(tmp_path / "w" / name)
        assert f"[{unit}]" in text, (name, text)
        assert "in Z" not in text and "in Y" not in text and "in X" not in text
    section = _png_text(tmp_path / "w" / "workspace_section.png")
    assert f"{summary['volume']:.4g} {unit}^3" in section
    assert " L " not in section and "mm" not in section
    assert "top view: projection onto the x-y plane" in _png_text(
        tmp_path / "w" / "workspace_projections.png"
    )
