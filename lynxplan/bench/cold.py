"""Bench section ``cold``: fresh-process start-up of the commands users type first.

Each command runs in a new Python process (after one untimed run that fills the numba, bytecode
and OS caches, so "cold" means a new process, not a cold disk; ``PYTHONDONTWRITEBYTECODE`` is
dropped for the children, as an installed package has its ``.pyc`` files): ``lynxplan fk``,
``lynxplan run scenarios/ok_task.yaml --quick`` and, as the yardstick of the machine,
``python -c 'import pinocchio'``. Figures are medians of wall time and of the child's CPU time
(user + system, less sensitive to a shared machine), and each command's ratio to the pinocchio
import. Run from a source tree, the children import that tree's lynxplan (``PYTHONPATH``), so a
worktree measures its own code, not an editable install's.
"""

from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from lynxplan.bench import Figure
from lynxplan.shipped import checkout_root, scenario_path

SECTION = "cold"
#: The issue's goals, in [s] of wall time on the CI machine.
TARGET_FK_SECONDS = 0.5
TARGET_RUN_SECONDS = 1.5
_CLI = "import sys; from lynxplan.cli import main; sys.exit(main())"


def _commands(out_dir: str) -> dict[str, list[str]]:
    python = sys.executable
    return {
        "python -c 'import pinocchio'": [python, "-c", "import pinocchio"],
        "lynxplan fk 0.1 0.2 -0.3 0.4 0.5": [
            python, "-c", _CLI, "fk", "0.1", "0.2", "-0.3", "0.4", "0.5",
        ],
        "lynxplan run scenarios/ok_task.yaml --quick": [
            python, "-c", _CLI, "run", str(scenario_path("ok_task.yaml")), "--quick", "--out",
            out_dir, "--force",
        ],
    }  # fmt: skip


def time_command(command: list[str]) -> tuple[float, float]:
    """Wall time and CPU time (user + system) of one run of ``command``, in [s].

    Raises:
        RuntimeError: the command failed (its last stderr line is quoted).
    """
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    source = checkout_root()
    if source is not None:
        # Run from a source tree (a checkout, a worktree): the children import this lynxplan,
        # not whichever one their working directory or an editable install would give them.
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(source), env.get("PYTHONPATH")]))
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, check=False, env=env)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        last = (done.stderr.strip().splitlines() or ["no output"])[-1]
        raise RuntimeError(f"{command[-1]!r}... exited {done.returncode}: {last}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def run(quick: bool) -> list[Figure]:
    """Median start-up times of the three commands and their ratios to the pinocchio import."""
    repeats = 3 if quick else 7
    with tempfile.TemporaryDirectory(prefix="lynxplan-cold-") as tmp:
        commands = _commands(str(Path(tmp) / "out"))
        medians: dict[str, tuple[float, float]] = {}
        for name, command in commands.items():
            time_command(command)  # fills the numba cache and the OS page cache
            runs = [time_command(command) for _ in range(repeats)]
            medians[name] = (
                statistics.median(w for w, _ in runs),
                statistics.median(c for _, c in runs),
            )
    base_wall, base_cpu = medians["python -c 'import pinocchio'"]
    figures = []
    targets = {"lynxplan fk": TARGET_FK_SECONDS, "lynxplan run": TARGET_RUN_SECONDS}
    for name, (wall, cpu) in medians.items():
        goal = next((g for prefix, g in targets.items() if name.startswith(prefix)), None)
        figures.append(
            Figure(SECTION, f"{name}: wall", wall, "s",
                   "" if goal is None else f"<= {goal:g}", None if goal is None else wall <= goal)
        )  # fmt: skip
        figures.append(Figure(SECTION, f"{name}: CPU (user + system)", cpu, "s"))
        if goal is not None:
            figures += [
                Figure(SECTION, f"{name}: wall / pinocchio import", wall / base_wall, "x"),
                Figure(SECTION, f"{name}: CPU / pinocchio import", cpu / base_cpu, "x"),
            ]
    return figures
