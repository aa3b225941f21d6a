"""A sub-command that fails the way a bug would: registered by tests of the CLI's error display."""

from __future__ import annotations

import argparse
from typing import Any


def register(subparsers: Any) -> None:
    parser = subparsers.add_parser("boom", help="raise an internal error (tests only)")
    parser.add_argument("what", choices=("zero", "key", "recursion", "memory", "interrupt", "exit"))
    parser.set_defaults(handler=handle)


def _recurse(n: int) -> int:
    return _recurse(n + 1) + 1


def handle(args: argparse.Namespace) -> int:
    if args.what == "zero":
        return 1 // 0
    if args.what == "key":
        return {}["missing\nsecond line"]  # type: ignore[no-any-return]
    if args.what == "recursion":
        return _recurse(0)
    if args.what == "memory":
        raise MemoryError
    if args.what == "interrupt":
        raise KeyboardInterrupt
    raise SystemExit(7)
