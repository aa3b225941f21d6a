"""Compiling numba kernels: ahead of a timed call, and a notice when it takes long.

numba compiles a kernel on its first call in a process, or loads it from its on-disk cache next
to the sources. The first use after installation compiles: half a minute for the IK solvers,
about two minutes for the planner on a small machine.

- :func:`compile_before_timing` compiles a kernel before a clock or a time limit starts.
- :func:`listen` (called by the modules of the big kernels once numba is imported: the CLI's
  light commands never import it) says :data:`NOTICE` once compiling has taken
  :data:`NOTICE_AFTER` seconds: as a :class:`CompileWarning` in a Python program (a notebook, a
  script: the first plan compiles for minutes, never in silence), on stderr in the CLI when
  stderr is a terminal (:func:`enable_notices`), not at all after :func:`disable_notices`. numba
  reports a compile only when its cache had no version of the kernel for the argument types:
  the notice never shows on a warm cache.
- :func:`interpret_one_target` (the CLI's single-target ``ik`` and ``fk``) runs the kernels as
  Python code instead: one target costs 0.3-1 s interpreted against 5-30 s of compiling on a
  cold cache, and the answers are the same to the bit (the kernels use no fast-math flags and no
  function whose Python and compiled versions round differently: ``tests/test_jit.py``).
- :func:`plan_as_python_if_cold` (the CLI's ``run`` of a plan scenario) does the same for a
  plan while the planner's kernels (:data:`PLANNER_KERNELS`) have no compiled version: the
  shipped plans take 1-6 s as Python against ~1.5 min of compiling, with the same paths to the
  bit. A plan that reaches its time limit (or :data:`PYTHON_PLAN_SECONDS`) as Python is planned
  again compiled (:class:`PythonPlanTooSlowError`): the verdict never depends on the cache.
- :func:`cold_kernels` tells, before anything runs, which of the big kernels
  (:data:`ENTRY_KERNELS`) have no version in numba's cache for their current source: the pytest
  plugin and ``lynxplan serve`` say :data:`NOTICE` up front when some do. ``lynxplan compile``
  compiles them all.
"""

from __future__ import annotations

import importlib
import os
import sys
import threading
import time
import warnings
from collections.abc import Callable
from typing import Any

from lynxplan._numba_cache import cached

#: Seconds of compiling after which the wait is explained on stderr.
NOTICE_AFTER = 3.0

#: The one line that explains a first run's wait. Measured from an empty cache (numba compiles
#: on one core): the AL5's IK and planner kernels ~2.5 min of CPU, the SO-101's IK ~3.5 min more,
#: ``lynxplan compile`` 6.2 min of CPU in all.
NOTICE = (
    "lynxplan: compiling numba kernels for the first run (about 2-6 min on 2 cores, once; "
    "`lynxplan compile` compiles them all ahead)"
)

#: The big kernels ("module:name"), the ones whose compile the first runs wait for; inner
#: kernels compile with them. :func:`cold_kernels` checks their cache entries.
ENTRY_KERNELS = (
    "lynxplan.arm.ik_kernel:ik_kernel",
    "lynxplan.arm.ik_select:ik_single_kernel",
    "lynxplan.robots.ik.family_kernel:family_ik_closed_form",
    "lynxplan.robots.ik.family_kernel:family_ik_general",
    "lynxplan.robots.ik.pose_kernel:pose_kernel",
    "lynxplan.robots.ik.pose_block:blocks",
    "lynxplan.planning.rrt_connect:rrt_connect_begin",
    "lynxplan.planning.rrt_connect:rrt_connect_kernel",
    "lynxplan.planning.shortcut:shortcut_path",
    "lynxplan.planning.certify:verification_rows",
)

#: The planner's entry kernels: a plan compiles them all (:func:`plan_as_python_if_cold`).
PLANNER_KERNELS = tuple(k for k in ENTRY_KERNELS if k.startswith("lynxplan.planning."))

#: Seconds of planning as Python after which the CLI plans again compiled (~100x faster), even
#: where the plan's time limit is longer: compiling takes about as long.
PYTHON_PLAN_SECONDS = 20.0

#: The note of a plan run as Python code (the CLI's stderr).
PYTHON_PLAN_NOTE = (
    "lynxplan: planning as Python code: the planner's compiled kernels are not built yet "
    "(`lynxplan compile` builds them once, about 3 min on 2 cores; plans then run ~100x faster)"
)


class CompileWarning(UserWarning):
    """numba is compiling lynxplan's kernels for the first time (minutes; once per
    installation). ``warnings.filterwarnings("ignore", category=lynxplan.CompileWarning)``
    silences it; ``lynxplan compile`` pays the compile ahead."""


#: notices: None (a Python program: warn), True (the CLI on a terminal: print), False (quiet).
#: cli: this process is a CLI command (:func:`in_cli_process`); python_plan: it runs its plan
#: as Python because the planner's kernels are cold (:func:`plan_as_python_if_cold`).
_state: dict[str, bool | None] = {
    "cli": False,
    "notices": None,
    "listening": False,
    "said": False,
    "python_plan": False,
}


def compile_before_timing(kernel: Any, args: tuple[Any, ...]) -> float:
    """Make sure ``kernel`` (a numba dispatcher) is compiled for ``args``, without running it;
    returns the seconds it took (0 when it already has a compiled version in this process)."""
    overloads = getattr(kernel, "overloads", None)  # None: a Python function (interpreted)
    if overloads is None or overloads:  # (not .signatures: it hashes every one, ~20 us)
        return 0.0
    import numba

    typeof: Any = numba.typeof
    began = time.perf_counter()
    kernel.compile(tuple(typeof(arg) for arg in args))
    return time.perf_counter() - began


def cold_kernels(kernels: tuple[str, ...] = ENTRY_KERNELS) -> list[str]:
    """The kernels among ``kernels`` ("module:name", numba dispatchers with ``cache=True``) that
    have no compiled version in numba's on-disk cache for their current source file (its index
    file, next to the source or under ``NUMBA_CACHE_DIR``, is missing, empty, from another numba
    version, older than the source, or compiled for another CPU): ``_numba_cache.cached``.
    Imports numba, not the kernels' modules; reads one small index file per kernel."""
    return [kernel for kernel in kernels if not cached(kernel)]


def announce_if_cold(
    write: Callable[[str], None], kernels: tuple[str, ...] = ENTRY_KERNELS
) -> bool:
    """Say :data:`NOTICE` through ``write`` (once per process) when some of ``kernels`` are cold
    (:func:`cold_kernels`); returns whether it said it. For the front ends that know ahead that
    the big kernels are about to be used (the pytest plugin, ``lynxplan serve``)."""
    if _state["said"] or not cold_kernels(kernels):
        return False
    _state["said"] = True
    write(NOTICE)
    return True


#: The CLI commands that solve one target (``ik`` without ``--poses``, ``fk``): numba's
#: interpreter answers them faster than a cold compile (:func:`interpret_one_target`).
ONE_TARGET_COMMANDS = frozenset({"ik", "fk"})


def interpret_one_target(command: str | None, argv: list[str]) -> bool:
    """Run the numba kernels as Python in this process (numba's ``NUMBA_DISABLE_JIT``) when
    ``command`` solves one target; returns whether it does. Only before numba is imported, and
    never against the user's own setting of the switch."""
    batch = any(a == "--poses" or a.startswith("--poses=") for a in argv)
    if command not in ONE_TARGET_COMMANDS or batch or "numba" in sys.modules:
        return False
    if "NUMBA_DISABLE_JIT" in os.environ:
        return os.environ["NUMBA_DISABLE_JIT"] == "1"
    os.environ["NUMBA_DISABLE_JIT"] = "1"
    return True


class PythonPlanTooSlowError(Exception):
    """A plan run as Python by :func:`plan_as_python_if_cold` reached its time limit or
    :data:`PYTHON_PLAN_SECONDS`: the CLI plans again compiled (``lynxplan.commands.run``). Not a
    ``LynxplanError`` on purpose: the scenario layer turns those into a failed run, and this one
    must reach the command, before anything is written. Never reaches a user."""


def plan_as_python_if_cold() -> bool:
    """Run the numba kernels of this process as Python (numba's ``NUMBA_DISABLE_JIT``) when
    the planner's kernels have no version in numba's cache; returns whether it does. For a CLI
    process about to run one plan, before any kernel module is imported; never against the
    user's own setting of the switch. The decision reads the cache's index files without
    importing the kernels' modules (:func:`cached`). Only in a CLI process
    (:func:`in_cli_process`): a Python program goes on compiling."""
    kernel_modules = ("lynxplan.arm", "lynxplan.robots", "lynxplan.collision", "lynxplan.planning")
    if not _state["cli"] or "NUMBA_DISABLE_JIT" in os.environ:
        return False
    if any(module in sys.modules for module in kernel_modules):
        return False
    if all(cached(kernel) for kernel in PLANNER_KERNELS):
        return False
    from numba.core import config

    os.environ["NUMBA_DISABLE_JIT"] = "1"
    reload: Any = config.reload_config
    reload()
    _state["python_plan"] = True
    print(PYTHON_PLAN_NOTE, file=sys.stderr, flush=True)  # terminal or log: say why it is slow
    return True


def check_python_plan(elapsed: float, time_limit: float) -> None:
    """Called by the planner between its compiled chunks: raises
    :class:`PythonPlanTooSlowError` when the plan runs as Python by :func:`plan_as_python_if_cold`
    and has used its time limit or :data:`PYTHON_PLAN_SECONDS` (compiled, ~100x faster, it may
    have been solved in time). elapsed, time_limit: [s]."""
    if _state["python_plan"] and elapsed >= min(time_limit, PYTHON_PLAN_SECONDS):
        raise PythonPlanTooSlowError


def kernels_run_as_python() -> bool:
    """Whether this process runs lynxplan's numba kernels as Python (numba's
    ``NUMBA_DISABLE_JIT``: :func:`plan_as_python_if_cold`, :func:`interpret_one_target` or the
    user's own setting)."""
    numba = sys.modules.get("numba")
    return bool(getattr(getattr(numba, "config", None), "DISABLE_JIT", False))


def in_cli_process() -> None:
    """This process is one CLI command (``lynxplan.cli.main`` as the program): it may run its
    kernels as Python (:func:`plan_as_python_if_cold`)."""
    _state["cli"] = True


def enable_notices() -> None:
    """From now on, announce long compiles on stderr (only when stderr is a terminal)."""
    _state["notices"] = sys.stderr.isatty()
    if "numba" in sys.modules:
        listen()


def disable_notices() -> None:
    """No notice from now on (``lynxplan compile`` shows a progress bar instead)."""
    _state["notices"] = False


def cache_folder(kernel: str = ENTRY_KERNELS[0]) -> str:
    """The folder of numba's cache files for ``kernel``'s module (imports it)."""
    module, name = kernel.split(":")
    dispatcher = getattr(importlib.import_module(module), name)
    return str(getattr(getattr(dispatcher, "_cache", None), "_cache_path", "(no cache)"))


def listen() -> None:
    """Start watching numba's compiles unless notices are off (idempotent)."""
    if _state["notices"] is False or _state["listening"]:
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
        if _state["notices"] is False or _state["said"]:
            return
        _state["said"] = True
        if _state["notices"]:
            print(NOTICE, file=sys.stderr, flush=True)
        else:
            warnings.warn(NOTICE.removeprefix("lynxplan: "), CompileWarning, stacklevel=1)
