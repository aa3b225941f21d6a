"""Compiling numba kernels ahead of a timed call.

numba compiles a kernel on its first call in a process (or loads it from its on-disk cache, next
to the sources). The planner's kernels take minutes to compile on a small machine the first time
after installation: :func:`compile_before_timing` and :func:`compile_notice` let that happen
before a clock or a time limit starts, and say on stderr (a terminal only) what the wait is.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

#: Seconds of compiling after which the wait is explained on stderr.
NOTICE_AFTER = 3.0


@contextmanager
def compile_notice(what: str) -> Iterator[None]:
    """Around code that may compile kernels: after :data:`NOTICE_AFTER` seconds, one line on
    stderr naming ``what`` is compiling (only when stderr is a terminal, like the progress
    bars)."""
    notice = threading.Timer(NOTICE_AFTER, _notice, (what,))
    notice.daemon = True
    if sys.stderr.isatty():
        notice.start()
    try:
        yield
    finally:
        notice.cancel()


def compile_before_timing(kernel: Any, args: tuple[Any, ...], what: str) -> float:
    """Make sure ``kernel`` (a numba dispatcher) is compiled for ``args``, without running it;
    returns the seconds it took.

    Does nothing (and returns 0) when the kernel already has a compiled version in this
    process. ``what`` names the kernels in the stderr notice (:func:`compile_notice`).
    """
    if kernel.signatures:
        return 0.0
    import numba

    typeof: Any = numba.typeof
    began = time.perf_counter()
    with compile_notice(what):
        kernel.compile(tuple(typeof(arg) for arg in args))
    return time.perf_counter() - began


def _notice(what: str) -> None:
    print(
        f"lynxplan: compiling {what} (once after installation: a few minutes; later runs load it "
        "from numba's cache)...",
        file=sys.stderr,
        flush=True,
    )
