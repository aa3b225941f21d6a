"""Command-line entry point: argument parsing and error display only.

Each sub-command lives in a module of :mod:`lynxplan.commands` that exposes
``register(subparsers)``; the handler it sets returns the process exit code.

Whatever happens, the user sees at most one line on stderr (``--debug`` adds the traceback) and
one of the documented exit codes (:data:`EXIT_CODES`).

A ``lynxplan`` process is short-lived, and its start-up allocates about 200,000 objects that live
until exit (numba's typing registries, pydantic schemas, Pinocchio bindings). As the process
entry point (``argv`` None), :func:`main` collects young garbage only every :data:`GC_THRESHOLD`
net allocations instead of Python's 700: the default spent 60-90 ms of a cold ``lynxplan run``
traversing those objects. Long runs still collect, and objects without reference cycles are
freed at once as always. Once the command is done, :func:`main` freezes the collector, so that
the interpreter's exit does not traverse them all once more (about 0.3 s). ``lynxplan serve`` and
``lynxplan bench`` (:data:`LONG_RUNNING_COMMANDS`) keep Python's settings. ``lynxplan bench
--cold`` measures the start-up.
"""

from __future__ import annotations

import argparse
import contextlib
import gc
import importlib
import os
import re
import sys
import traceback
import warnings
from collections.abc import Sequence
from typing import Any

from lynxplan import _jit, guards
from lynxplan.exceptions import LynxplanError, LynxplanInputError

#: Negative numbers, including ``-inf`` and ``-nan`` (which the value checks then reject with a
#: message naming the option, instead of argparse taking them for unknown options).
_NEGATIVE_NUMBER = re.compile(
    r"^-((\d+\.?\d*|\.\d+)([eE][-+]?\d+)?|inf|infinity|nan)$", re.IGNORECASE
)

#: Success.
EXIT_OK = 0
#: The run completed, and at least one ``expect:`` entry did not hold.
EXIT_EXPECTATION_FAILED = 1
#: Bad input: usage error, invalid value, malformed or unreadable file, resource limit.
EXIT_BAD_INPUT = 2
#: An internal error (a bug in lynxplan): please report it.
EXIT_BUG = 3
#: Interrupted (Ctrl-C).
EXIT_INTERRUPTED = 130

EXIT_CODES: dict[int, str] = {
    EXIT_OK: "success",
    EXIT_EXPECTATION_FAILED: "the run completed but an expectation (expect:) failed",
    EXIT_BAD_INPUT: "bad input: usage, value, file or resource limit (one line on stderr)",
    EXIT_BUG: "internal error, a bug in lynxplan: please report it (rerun with --debug)",
    EXIT_INTERRUPTED: "interrupted (Ctrl-C)",
}


#: The module that registers each sub-command: ``lynxplan CMD ...`` builds the parsers of CMD's
#: module only (building all of them took ~8 ms of every start-up); ``lynxplan --help`` and an
#: unknown command build them all. tests/cli checks this table against the modules.
COMMAND_OF: dict[str, str] = {
    "fk": "lynxplan.commands.arm",
    "ik": "lynxplan.commands.arm",
    "workspace": "lynxplan.commands.workspace",
    "run": "lynxplan.commands.run",
    "bench": "lynxplan.commands.bench",
    "parallel": "lynxplan.commands.parallel",
    "schema": "lynxplan.commands.scenario_tools",
    "validate": "lynxplan.commands.scenario_tools",
    "serve": "lynxplan.commands.serve",
    "robots": "lynxplan.commands.robots",
    "robot": "lynxplan.commands.robots",
    "compile": "lynxplan.commands.compile",
    "lerobot": "lynxplan.commands.lerobot",
}
#: Every sub-command module, in the order of ``lynxplan --help``.
COMMAND_MODULES = tuple(dict.fromkeys(COMMAND_OF.values()))


class _Parser(argparse.ArgumentParser):
    """ArgumentParser whose usage errors are one line and exit code 2, and which takes every
    negative number (``-45``, ``-5.``, ``-1e-3``) as a value, never as an option."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._negative_number_matcher = _NEGATIVE_NUMBER

    def error(self, message: str) -> None:  # type: ignore[override]
        sys.stderr.write(f"{self.prog}: error: {_one_line(message)}\n")
        raise SystemExit(EXIT_BAD_INPUT)


class _VersionAction(argparse.Action):
    """``--version``: reads the package metadata only when asked (importlib.metadata costs about
    30 ms of every start-up otherwise)."""

    def __init__(self, option_strings: list[str], dest: str, **kwargs: Any) -> None:
        kwargs.setdefault("help", "show the version and exit")
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser: argparse.ArgumentParser, *_: Any, **__: Any) -> None:
        sys.stdout.write(f"lynxplan {_version()}\n")
        parser.exit()


def _version() -> str:
    import lynxplan

    return str(lynxplan.__version__)


def _epilog() -> str:
    lines = ["exit codes:"] + [f"  {code:<4} {meaning}" for code, meaning in EXIT_CODES.items()]
    return "\n".join(lines)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``lynxplan`` parser: every sub-command registered, or (``command`` named in
    :data:`COMMAND_OF`) only the sub-commands of that command's module."""
    parser = _Parser(
        prog="lynxplan",
        description="Modelling and planning for a 5-DOF arm and a planar 3-RRR parallel robot.",
        epilog=_epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action=_VersionAction)
    parser.add_argument(
        "--max-samples",
        metavar="N",
        help="raise the resource limit on samples, grid cells and batch sizes (default "
        "100,000,000; accepted anywhere on the command line)",
    )
    parser.add_argument(
        "--debug",
        action="store_true",
        help="show the full traceback of an error (accepted anywhere on the command line)",
    )
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    subparsers.required = True
    modules = (COMMAND_OF[command],) if command in COMMAND_OF else COMMAND_MODULES
    for name in modules:
        importlib.import_module(name).register(subparsers)
    return parser


def _one_line(message: str) -> str:
    """``message`` folded onto one line (error messages may quote multi-line values)."""
    return " ".join(str(message).split())


def _split_global(argv: Sequence[str]) -> tuple[list[str], bool, str | None]:
    """Remove the global options ``--debug`` and ``--max-samples N`` (or ``=N``) from anywhere
    before a ``--`` separator; returns the rest, debug, and the max-samples text (or None)."""
    args = list(argv)
    end = args.index("--") if "--" in args else len(args)
    rest: list[str] = []
    debug, max_samples = False, None
    i = 0
    while i < len(args):
        arg = args[i]
        if i < end and arg == "--debug":
            debug = True
        elif i < end and arg.startswith("--max-samples="):
            max_samples = arg.split("=", 1)[1]
        elif i < end and arg == "--max-samples":
            if i + 1 >= end:
                raise LynxplanInputError("--max-samples: expected a number N")
            max_samples = args[i + 1]
            i += 1
        else:
            rest.append(arg)
        i += 1
    return rest, debug, max_samples


def _max_samples(text: str) -> int:
    try:
        value = float(text.replace("_", ""))
    except ValueError:
        raise LynxplanInputError(f"--max-samples: {text!r} is not a number") from None
    return guards.count("--max-samples", value, minimum=1, limit=None)


def _report(message: str, debug: bool) -> None:
    if debug:
        traceback.print_exc()
    sys.stderr.write(f"lynxplan: {message}\n")


#: Collection threshold of the youngest generation in a ``lynxplan`` process, in net allocations
#: of container objects (Python's default: 700): above what a cold start allocates.
GC_THRESHOLD = 500_000
#: Commands that keep Python's garbage-collector settings: a long-running service, and the
#: benchmarks (whose timed loops should see the collector as any program would).
LONG_RUNNING_COMMANDS = frozenset({"serve", "bench"})


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; returns the exit code (see :data:`EXIT_CODES`).

    Never raises (except SystemExit from ``--help``/``--version`` handled here too) and never
    lets a traceback reach the user unless ``--debug`` is given.

    Args:
        argv: The arguments; None: ``sys.argv[1:]``, and this call is the process (the garbage
            collector is tuned for a short-lived process, see the module docstring).
    """
    if argv is not None:
        return _main(argv)
    argv = sys.argv[1:]
    _jit.in_cli_process()
    _jit.enable_notices()  # the process is the CLI: say so when numba compiles for long
    command = _command(argv)
    _jit.interpret_one_target(command, argv)  # one IK/FK target: no compile to wait for
    if command not in LONG_RUNNING_COMMANDS:
        young, middle, old = gc.get_threshold()
        gc.set_threshold(max(young, GC_THRESHOLD), middle, old)
    try:
        return _main(argv)
    finally:
        gc.freeze()  # the process exits next: no final traversal of the start-up's objects


def _show_lynxplan_warnings() -> None:
    """lynxplan's own warnings (a length implausible for the robot) as one line on stderr each,
    also when library warnings are silenced (call inside ``warnings.catch_warnings``)."""
    from lynxplan.units import ImplausibleLengthWarning

    warnings.simplefilter("always", ImplausibleLengthWarning)
    default = warnings.showwarning

    def show(message: Any, category: Any, *args: Any, **kwargs: Any) -> None:
        if issubclass(category, ImplausibleLengthWarning):
            sys.stderr.write(f"lynxplan: warning: {_one_line(str(message))}\n")
        else:
            default(message, category, *args, **kwargs)

    warnings.showwarning = show


def _command(argv: Sequence[str]) -> str | None:
    """The sub-command named by ``argv`` (global options removed), or None."""
    try:
        rest = _split_global(argv)[0]
    except LynxplanError:
        return None
    return rest[0] if rest and not rest[0].startswith("-") else None


def _main(argv: Sequence[str]) -> int:
    """:func:`main` with its arguments."""
    debug = "--debug" in argv
    try:
        args_list, debug, max_samples = _split_global(argv)
        try:
            args = build_parser(_command(args_list)).parse_args(args_list)
        except SystemExit as exc:  # --help, --version, usage errors (already printed)
            return exc.code if isinstance(exc.code, int) else EXIT_BAD_INPUT
        limit = None if max_samples is None else _max_samples(max_samples)
        with guards.raised_limits(max_samples=limit), warnings.catch_warnings():
            if not debug:  # library warnings (numpy, Pinocchio) would break the one-line rule
                warnings.simplefilter("ignore")
            _show_lynxplan_warnings()
            code: int = args.handler(args)
        return code
    except LynxplanError as exc:
        _report(f"error: {_one_line(str(exc))}", debug)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        _report("interrupted", debug)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # output piped into e.g. `head`, which closed early
        # Python flushes stdout at exit and would fail again: point it at /dev/null.
        with contextlib.suppress(OSError, ValueError):
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except OSError as exc:  # e.g. an output folder that cannot be created
        where = f": {exc.filename}" if exc.filename else ""
        _report(f"error: {_one_line(exc.strerror or str(exc))}{where}", debug)
        return EXIT_BAD_INPUT
    except SystemExit as exc:
        return exc.code if isinstance(exc.code, int) else EXIT_BAD_INPUT
    except (MemoryError, RecursionError, Exception) as exc:  # a bug: guards must prevent these
        detail = _one_line(str(exc))[:200]
        _report(
            f"internal error ({type(exc).__name__}{': ' + detail if detail else ''}); this is a "
            f"bug in lynxplan {_version()}: please file a bug report with the command line and "
            "the output of the same command with --debug",
            debug,
        )
        return EXIT_BUG


if __name__ == "__main__":
    raise SystemExit(main())
