"""``lynxplan bench``: performance figures measured side by side in one run.

Each section module exposes ``run(quick: bool) -> list[Figure]``. Figures are medians over
repeats (the machine is shared and noisy); ratios between figures of one run are what to quote.

Every figure with a target gets one :func:`verdict`: ``ok`` only when its value is a finite number
that meets the target, ``MISSED`` otherwise. A section that raises is reported as one figure
``NOT RUN`` with the error; a peer (OMPL, pyroboplan, placo, ...) that is not installed is
reported as ``peer not installed``: peers are optional, so that is no failure.
"""

from __future__ import annotations

import importlib
import math
import operator
import re
import time
from collections.abc import Callable
from typing import NamedTuple

#: Section name -> module with ``run(quick) -> list[Figure]``.
SECTIONS: dict[str, str] = {
    "arm": "lynxplan.bench.arm",
    "singularity": "lynxplan.bench.singularity",
    "parallel": "lynxplan.bench.parallel",
    "trajectory": "lynxplan.bench.trajectory",
    "collision": "lynxplan.bench.collision",
    "task": "lynxplan.bench.task",
    "cold": "lynxplan.bench.cold",
    "plan": "lynxplan.bench.plan",
    "serve": "lynxplan.bench.serve",
    "robots": "lynxplan.bench.robots",
    "suite": "lynxplan.bench.suite",
}


class Figure(NamedTuple):
    """One measured figure."""

    section: str
    """Bench section, e.g. ``"arm"``."""
    name: str
    """What was measured."""
    value: float
    """The measured value (median over repeats)."""
    unit: str
    """Unit of ``value``, e.g. ``"poses/s"``, ``"us"``, ``"x"`` for ratios."""
    target: str = ""
    """The target from the issue, e.g. ``">= 3e6"``, or empty."""
    met: bool | None = None
    """Whether the target is met, or None when there is no target."""
    skipped: str = ""
    """Why there is no value (``value`` is NaN), or empty: :data:`PEER_NOT_INSTALLED` and the
    peer's name, or what stopped the measurement (an error)."""


#: Verdicts of a figure (:func:`verdict`); "" for a figure without a target.
OK, MISSED, NOT_RUN, PEER_NOT_INSTALLED = "ok", "MISSED", "NOT RUN", "peer not installed"
_TARGET = re.compile(r"^\s*(>=|<=|>|<|==)?\s*([-+0-9.eE]+)\s*$")
_COMPARE = {">=": operator.ge, "<=": operator.le, ">": operator.gt, "<": operator.lt}


def meets(value: float, target: str) -> bool:
    """Whether ``value`` meets ``target`` (``">= 3e6"``, ``"<= 0.5"``, or a bare number: equal).

    A value that is not a finite number meets no target; a target of another form is met by no
    value (a figure is never ``ok`` by accident).
    """
    match = _TARGET.match(target)
    if match is None or not math.isfinite(value):
        return False
    bound = float(match.group(2))
    return bool(_COMPARE.get(match.group(1) or "", operator.eq)(value, bound))


def verdict(figure: Figure) -> str:
    """``ok``, ``MISSED``, ``NOT RUN``, ``peer not installed`` or "" (no target).

    ``ok`` needs both the section's own ``met`` and :func:`meets` on the value shown.
    """
    if figure.skipped:
        return PEER_NOT_INSTALLED if figure.skipped.startswith(PEER_NOT_INSTALLED) else NOT_RUN
    if not figure.target:
        return ""
    return OK if figure.met is not False and meets(figure.value, figure.target) else MISSED


def peer_missing(section: str, peer: str, looked_for: object) -> Figure:
    """The figure saying that the optional peer ``peer`` is not installed."""
    reason = f"{PEER_NOT_INSTALLED} (no {looked_for}; optional, see lynxplan.bench.peers)"
    return Figure(section, peer, math.nan, "", skipped=reason)


def not_run(section: str, what: str, reason: str) -> Figure:
    """The figure saying that ``what`` could not be measured, and why."""
    return Figure(section, what, math.nan, "", skipped=reason)


def median_seconds(
    fn: Callable[[], object],
    *,
    repeats: int = 7,
    number: int = 1,
    clock: Callable[[], float] = time.thread_time,
) -> float:
    """Median time of one call of ``fn``, in [s], over ``repeats`` batches of ``number`` calls.

    The default clock is the calling thread's CPU time: every kernel measured here runs on that
    one thread, so the figure is one core's throughput even when other processes share the
    machine (wall time would count the time the thread waits for a core). Pass
    ``clock=time.perf_counter`` for wall time.
    """
    fn()  # warm-up: JIT compilation, caches
    samples = []
    for _ in range(repeats):
        start = clock()
        for _ in range(number):
            fn()
        samples.append((clock() - start) / number)
    samples.sort()
    return samples[len(samples) // 2]


def run_sections(names: list[str] | None = None, *, quick: bool = False) -> list[Figure]:
    """Run the named sections (all by default) and collect their figures; a section that raises
    gives one ``NOT RUN`` figure naming the error."""
    figures: list[Figure] = []
    for name in names or list(SECTIONS):
        figures += _run_section(name, quick)
    return figures


def _run_section(name: str, quick: bool) -> list[Figure]:
    """The figures of section ``name``, or one ``NOT RUN`` figure naming the error it raised
    (one section's failure is reported; the others still run)."""
    try:
        module = importlib.import_module(SECTIONS[name])
        figures: list[Figure] = module.run(quick)
    except Exception as error:
        reason = (f"{type(error).__name__}: {error}".strip().splitlines() or ["error"])[0]
        return [not_run(name, "section could not run", reason[:300])]
    return figures
