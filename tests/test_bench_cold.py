"""The cold-start bench's timing helper and its first-run rows (the full section runs in
``lynxplan bench --cold``; these tests time nothing)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

import lynxplan
from lynxplan.bench import MISSED, NOT_RUN, OK, verdict
from lynxplan.bench.cold import (
    _CLI,
    FIRST_PLAN,
    FIRST_RUNS,
    FirstRun,
    _first_run,
    first_run_command,
    first_run_figures,
    time_command,
)
from lynxplan.cli import build_parser
from lynxplan.shipped import scenario_path


def test_time_command_measures_a_fresh_process() -> None:
    wall, cpu = time_command([sys.executable, "-c", "sum(range(10**6))"])
    assert 0.0 < wall < 60.0
    assert 0.0 < cpu < 60.0


def test_time_command_reports_a_failing_command() -> None:
    code = "import sys; print('boom', file=sys.stderr); sys.exit(3)"
    with pytest.raises(RuntimeError, match=r"exited 3: boom"):
        time_command([sys.executable, "-c", code])


def test_the_children_import_the_benchmarked_lynxplan(monkeypatch, tmp_path) -> None:
    # From another folder, without PYTHONPATH, a child would import the installed lynxplan.
    monkeypatch.delenv("PYTHONPATH", raising=False)
    monkeypatch.chdir(tmp_path)
    package = str(Path(lynxplan.__file__).resolve().parent)
    code = f"import sys, lynxplan; sys.exit(0 if lynxplan.__file__.startswith({package!r}) else 5)"
    time_command([sys.executable, "-c", code])


def test_the_first_runs_are_the_issues_commands_with_their_goals() -> None:
    """Issue 36: ik of the SO-101 <= 8 s, of the AL5 <= 4 s, compile reported; issue 37: the first
    plan (the shipped p02) <= 30 s. Each command line is one the CLI takes."""
    goals = {run.name: run.goal for run in FIRST_RUNS}
    assert goals == {
        "lynxplan ik --robot so101 --position 0.2 0 0.1 --approach 0 0 -1": 8.0,
        "lynxplan ik --robot al5 --position 0.2 0 0.1 --pitch 60 --deg": 4.0,
        "lynxplan run scenarios/planning/p02_box_between.yaml": 30.0,
        "lynxplan compile": None,
    }
    assert scenario_path(FIRST_PLAN).is_file()
    for run in FIRST_RUNS:
        command = first_run_command(run, "/tmp/out")
        assert command[:3] == [sys.executable, "-c", _CLI]
        build_parser().parse_args(command[3:])  # exits 2 on arguments it does not take
        if run.arguments[0] == "ik":  # the name is the command line typed
            assert run.name == " ".join(["lynxplan", *run.arguments])


def test_a_first_run_over_its_goal_is_missed() -> None:
    so101 = FIRST_RUNS[0]
    met = first_run_figures(so101, wall=7.9, cpu=7.5)
    assert [verdict(f) for f in met] == [OK, ""]
    missed = first_run_figures(so101, wall=20.0, cpu=19.0)
    assert [verdict(f) for f in missed] == [MISSED, ""]
    assert missed[0].value == 20.0 and missed[0].target == "<= 8"
    compile_ = first_run_figures(FIRST_RUNS[-1], wall=400.0, cpu=380.0)
    assert [verdict(f) for f in compile_] == ["", ""]


def test_a_first_run_gets_an_empty_numba_cache_of_its_own(tmp_path: Path) -> None:
    code = "import os, sys; d = os.environ['NUMBA_CACHE_DIR']; sys.exit(len(os.listdir(d)))"
    (tmp_path / "numba").mkdir()
    time_command([sys.executable, "-c", code], {"NUMBA_CACHE_DIR": str(tmp_path / "numba")})
    (tmp_path / "numba" / "stale.nbi").write_text("")
    with pytest.raises(RuntimeError, match="exited 1"):
        time_command([sys.executable, "-c", code], {"NUMBA_CACHE_DIR": str(tmp_path / "numba")})


def test_a_first_run_that_fails_is_not_run_and_the_others_go_on() -> None:
    broken = FirstRun("lynxplan ik --robot nonesuch", ("ik", "--robot", "nonesuch"), 1.0)
    (figure,) = _first_run(broken)
    assert verdict(figure) == NOT_RUN
    assert "exited 2" in figure.skipped
