"""Command-line entry point: argument parsing and error display only.

Each sub-command lives in a module of :mod:`lynxplan.commands` that exposes
``register(subparsers)``; the handler it sets returns the process exit code.
"""

from __future__ import annotations

import argparse
import importlib
import re
import sys
from collections.abc import Sequence
from typing import Any

from lynxplan import __version__
from lynxplan.exceptions import LynxplanError

_NEGATIVE_NUMBER = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")

COMMAND_MODULES = (
    "lynxplan.commands.arm",
    "lynxplan.commands.workspace",
    "lynxplan.commands.run",
    "lynxplan.commands.bench",
    "lynxplan.commands.parallel",
    "lynxplan.commands.scenario_tools",
    "lynxplan.commands.robots",
)


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose usage errors are one line and exit code 2, and which takes every
    negative number (``-45``, ``-5.``, ``-1e-3``) as a value, never as an option."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"{self.prog}: error: {message}\n")
        raise SystemExit(2)


def build_parser() -> argparse.ArgumentParser:
    """The full ``lynxplan`` parser with every sub-command registered."""
    parser = _Parser(
        prog="lynxplan",
        description="Modelling and planning for a 5-DOF arm and a planar 3-RRR parallel robot.",
    )
    parser.add_argument("--version", action="version", version=f"lynxplan {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    subparsers.required = True
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(subparsers)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code (0 ok, 1 expectation failed, 2 bad input)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        code: int = args.handler(args)
    except LynxplanError as exc:
        sys.stderr.write(f"lynxplan: error: {exc}\n")
        return 2
    except OSError as exc:  # e.g. an output folder that cannot be created
        where = f": {exc.filename}" if exc.filename else ""
        sys.stderr.write(f"lynxplan: error: {exc.strerror or exc}{where}\n")
        return 2
    except KeyboardInterrupt:
        sys.stderr.write("lynxplan: interrupted\n")
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`, which closed early
        sys.stderr.close()
        return 0
    return code


if __name__ == "__main__":
    raise SystemExit(main())
