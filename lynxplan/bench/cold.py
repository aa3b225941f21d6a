"""Bench section ``cold``: fresh-process start-up of the commands users type first.

Each command runs in a new Python process (after one untimed run that fills the numba, bytecode
and OS caches, so "cold" means a new process, not a cold disk; ``PYTHONDONTWRITEBYTECODE`` is
dropped for the children, as an installed package has its ``.pyc`` files): ``lynxplan fk``,
``lynxplan run scenarios/ok_task.yaml --quick`` and, as the yardstick of the machine,
``python -c 'import pinocchio'``. Figures are medians of wall time and of the child's CPU time
(user + system, less sensitive to a shared machine), and each command's ratio to the pinocchio
import. Run from a source tree, the children import that tree's lynxplan (``PYTHONPATH``), so a
worktree measures its own code, not an editable install's.

First runs (issues 36 and 37): the commands a new user types first, each once in a new process
with its own empty numba cache (``NUMBA_CACHE_DIR``), so every kernel it needs compiles:
``lynxplan ik`` of the SO-101 and of the AL5, ``lynxplan run`` of the shipped planning problem
``planning/p02_box_between.yaml``, and ``lynxplan compile`` (every kernel: the price paid once).
Their goals are wall time on the 2-core machine; the CPU time is shown too (numba compiles on
one core, so on a machine shared with other jobs the CPU time is the figure to compare). They
take minutes: ``--quick`` leaves them out.
"""

from __future__ import annotations

import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Mapping
from pathlib import Path
from typing import NamedTuple

from lynxplan.bench import Figure, not_run
from lynxplan.shipped import checkout_root, scenario_path

SECTION = "cold"
#: The issue's goals, in [s] of wall time on the CI machine.
TARGET_FK_SECONDS = 0.5
TARGET_RUN_SECONDS = 1.5
_CLI = "import sys; from lynxplan.cli import main; sys.exit(main())"


class FirstRun(NamedTuple):
    """A command timed from an empty numba cache."""

    name: str
    """The command as a user types it."""
    arguments: tuple[str, ...]
    """Its arguments after ``lynxplan`` (``{out}``: an output folder)."""
    goal: float | None
    """The issue's goal in [s] of wall time, or None."""


#: The first runs, in order (issue 36: the IK commands and compile; issue 37: the first plan).
FIRST_RUNS: tuple[FirstRun, ...] = (
    FirstRun(
        "lynxplan ik --robot so101 --position 0.2 0 0.1 --approach 0 0 -1",
        ("ik", "--robot", "so101", "--position", "0.2", "0", "0.1", "--approach", "0", "0", "-1"),
        8.0,
    ),
    FirstRun(
        "lynxplan ik --robot al5 --position 0.2 0 0.1 --pitch 60 --deg",
        ("ik", "--robot", "al5", "--position", "0.2", "0", "0.1", "--pitch", "60", "--deg"),
        4.0,
    ),
    FirstRun(
        "lynxplan run scenarios/planning/p02_box_between.yaml",
        ("run", "{scenario}", "--out", "{out}", "--force"),
        30.0,
    ),
    FirstRun("lynxplan compile", ("compile",), None),
)
#: The shipped scenario of the first plan (``{scenario}`` in :data:`FIRST_RUNS`).
FIRST_PLAN = "planning/p02_box_between.yaml"


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


def time_command(
    command: list[str], variables: Mapping[str, str] | None = None
) -> tuple[float, float]:
    """Wall time and CPU time (user + system) of one run of ``command``, in [s]; ``variables``:
    environment variables set for it.

    Raises:
        RuntimeError: the command failed (its last stderr line is quoted).
    """
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env.update(variables or {})
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


def first_run_command(run: FirstRun, out_dir: str) -> list[str]:
    """The child's command line of ``run`` (``{out}`` and ``{scenario}`` filled in)."""
    fill = {"{out}": out_dir, "{scenario}": str(scenario_path(FIRST_PLAN))}
    return [sys.executable, "-c", _CLI, *(fill.get(a, a) for a in run.arguments)]


def time_first_run(run: FirstRun) -> tuple[float, float]:
    """Wall and CPU time [s] of ``run`` in a new process with an empty numba cache of its own."""
    with tempfile.TemporaryDirectory(prefix="lynxplan-first-run-") as tmp:
        cache = Path(tmp) / "numba"
        cache.mkdir()
        command = first_run_command(run, str(Path(tmp) / "out"))
        return time_command(command, {"NUMBA_CACHE_DIR": str(cache)})


def first_run_figures(run: FirstRun, wall: float, cpu: float) -> list[Figure]:
    """The figures of one first run: its wall time (judged against its goal) and CPU time."""
    goal = "" if run.goal is None else f"<= {run.goal:g}"
    return [
        Figure(SECTION, f"first run, empty numba cache: {run.name}: wall", wall, "s", goal,
               None if run.goal is None else wall <= run.goal),
        Figure(SECTION, f"first run, empty numba cache: {run.name}: CPU (user + system)", cpu, "s"),
    ]  # fmt: skip


def first_runs() -> list[Figure]:
    """Every first run of :data:`FIRST_RUNS`, one after the other (a command that fails gives a
    ``NOT RUN`` figure with its error)."""
    return [figure for first in FIRST_RUNS for figure in _first_run(first)]


def _first_run(first: FirstRun) -> list[Figure]:
    try:
        wall, cpu = time_first_run(first)
    except RuntimeError as error:  # the command failed: said, the other runs still run
        return [not_run(SECTION, f"first run: {first.name}", str(error)[:300])]
    return first_run_figures(first, wall, cpu)


def run(quick: bool) -> list[Figure]:
    """Median start-up times of the three commands and their ratios to the pinocchio import, and
    the first runs from an empty numba cache (not with ``quick``)."""
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
    return figures if quick else figures + first_runs()
