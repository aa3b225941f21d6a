"""First runs say once that they compile; ``lynxplan compile`` compiles every kernel ahead.

Each test uses its own empty numba cache (``NUMBA_CACHE_DIR``): the state after installation.
"""

from __future__ import annotations

import os
import pty
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from lynxplan import _jit
from lynxplan.cli import COMMAND_OF

ROOT = Path(__file__).resolve().parents[2]
LYNXPLAN = str(Path(sys.executable).with_name("lynxplan"))
P02 = ROOT / "scenarios" / "planning" / "p02_box_between.yaml"
OK_TASK = ROOT / "scenarios" / "ok_task.yaml"
PLAN_KIND = "lynxplan: compiling numba kernels for the first run"


def _env(cache: Path) -> dict[str, str]:
    return {**os.environ, "NUMBA_CACHE_DIR": str(cache)}


def _on_a_terminal(command: list[str], cache: Path, timeout: float) -> tuple[int, str]:
    """Run ``command`` with stderr on a pseudo-terminal (stdout discarded), read as it comes (a
    full terminal would block the writer); returns the exit code and what the terminal got."""
    main, other = pty.openpty()
    chunks: list[bytes] = []

    def read() -> None:
        while True:
            try:
                chunk = os.read(main, 65536)
            except OSError:  # EIO: the writer's side is closed
                return
            if not chunk:
                return
            chunks.append(chunk)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        done = subprocess.run(
            command, cwd=ROOT, env=_env(cache), stdout=subprocess.DEVNULL, stderr=other,
            timeout=timeout, check=False,
        )  # fmt: skip
    finally:
        os.close(other)
        reader.join(timeout=30)
        os.close(main)
    return done.returncode, b"".join(chunks).decode(errors="replace")


def _pytest(paths: list[Path], cache: Path, *options: str) -> str:
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-q", *options,
         *(str(p) for p in paths)],
        cwd=ROOT, env=_env(cache), capture_output=True, text=True, timeout=1800, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return done.stdout + done.stderr


def test_compile_is_a_command() -> None:
    assert COMMAND_OF["compile"] == "lynxplan.commands.compile"
    done = subprocess.run([LYNXPLAN, "compile", "--help"], capture_output=True, text=True,
                          timeout=60, check=True)  # fmt: skip
    assert "numba" in done.stdout


@pytest.mark.parametrize(
    ("jobs", "said"),
    [("0", "must be an integer >= 1"), ("x", "is not a number"), ("inf", "not a finite"),
     ("1.5", "must be an integer"), ("65", "must be an integer <= 64")],
)  # fmt: skip
def test_compile_refuses_a_bad_job_count_before_compiling(jobs: str, said: str) -> None:
    done = subprocess.run([LYNXPLAN, "compile", "--jobs", jobs], capture_output=True,
                          text=True, timeout=60, check=False)  # fmt: skip
    assert done.returncode == 2
    assert done.stdout == ""
    assert done.stderr.count("\n") == 1 and "--jobs" in done.stderr and said in done.stderr


def test_cold_kernels_reads_the_cache_index_of_each_kernel(tmp_path: Path) -> None:
    """Against an empty cache every big kernel is cold (numba's own cache dir for them)."""
    script = "from lynxplan import _jit; print(len(_jit.cold_kernels()), _jit.cache_folder())"
    done = subprocess.run([sys.executable, "-c", script], env=_env(tmp_path), capture_output=True,
                          text=True, timeout=300, check=True)  # fmt: skip
    count, folder = done.stdout.split()
    assert int(count) == len(_jit.ENTRY_KERNELS)
    assert folder.startswith(str(tmp_path))


def test_pytest_plugin_says_once_that_it_compiles_on_an_empty_cache(tmp_path: Path) -> None:
    said = _pytest([P02, OK_TASK], tmp_path, "--collect-only")
    assert said.count(PLAN_KIND) == 1, said


def test_pytest_plugin_says_nothing_for_kinds_without_big_kernels(tmp_path: Path) -> None:
    said = _pytest([ROOT / "scenarios" / "parallel_ik.yaml"], tmp_path, "--collect-only")
    assert PLAN_KIND not in said


@pytest.mark.slow
def test_first_run_says_it_compiles_and_none_after_lynxplan_compile(tmp_path: Path) -> None:
    """The whole story on an empty cache (minutes: every kernel compiles, twice over). A first
    plan runs as Python (one line says so, nothing compiles); the main job compiles and says so;
    after ``lynxplan compile`` neither says anything."""
    code, said = _on_a_terminal([LYNXPLAN, "run", str(P02), "--quick", "--out",
                                 str(tmp_path / "p02")], tmp_path / "cache", 3600)  # fmt: skip
    assert code == 0
    assert said.count(_jit.PYTHON_PLAN_NOTE) == 1 and PLAN_KIND not in said, said
    code, said = _on_a_terminal([LYNXPLAN, "run", str(OK_TASK), "--quick", "--out",
                                 str(tmp_path / "ok")], tmp_path / "cache", 3600)  # fmt: skip
    assert code == 0
    assert said.count(PLAN_KIND) == 1, said
    done = subprocess.run([LYNXPLAN, "compile"], cwd=ROOT, env=_env(tmp_path / "cache"),
                          capture_output=True, text=True, timeout=3600, check=False)  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    assert "kernels compiled" in done.stdout
    for scenario in (OK_TASK, P02):
        out = str(tmp_path / scenario.stem)
        command = [LYNXPLAN, "run", str(scenario), "--quick", "--out", out]
        code, said = _on_a_terminal(command, tmp_path / "cache", 600)
        assert code == 0
        assert PLAN_KIND not in said and _jit.PYTHON_PLAN_NOTE not in said, said
    assert PLAN_KIND not in _pytest([P02, OK_TASK], tmp_path / "cache")
    again = subprocess.run([LYNXPLAN, "compile"], cwd=ROOT, env=_env(tmp_path / "cache"),
                           capture_output=True, text=True, timeout=900, check=False)  # fmt: skip
    assert again.returncode == 0  # idempotent
