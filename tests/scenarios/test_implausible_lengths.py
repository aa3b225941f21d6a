"""A length implausible for the robot (a file in mm read as metres) warns, naming the key and
the unit that would fit (issue 34, section 4): one line on stderr from the CLI, a Python
warning from the library."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import yaml

import lynxplan
from lynxplan.units import ImplausibleLengthWarning

LYNXPLAN = str(Path(sys.executable).with_name("lynxplan"))
WINDOW = Path(__file__).resolve().parents[2] / "scenarios" / "planning" / "p04_window.yaml"


def _mm_read_as_metres() -> dict[str, object]:
    """The window problem with its obstacles written in mm while the file says metres."""
    data = yaml.safe_load(WINDOW.read_text())
    for obstacle in data["obstacles"]:
        for key in ("centre", "size"):
            obstacle[key] = [v * 1000 for v in obstacle[key]]
    return data


def test_cli_warns_in_one_line(tmp_path: Path) -> None:
    scenario = tmp_path / "mm.yaml"
    scenario.write_text(yaml.safe_dump(_mm_read_as_metres()))
    done = subprocess.run(
        [LYNXPLAN, "run", str(scenario), "--quick", "--out", str(tmp_path / "out")],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    warnings = [line for line in done.stderr.splitlines() if "warning" in line]
    assert warnings == [
        "lynxplan: warning: obstacles[0].centre: 105 m is 251 times the robot's reach "
        "(0.419 m) (9 more lengths like it); is the file in mm? (units: {length: mm})"
    ], done.stderr


def test_library_warns_and_plausible_files_do_not() -> None:
    with pytest.warns(ImplausibleLengthWarning, match=r"obstacles\[0\]\.centre: .*in mm\?"):
        lynxplan.run_scenario(_mm_read_as_metres())
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", ImplausibleLengthWarning)
        lynxplan.run_scenario(WINDOW)  # the shipped file: no warning


def test_task_scenarios_warn_too() -> None:
    """The OK task with its obstacles written in thousandths of an inch while the file says
    inches: the task kind warns as the plan kind does (the run may then fail on its own terms)."""
    task = yaml.safe_load((WINDOW.parents[1] / "ok_task.yaml").read_text())
    assert task["units"]["length"] == "in"
    for obstacle in task["obstacles"]:
        obstacle["min_corner"] = [v * 1000 for v in obstacle["min_corner"]]
    import contextlib

    # the warning comes before the run can fail on the lengths
    with (
        contextlib.suppress(lynxplan.LynxplanError),
        pytest.warns(ImplausibleLengthWarning, match=r"obstacles\[0\]\.min_corner: "),
    ):
        lynxplan.run_scenario(task, quick=True)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", ImplausibleLengthWarning)
        lynxplan.run_scenario(WINDOW.parents[1] / "ok_task.yaml", quick=True)  # no warning
