"""The cold-start bench's timing helper (the full section runs in ``lynxplan bench --cold``)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

import lynxplan
from lynxplan.bench.cold import time_command


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
