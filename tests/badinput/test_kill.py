"""Kill tests: a run killed with SIGKILL while writing leaves the previous complete output intact,
and the next run succeeds and leaves no staging debris."""

from __future__ import annotations

import hashlib
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from lynxplan.scenarios.folders import MARKER

REPO = Path(__file__).resolve().parents[2]
_CLI = "import sys; from lynxplan.cli import main; raise SystemExit(main(sys.argv[1:]))"


def _lynxplan(*args: str) -> subprocess.Popen[str]:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    return subprocess.Popen(
        [sys.executable, "-c", _CLI, *args],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        cwd=REPO,
    )


def _snapshot(folder: Path) -> dict[str, str]:
    return {
        str(p.relative_to(folder)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def _debris(parent: Path, name: str) -> list[str]:
    return sorted(p.name for p in parent.iterdir() if p.name.startswith(f".{name}."))


def _kill_while_writing(process: subprocess.Popen[str], parent: Path, name: str) -> bool:
    """SIGKILL ``process`` as soon as its staging folder holds an output (its manifest, written
    when the folder is made through a temporary file, does not count: a kill between the two
    leaves a folder with no manifest, which lynxplan rightly never removes); False if it ended
    first."""
    deadline = time.monotonic() + 120.0
    manifest = (MARKER, f"{MARKER}.partial")
    while time.monotonic() < deadline and process.poll() is None:
        for staging in parent.glob(f".{name}.staging-*"):
            if any(p.is_file() and p.name not in manifest for p in staging.rglob("*")):
                process.send_signal(signal.SIGKILL)
                process.communicate(timeout=30)
                return True
        time.sleep(0.005)
    process.kill()
    process.communicate(timeout=30)
    return False


_WORKSPACE = ("workspace", "--cell", "2", "--voxel", "20", "--units", "mm")


@pytest.mark.parametrize(
    ("command", "killed_command"),
    [
        # quick runs (workspace.json only) around a killed full run (plots: a long write phase)
        ((*_WORKSPACE, "--quick"), (*_WORKSPACE, "--samples", "100000")),
        (("run", "{scenario}", "--quick"), ("run", "{scenario}")),
    ],
    ids=["workspace", "run"],
)
def test_sigkill_mid_write_keeps_previous_output(
    tmp_path: Path, command: tuple[str, ...], killed_command: tuple[str, ...]
) -> None:
    scenario = tmp_path / "ws.yaml"
    scenario.write_text(
        "kind: workspace\nunits: {length: mm, angle: deg}\nsamples: 100000\ncell: 2\n"
        "voxel_size: 20\nreport_grid: false\n"
    )
    command = tuple(a.replace("{scenario}", str(scenario)) for a in command)
    killed_command = tuple(a.replace("{scenario}", str(scenario)) for a in killed_command)
    out = tmp_path / "out"
    first = _lynxplan(*command, "--out", str(out))
    _, err = first.communicate(timeout=300)
    assert first.returncode == 0, err
    before = _snapshot(out)
    assert before

    killed = _lynxplan(*killed_command, "--out", str(out))
    assert _kill_while_writing(killed, tmp_path, "out"), "the run ended before it was killed"
    assert killed.returncode == -signal.SIGKILL
    if out.exists():
        assert _snapshot(out) == before, "a killed run changed the previous output"
    else:  # killed between the two renames: the previous output waits to be moved back
        (previous,) = tmp_path.glob(".out.previous-*")
        assert _snapshot(previous) == before
    assert _debris(tmp_path, "out"), "expected the killed run's staging folder"

    again = _lynxplan(*command, "--out", str(out))
    _, err = again.communicate(timeout=300)
    assert again.returncode == 0, err
    assert err == ""
    assert _debris(tmp_path, "out") == [], "stale staging folders were not cleaned up"
    assert set(_snapshot(out)) == set(before)


def test_run_into_foreign_folder_needs_force(tmp_path: Path, capsys) -> None:
    from lynxplan.cli import main

    scenario = tmp_path / "ik.yaml"
    scenario.write_text(
        "kind: parallel_ik\nunits: {length: mm, angle: deg}\npose: [260, 180, 30]\n"
    )
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("do not delete")
    assert main(["run", str(scenario), "--out", str(out), "--quick"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "thesis.tex, which lynxplan did not write" in err
    assert "--force" in err
    assert (out / "thesis.tex").read_text() == "do not delete"
    assert main(["run", str(scenario), "--out", str(out), "--quick", "--force"]) == 0
    # --force replaces lynxplan's outputs only: the user's file stays.
    assert (out / "thesis.tex").read_text() == "do not delete" and (out / "report.json").is_file()
    assert _debris(tmp_path, "mine") == []
