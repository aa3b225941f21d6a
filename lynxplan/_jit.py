"""Compiling numba kernels: ahead of a timed call, and a notice when it takes long.

numba compiles a kernel on its first call in a process, or loads it from its on-disk cache next
to the sources. The first use after installation compiles: half a minute for the IK solvers,
about two minutes for the planner on a small machine.

- :func:`compile_before_timing` compiles a kernel before a clock or a time limit starts.
- :func:`enable_notices` (the CLI, when stderr is a terminal) and :func:`listen` (called by the
  modules of the big kernels once numba is imported: the CLI's light commands never import it)
  print one line on stderr once compiling has taken :data:`NOTICE_AFTER` seconds.
"""

from __future__ import annotations

import sys
import threading
import time
from typing import Any

#: Seconds of compiling after which the wait is explained on stderr.
NOTICE_AFTER = 3.0

_state = {"notices": False, "listening": False}


def compile_before_timing(kernel: Any, args: tuple[Any, ...]) -> float:
    """Make sure ``kernel`` (a numba dispatcher) is compiled for ``args``, without running it;
    returns the seconds it took (0 when it already has a compiled version in this process)."""
    if kernel.overloads:  # (not .signatures: it hashes every signature, ~20 us for a big one)
        return 0.0
    import numba

    typeof: Any = numba.typeof
    began = time.perf_counter()
    kernel.compile(tuple(typeof(arg) for arg in args))
    return time.perf_counter() - began


def enable_notices() -> None:
    """From now on, announce long compiles on stderr (only when stderr is a terminal)."""
    _state["notices"] = sys.stderr.isatty()
    if "numba" in sys.modules:
        listen()


def listen() -> None:
    """Start watching numba's compiles if :func:`enable_notices` asked for it (idempotent)."""
    if not _state["notices"] or _state["listening"]:
        return
    from numba.core import event

    announcer = _Announcer()

    class _Listener(event.Listener):
        def on_start(self, _event: Any) -> None:
            announcer.start()

        def on_end(self, _event: Any) -> None:
            announcer.end()

    register: Any = event.register
    register("numba:compile", _Listener())
    _state["listening"] = True


class _Announcer:
    """numba compile-event listener: total compile time, one line once it passes NOTICE_AFTER."""

    def __init__(self) -> None:
        self.depth = 0
        self.spent = 0.0
        self.began = 0.0
        self.timer: threading.Timer | None = None
        self.said = False

    def start(self) -> None:
        self.depth += 1
        if self.depth == 1 and not self.said:
            self.began = time.perf_counter()
            self.timer = threading.Timer(max(NOTICE_AFTER - self.spent, 0.0), self._say)
            self.timer.daemon = True
            self.timer.start()

    def end(self) -> None:
        self.depth -= 1
        if self.depth == 0 and self.timer is not None:
            self.timer.cancel()
            self.timer = None
            self.spent += time.perf_counter() - self.began

    def _say(self) -> None:
        self.said = True
        print(
            "lynxplan: compiling numba kernels (once after installation; later runs load them "
            "from numba's cache)...",
            file=sys.stderr,
            flush=True,
        )
