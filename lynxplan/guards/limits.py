"""Resource limits checked before any allocation: the most elements one computation may create
and the longest planning time, raised for a ``with`` block by
:func:`lynxplan.guards.scalars.raised_limits` (which checks its values with the scalar checks)."""

from __future__ import annotations

import math
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass

from lynxplan.exceptions import ResourceLimitError

#: Default largest number of elements (samples, grid cells, poses) one computation may create.
DEFAULT_MAX_SAMPLES = 100_000_000
#: Default largest planning time limit, in [s].
DEFAULT_MAX_PLANNING_TIME = 600.0
#: How a user raises a resource limit (appended to every ResourceLimitError). The scenario layer
#: applies a file's own limit with :func:`raised_limits` around the run.
HOW_TO_RAISE = "raise the limit with --max-samples N (or raised_limits(max_samples=N) in Python)"


@dataclass(frozen=True)
class ResourceLimits:
    """Resource limits checked before any allocation.

    Attributes:
        max_samples: Most elements (samples, grid cells, poses, trajectory samples) one
            computation may create.
        max_planning_time: Longest accepted planning time limit, in [s].
    """

    max_samples: int = DEFAULT_MAX_SAMPLES
    max_planning_time: float = DEFAULT_MAX_PLANNING_TIME


_DEFAULT_LIMITS = ResourceLimits()
#: The limits set by :func:`lynxplan.guards.scalars.raised_limits` (None: the defaults).
_LIMITS: ContextVar[ResourceLimits | None] = ContextVar("lynxplan_resource_limits", default=None)


def current_limits() -> ResourceLimits:
    """The resource limits in force (default, or those set by ``raised_limits``)."""
    return _LIMITS.get() or _DEFAULT_LIMITS


@contextmanager
def limits_in_force(limits: ResourceLimits) -> Iterator[ResourceLimits]:
    """``limits`` in force inside a ``with`` block (unchecked: ``raised_limits`` checks them)."""
    token = _LIMITS.set(limits)
    try:
        yield limits
    finally:
        _LIMITS.reset(token)


def check_size(quantity: str, requested: float, bytes_per_element: float = 0.0) -> None:
    """Refuse a computation of ``requested`` elements beyond ``max_samples`` (before allocating).

    Raises:
        ResourceLimitError: naming the quantity, the size, the limit and how to raise it.
    """
    limit = current_limits().max_samples
    if not requested <= limit:  # also catches NaN
        memory = ""
        if bytes_per_element > 0 and math.isfinite(_as_float(requested)):
            memory = f" (about {_bytes(_as_float(requested) * bytes_per_element)} of memory)"
        raise ResourceLimitError(f"{quantity}{memory}", _as_float(requested), limit, HOW_TO_RAISE)


def grid_cells(quantity: str, extent: float, cell: float, dims: int) -> int:
    """Cells of a ``dims``-D grid of edge ``cell`` over ``extent`` (same unit), checked."""
    per_axis = extent / cell + 2.0
    total = per_axis**dims if per_axis < 1e100 else math.inf
    check_size(f"{quantity} ({per_axis:.3g} per axis for a {cell:.3g} cell)", total, 1.0)
    return math.ceil(per_axis)


def _as_float(n: float) -> float:
    """``float(n)``, infinity for integers beyond the float range."""
    try:
        return float(n)
    except OverflowError:
        return math.inf


def _bytes(n: float) -> str:
    for unit in ("B", "kB", "MB", "GB", "TB"):
        if n < 1000:
            return f"{n:.3g} {unit}"
        n /= 1000
    return f"{n:.3g} PB"
