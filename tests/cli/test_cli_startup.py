"""Start-up of the command line: what a fresh ``lynxplan fk`` loads, and ``--version``.

The timings themselves are figures of ``lynxplan bench --cold``, not tests; these tests keep the
heavy imports off the paths that do not need them.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import subprocess
import sys
from importlib.metadata import version
from pathlib import Path

import pytest

from lynxplan.cli import COMMAND_MODULES, COMMAND_OF, GC_THRESHOLD, build_parser, main

ROOT = Path(__file__).resolve().parents[2]

#: Modules ``lynxplan fk`` does not need: compiled kernels, schemas, YAML, plots, the metadata.
NOT_FOR_FK = ("numba", "pydantic", "scipy", "yaml", "matplotlib", "importlib.metadata")


def test_version_is_printed_on_stdout(capsys) -> None:
    assert main(["--version"]) == 0
    assert capsys.readouterr().out == f"lynxplan {version('lynxplan')}\n"


def test_fk_loads_none_of_the_heavy_modules() -> None:
    code = (
        "import sys; from lynxplan.cli import main; "
        "code = main(['fk', '0.1', '0.2', '-0.3', '0.4', '0.5']); "
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


@pytest.mark.parametrize("command", ["serve", "bench"])
def test_long_running_commands_keep_python_s_collector_settings(
    monkeypatch, capsys, command: str
) -> None:
    threshold = gc.get_threshold()
    monkeypatch.setattr(sys, "argv", ["lynxplan", "--debug", command, "--help"])
    try:
        assert main() == 0
        assert gc.get_threshold() == threshold
    finally:
        gc.unfreeze()
        gc.set_threshold(*threshold)
    assert f"usage: lynxplan {command}" in capsys.readouterr().out


def test_a_call_with_arguments_leaves_the_garbage_collector_alone(capsys) -> None:
    threshold, frozen = gc.get_threshold(), gc.get_freeze_count()
    assert main(["--version"]) == 0
    assert (gc.get_threshold(), gc.get_freeze_count()) == (threshold, frozen)


def _registered(modules: tuple[str, ...]) -> dict[str, str]:
    """Sub-command name -> the module whose ``register`` adds it."""
    found = {}
    for name in modules:
        subparsers = argparse.ArgumentParser().add_subparsers()
        importlib.import_module(name).register(subparsers)
        found |= dict.fromkeys(subparsers.choices, name)
    return found


def test_the_command_table_names_the_module_of_every_sub_command() -> None:
    assert _registered(COMMAND_MODULES) == COMMAND_OF


def test_a_command_builds_only_its_module_s_parsers(capsys) -> None:
    parser = build_parser("fk")
    assert parser.parse_args(["ik", "--position", "0.2", "0.1", "0.3"]).command == "ik"
    with pytest.raises(SystemExit):
        parser.parse_args(["run", "scenario.yaml"])
    assert "invalid choice: 'run'" in capsys.readouterr().err
    assert build_parser(None).parse_args(["run", "scenario.yaml"]).command == "run"


def test_help_and_unknown_commands_list_every_command(capsys) -> None:
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    assert all(name in out for name in COMMAND_OF)
    assert main(["frobnicate"]) == 2
    err = capsys.readouterr().err
    assert "invalid choice: 'frobnicate'" in err and "robots" in err
