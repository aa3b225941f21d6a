"""Output folders never lose a user's file (issue 34, section 5), through the real command line.

Each test runs ``lynxplan run`` as a user would (the installed console script, in a fresh folder,
on real files) and checks what is left on disk. lynxplan writes a manifest (``.lynxplan-output``)
naming each output and its SHA-256; everything else is the user's and stays.
"""

from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from lynxplan.scenarios.folders import MARKER, OutputFolderError, folder_name
from lynxplan.scenarios.runner import run_scenario

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
PARALLEL_IK = SCENARIOS / "parallel_ik.yaml"  # ~1 s: report.json + parallel_ik.json
STRAIGHT_LINE = SCENARIOS / "straight_line.yaml"  # CSV first, then three plots (not --quick)
_SCRIPT = Path(sys.executable).with_name("lynxplan")
LYNXPLAN = [str(_SCRIPT)] if _SCRIPT.is_file() else [sys.executable, "-m", "lynxplan.cli"]


def lynxplan(cwd: Path, *args: object) -> subprocess.CompletedProcess[str]:
    """``lynxplan run ARGS`` in ``cwd``."""
    command = [*LYNXPLAN, "run", *map(str, args)]
    return subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=600)


def snapshot(folder: Path) -> dict[str, bytes]:
    """Every file under ``folder`` (relative path -> content)."""
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def leftovers(parent: Path) -> list[str]:
    return sorted(
        p.name for p in parent.iterdir() if ".staging-" in p.name or ".previous-" in p.name
    )


def test_without_out_a_run_writes_out_scenario_name_and_reruns_just_work(tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "plan.txt").write_text("mine")  # the user's file beside the outputs
    first = lynxplan(tmp_path, PARALLEL_IK, "--quick")
    assert first.returncode == 0, first.stderr
    out = tmp_path / "out" / "report_pose"  # name: "report pose"
    assert "outputs in out/report_pose/" in first.stdout
    assert sorted(snapshot(out)) == [MARKER, "parallel_ik.json", "report.json"]
    again = lynxplan(tmp_path, PARALLEL_IK, "--quick")  # a re-run needs no --force
    assert again.returncode == 0, again.stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["plan.txt", "report_pose"]
    assert (tmp_path / "out" / "plan.txt").read_text() == "mine"


def test_a_users_file_in_an_earlier_output_folder_is_refused_and_kept(tmp_path):
    out = tmp_path / "results"
    assert lynxplan(tmp_path, PARALLEL_IK, "--quick", "--out", out).returncode == 0
    (out / "notes.txt").write_text("my measurements")
    before = snapshot(out)
    refused = lynxplan(tmp_path, PARALLEL_IK, "--quick", "--out", out)
    assert refused.returncode == 2
    [line] = refused.stderr.splitlines()
    assert "notes.txt" in line and "--force" in line and "did not write" in line
    assert snapshot(out) == before
    assert leftovers(tmp_path) == []


def test_force_replaces_only_lynxplans_outputs(tmp_path):
    out = tmp_path / "out" / "line"
    (tmp_path / "out" / "other").mkdir(parents=True)
    (tmp_path / "out" / "other" / "keep.csv").write_text("1,2\n")
    assert lynxplan(tmp_path, STRAIGHT_LINE, "--out", out).returncode == 0  # with plots
    assert (out / "joint_profiles.png").is_file()
    (out / "notes.txt").write_text("mine")
    (out / "photos").mkdir()
    (out / "photos" / "setup.jpg").write_bytes(b"\xff\xd8 jpeg")
    forced = lynxplan(tmp_path, STRAIGHT_LINE, "--quick", "--out", out, "--force")
    assert forced.returncode == 0, forced.stderr
    # The old plots went (lynxplan's, not written again by --quick); the user's files stay.
    assert sorted(snapshot(out)) == [
        MARKER,
        "notes.txt",
        "photos/setup.jpg",
        "report.json",
        "trajectory.csv",
    ]
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "photos" / "setup.jpg").read_bytes() == b"\xff\xd8 jpeg"
    assert (tmp_path / "out" / "other" / "keep.csv").read_text() == "1,2\n"
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["line", "other"]
    # The files a forced run kept are accepted by the next runs; a new foreign file is not.
    assert lynxplan(tmp_path, STRAIGHT_LINE, "--quick", "--out", out).returncode == 0
    (out / "draft.md").write_text("new")
    refused = lynxplan(tmp_path, STRAIGHT_LINE, "--quick", "--out", out)
    assert refused.returncode == 2 and "draft.md" in refused.stderr


def test_a_failing_run_never_deletes_foreign_files(tmp_path):
    strict = tmp_path / "strict.yaml"
    # The expected angles are printed to 4 decimals: a 1e-9 deg tolerance cannot hold.
    strict.write_text(PARALLEL_IK.read_text().replace("tolerance: 1.0e-4", "tolerance: 1.0e-9"))
    out = tmp_path / "out"
    assert lynxplan(tmp_path, PARALLEL_IK, "--quick", "--out", out).returncode == 0
    (out / "notes.txt").write_text("mine")
    assert lynxplan(tmp_path, strict, "--quick", "--out", out).returncode == 2  # refused first
    failed = lynxplan(tmp_path, strict, "--quick", "--out", out, "--force")
    assert failed.returncode == 1, failed.stderr
    assert (out / "notes.txt").read_text() == "mine"
    assert json.loads((out / "report.json").read_text())["passed"] is False
    assert leftovers(tmp_path) == []


def test_a_foreign_file_named_like_an_output_is_never_overwritten(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "report.json").write_text('{"mine": true}')
    done = lynxplan(tmp_path, PARALLEL_IK, "--quick", "--out", out, "--force")
    assert done.returncode == 2
    assert "report.json" in done.stderr and len(done.stderr.splitlines()) == 1
    assert snapshot(out) == {"report.json": b'{"mine": true}'}
    assert leftovers(tmp_path) == []


def test_an_edited_output_is_kept_unless_forced(tmp_path):
    out = tmp_path / "out"
    assert lynxplan(tmp_path, PARALLEL_IK, "--quick", "--out", out).returncode == 0
    (out / "parallel_ik.json").write_text("edited by hand")
    refused = lynxplan(tmp_path, PARALLEL_IK, "--quick", "--out", out)
    assert refused.returncode == 2 and "parallel_ik.json was changed" in refused.stderr
    assert (out / "parallel_ik.json").read_text() == "edited by hand"
    assert lynxplan(tmp_path, PARALLEL_IK, "--quick", "--out", out, "--force").returncode == 0
    assert json.loads((out / "parallel_ik.json").read_text())["pose"] == [260, 180, 30]


def test_a_run_killed_mid_write_leaves_the_previous_outputs_and_no_staging(tmp_path):
    out = tmp_path / "line"
    assert lynxplan(tmp_path, STRAIGHT_LINE, "--quick", "--out", out).returncode == 0
    (out / "notes.txt").write_text("mine")
    assert lynxplan(tmp_path, STRAIGHT_LINE, "--quick", "--out", out, "--force").returncode == 0
    before = snapshot(out)
    not_ours = tmp_path / ".line.staging-4194305-abcdefgh"  # staging-like name, no manifest
    not_ours.mkdir()
    (not_ours / "data.bin").write_bytes(b"user")
    # A full run writes trajectory.csv, then its plots: kill it once the CSV is staged.
    process = subprocess.Popen(
        [*LYNXPLAN, "run", str(STRAIGHT_LINE), "--out", str(out)],
        cwd=tmp_path,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        staged = _wait_for_staged(tmp_path, ".line.staging-", "trajectory.csv", process)
        os.kill(process.pid, signal.SIGKILL)
    finally:
        process.kill()
        process.wait()
    assert process.returncode == -signal.SIGKILL
    assert staged.is_dir()  # killed mid-write: the staging folder was left behind
    assert snapshot(out) == before
    # The next run removes the dead run's staging folder, not the user's look-alike.
    assert lynxplan(tmp_path, STRAIGHT_LINE, "--quick", "--out", out).returncode == 0
    assert leftovers(tmp_path) == [not_ours.name]
    assert (not_ours / "data.bin").read_bytes() == b"user"
    assert (out / "notes.txt").read_text() == "mine"


def _wait_for_staged(
    parent: Path, prefix: str, name: str, process: subprocess.Popen[bytes]
) -> Path:
    """The staging folder once ``name`` is written into it (polls; the run writes for seconds)."""
    deadline = time.monotonic() + 600  # a safety net against a hang, not a timing check
    while time.monotonic() < deadline and process.poll() is None:
        for folder in parent.glob(f"{prefix}*"):
            if (folder / MARKER).is_file() and (folder / name).is_file():
                return folder
        time.sleep(0.005)
    raise AssertionError(f"the run ended (exit {process.returncode}) before staging {name}")


def test_without_hard_links_the_outputs_are_moved_in_file_by_file(tmp_path, monkeypatch):
    # A file system without hard links (FAT, some network shares) refuses os.link with EPERM.
    out = tmp_path / "out"
    run_scenario(PARALLEL_IK, out, quick=True)
    (out / "notes.txt").write_text("mine")

    def no_link(*args: object, **kwargs: object) -> None:
        raise OSError(errno.EPERM, "Operation not permitted")

    monkeypatch.setattr(os, "link", no_link)
    run_scenario(PARALLEL_IK, out, quick=True, force=True)
    assert sorted(snapshot(out)) == [MARKER, "notes.txt", "parallel_ik.json", "report.json"]
    assert (out / "notes.txt").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out"]
    run_scenario(PARALLEL_IK, out, quick=True)  # the kept file is accepted, the outputs own


@pytest.mark.parametrize(
    ("name", "path", "folder"),
    [
        ("free motion (report example)", "free_motion.yaml", "free_motion_report_example"),
        ("ok_task", "ok_task.yaml", "ok_task"),
        ("", "singularity_line.yaml", "singularity_line"),
        ("../..", "x.yaml", "x"),
    ],
)
def test_the_default_folder_name(name, path, folder):
    assert folder_name(name, path) == folder


def test_a_folder_written_before_the_manifest_is_still_lynxplans(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / MARKER).write_text("written by lynxplan; replaced as a whole by each run\n")
    (out / "report.json").write_text(json.dumps({"artifacts": ["parallel_ik.json", "report.json"]}))
    (out / "parallel_ik.json").write_text("{}")
    (out / "notes.txt").write_text("mine")
    with pytest.raises(OutputFolderError, match=r"holds notes\.txt"):
        run_scenario(PARALLEL_IK, out, quick=True)
    (out / "notes.txt").unlink()
    run_scenario(PARALLEL_IK, out, quick=True)  # its report's artifacts are lynxplan's
    assert json.loads((out / MARKER).read_text())["files"].keys() == {
        "parallel_ik.json",
        "report.json",
    }


def test_forced_runs_keep_foreign_links_and_folders_as_they_are(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (tmp_path / "data.csv").write_text("1\n")
    (out / "data.csv").symlink_to(tmp_path / "data.csv")
    (out / "raw").mkdir()
    (out / "raw" / "log.txt").write_text("log")
    inode = (out / "raw" / "log.txt").stat().st_ino
    run_scenario(PARALLEL_IK, out, quick=True, force=True)
    run_scenario(PARALLEL_IK, out, quick=True)
    assert os.readlink(out / "data.csv") == str(tmp_path / "data.csv")
    assert (out / "raw" / "log.txt").stat().st_ino == inode  # the same file, not a copy
    assert (tmp_path / "data.csv").read_text() == "1\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["data.csv", "out"]
