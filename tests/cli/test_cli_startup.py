"""Start-up of the command line: what a fresh ``lynxplan fk`` loads, and ``--version``.

The timings themselves are figures of ``lynxplan bench --cold``, not tests; these tests keep the
heavy imports off the paths that do not need them.
"""

from __future__ import annotations

import gc
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

from lynxplan.cli import GC_THRESHOLD, main

ROOT = Path(__file__).resolve().parents[2]

#: Modules ``lynxplan fk`` does not need: compiled kernels, schemas, YAML, plots, the metadata.
NOT_FOR_FK = ("numba", "pydantic", "scipy", "yaml", "matplotlib", "importlib.metadata")


def test_version_is_printed_on_stdout(capsys) -> None:
    assert main(["--version"]) == 0
    assert capsys.readouterr().out == f"lynxplan {version('lynxplan')}\n"


def test_fk_loads_none_of_the_heavy_modules() -> None:
    code = (
        "import sys; from lynxplan.cli import main; "
        "code = main(['fk', '0.1', '0.2', '0.3', '0.4', '0.5']); "
        f"print(sorted(m for m in {NOT_FOR_FK!r} if m in sys.modules)); sys.exit(code)"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=False, cwd=ROOT
    )
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines()[-1] == "[]"


def test_the_process_entry_tunes_the_garbage_collector(monkeypatch, capsys) -> None:
    threshold = gc.get_threshold()
    monkeypatch.setattr(sys, "argv", ["lynxplan", "--version"])
    try:
        assert main() == 0
        assert gc.get_threshold()[0] >= GC_THRESHOLD
        assert gc.get_freeze_count() > 0  # the exit skips the cycle search of these
    finally:
        gc.unfreeze()
        gc.set_threshold(*threshold)
    assert capsys.readouterr().out.startswith("lynxplan ")


def test_a_call_with_arguments_leaves_the_garbage_collector_alone(capsys) -> None:
    threshold, frozen = gc.get_threshold(), gc.get_freeze_count()
    assert main(["--version"]) == 0
    assert (gc.get_threshold(), gc.get_freeze_count()) == (threshold, frozen)
