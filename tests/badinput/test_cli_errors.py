"""The CLI's error display: one line, documented exit codes, traceback only with --debug."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from lynxplan import cli
from lynxplan.cli import EXIT_BUG, EXIT_CODES, main


@pytest.fixture
def with_boom(monkeypatch: pytest.MonkeyPatch) -> None:
    """Register the test-only ``boom`` sub-command (a real command module, loaded by the CLI)."""
    monkeypatch.setattr(
        cli, "COMMAND_MODULES", (*cli.COMMAND_MODULES, "tests.badinput._boom_command")
    )


@pytest.mark.parametrize(
    ("what", "code", "pattern"),
    [
        ("zero", 3, r"^lynxplan: internal error \(ZeroDivisionError: .*bug report"),
        ("key", 3, r"^lynxplan: internal error \(KeyError: 'missing\\nsecond line'\)"),
        ("recursion", 3, r"^lynxplan: internal error \(RecursionError"),
        ("memory", 3, r"^lynxplan: internal error \(MemoryError\)"),
        ("interrupt", 130, r"^lynxplan: interrupted$"),
        ("exit", 7, r"^$"),
    ],
)
def test_unexpected_errors_are_one_line(capsys, with_boom, what: str, code: int, pattern: str):
    assert main(["boom", what]) == code
    err = capsys.readouterr().err
    assert err.count("\n") <= 1 and "Traceback" not in err
    import re

    assert re.search(pattern, err.rstrip("\n")), err


@pytest.mark.parametrize("position", [0, 1, 2])
def test_debug_shows_the_traceback(capsys, with_boom, position: int) -> None:
    argv = ["boom", "zero"]
    argv.insert(position, "--debug")
    assert main(argv) == EXIT_BUG
    err = capsys.readouterr().err
    assert err.startswith("Traceback") and "ZeroDivisionError" in err
    assert err.rstrip().splitlines()[-1].startswith("lynxplan: internal error")


def test_bad_input_with_debug_keeps_exit_two(capsys) -> None:
    assert main(["--debug", "fk", "1", "2", "3", "4", "nan"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" in err and err.rstrip().endswith("q5: 'nan' is not a finite number")


def test_help_documents_exit_codes(capsys) -> None:
    assert main(["--help"]) == 0
    out = capsys.readouterr().out
    for code, meaning in EXIT_CODES.items():
        assert f"{code}" in out and meaning in out
    assert "--debug" in out


def test_version_and_usage_exit_codes(capsys) -> None:
    assert main(["--version"]) == 0
    assert main([]) == 2
    assert main(["frobnicate"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 2 and "Traceback" not in err


def test_ctrl_c_exits_130_with_one_line(tmp_path: Path) -> None:
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    # Ctrl-C as a terminal delivers it: Python's own handler, SIGINT unblocked, even where the
    # test process passes SIGINT on ignored or blocked (a background job ignores it)
    code = (
        "import signal, sys; signal.signal(signal.SIGINT, signal.default_int_handler); "
        "signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT}); "
        "from lynxplan.cli import main; "
        "sys.argv[0]='lynxplan'; raise SystemExit(main(sys.argv[1:]))"
    )
    process = subprocess.Popen(
        [
            sys.executable,
            "-c",
            code,
            "workspace",
            "--samples",
            "50000000",
            "--out",
            str(tmp_path / "ws"),
            "--cell",
            "0.5",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        env=env,
        text=True,
    )
    deadline = time.monotonic() + 120.0  # interrupt once the run is under way (staging exists)
    while not list(tmp_path.glob(".ws.staging-*")) and time.monotonic() < deadline:
        assert process.poll() is None, process.communicate()
        time.sleep(0.01)
    time.sleep(0.2)
    process.send_signal(signal.SIGINT)
    _, err = process.communicate(timeout=60)
    assert process.returncode == 130, err
    assert err == "lynxplan: interrupted\n"
    assert not (tmp_path / "ws").exists()
    assert not [p for p in tmp_path.iterdir() if ".staging" in p.name]
