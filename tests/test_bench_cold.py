"""The cold-start bench's timing helper (the full section runs in ``lynxplan bench --cold``)."""

from __future__ import annotations

import sys

import pytest

from lynxplan.bench.cold import time_command


def test_time_command_measures_a_fresh_process() -> None:
    wall, cpu = time_command([sys.executable, "-c", "sum(range(10**6))"])
    assert 0.0 < wall < 60.0
    assert 0.0 < cpu < 60.0


def test_time_command_reports_a_failing_command() -> None:
    code = "import sys; print('boom', file=sys.stderr); sys.exit(3)"
    with pytest.raises(RuntimeError, match=r"exited 3: boom"):
        time_command([sys.executable, "-c", code])
