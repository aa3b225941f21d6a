"""``load_robot(..., calibration=)`` and ``--calibration`` through the real command line."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import lynxplan
from lynxplan.lerobot import CalibrationWarning


def test_load_robot_with_a_calibration(calibration_file):
    with pytest.warns(CalibrationWarning, match=r"shoulder_lift \-104.3\.\.\+104.3 deg"):
        robot = lynxplan.load_robot("so101", calibration=calibration_file)
    assert robot.limits.position[1, 1] == pytest.approx(math.radians(1186 * 360 / 4095), abs=1e-12)
    plain = lynxplan.load_robot("so101")  # the cached built-in is left as it was
    np.testing.assert_allclose(plain.limits.position[1], [-1.74533, 1.74533])


def _cli(*args):
    return subprocess.run(
        [sys.executable, "-m", "lynxplan.cli", *args], capture_output=True, text=True, timeout=300
    )


def test_robot_info_with_calibration(calibration_file, tmp_path):
    done = _cli("robot", "info", "so101", "--calibration", str(calibration_file), "--deg", "--json")
    assert done.returncode == 0, done.stderr
    joints = {j["name"]: j for j in json.loads(done.stdout)["joints"]}
    assert joints["elbow_flex"]["upper"] == pytest.approx(1085 * 360 / 4095, abs=1e-9)
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: calibration ")
    assert "shoulder_pan" in lines[0] and "elbow_flex" not in lines[0]
    missing = _cli("robot", "info", "so101", "--calibration", str(tmp_path / "none.json"))
    assert missing.returncode == 2
    assert missing.stderr.strip().endswith("none.json: file not found")
    assert "Traceback" not in missing.stderr
