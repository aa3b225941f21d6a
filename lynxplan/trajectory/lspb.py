"""The report's linear segment with parabolic blends (LSPB), SPEC Part 2.

Notation of the report: total time ``tt``, blend time ``ta = 2 tau``, cruise parameter
``T = tt - 2 tau``; the report's time ``t`` runs over ``[-tau, T + tau]``. For a change ``dA``
from ``A0``:

- ``-tau <= t <= tau``: ``A = A0 + dA (t + tau)^2 / (4 T tau)``
- ``tau <= t <= T - tau``: ``A = A0 + dA t / T``
- ``T - tau <= t <= T + tau``: ``A = A0 + dA (t / T - (t - T + tau)^2 / (4 T tau))``

The law is valid for ``tt >= 2 ta`` (the blends must not overlap). Everything here is vectorised:
times of any shape broadcast against ``A0`` and ``dA``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple, TypeVar

import numpy as np
from numba.extending import register_jitable

from lynxplan.exceptions import TimingError

_Time = TypeVar("_Time", float, np.ndarray)


class LspbState(NamedTuple):
    """Value, rate and second rate of an LSPB law at some times (arrays broadcast together)."""

    position: np.ndarray
    """Value ``A`` (unit of ``A0``)."""
    velocity: np.ndarray
    """``dA/dt``, in [unit/s]."""
    acceleration: np.ndarray
    """``d2A/dt2``, in [unit/s^2]."""


@dataclass(frozen=True)
class LspbTiming:
    """Timing of one LSPB segment.

    Attributes:
        tt: Total time, in [s]; ``tt > 0``.
        ta: Blend time (one blend), in [s]; ``0 < ta <= tt / 2``.
    """

    tt: float
    ta: float

    def __post_init__(self) -> None:
        tt, ta = float(self.tt), float(self.ta)
        if not (math.isfinite(tt) and math.isfinite(ta)):
            raise TimingError(tt, ta, "times must be finite")
        if tt <= 0.0:
            raise TimingError(tt, ta, "the total time tt must be positive")
        if ta <= 0.0:
            raise TimingError(tt, ta, "the blend time ta must be positive")
        if tt < 2.0 * ta:
            raise TimingError(
                tt, ta, f"the blends overlap: tt must be at least 2 ta = {2.0 * ta:.6g} s"
            )
        object.__setattr__(self, "tt", tt)
        object.__setattr__(self, "ta", ta)

    @property
    def tau(self) -> float:
        """Half the blend time, ``tau = ta / 2``, in [s]."""
        return 0.5 * self.ta

    @property
    def cruise_parameter(self) -> float:
        """The report's ``T = tt - 2 tau``, in [s] (cruise time is ``T - 2 tau``)."""
        return self.tt - self.ta

    def peak_rate(self) -> float:
        """Peak of ``ds/dt`` for a unit change, ``1 / T``, in [1/s]."""
        return 1.0 / self.cruise_parameter

    def blend_rate(self) -> float:
        """``|d2s/dt2|`` in the blends for a unit change, ``1 / (2 T tau)``, in [1/s^2]."""
        return 1.0 / (2.0 * self.cruise_parameter * self.tau)


def lspb(
    t: np.ndarray | float,
    a0: np.ndarray | float,
    da: np.ndarray | float,
    timing: LspbTiming,
) -> LspbState:
    """The report's LSPB law in the report's time ``t`` over ``[-tau, T + tau]``.

    Outside that interval the value is held at rest (``A0`` before, ``A0 + dA`` after).

    Args:
        t: Report time, any shape, in [s].
        a0: Start value, broadcastable against ``t``.
        da: Change ``dA``, broadcastable against ``t``; zero gives a stationary segment.
        timing: ``tt`` and ``ta``.

    Returns:
        Value, rate and second rate, broadcast to a common shape.
    """
    tau, big_t = timing.tau, timing.cruise_parameter
    time = np.clip(np.asarray(t, dtype=float), -tau, big_t + tau)
    a0_arr, da_arr = np.asarray(a0, dtype=float), np.asarray(da, dtype=float)
    first = time <= tau
    last = time >= big_t - tau
    blend_in = _first_blend(time, big_t, tau)
    cruise = _cruise(time, big_t)
    blend_out = _last_blend(time, big_t, tau)
    s, sd, sdd = (
        np.where(last, blend_out[k], np.where(first, blend_in[k], cruise[k])) for k in range(3)
    )
    # At rest outside the segment: velocity and acceleration are zero there.
    outside = (np.asarray(t) < -tau) | (np.asarray(t) > big_t + tau)
    sd = np.where(outside, 0.0, sd)
    sdd = np.where(outside, 0.0, sdd)
    return LspbState(a0_arr + da_arr * s, da_arr * sd, da_arr * sdd)


# Report eqs.: the three pieces of the normalised law (SPEC Part 2), at report time ``time``;
# each returns (s, ds/dt, d2s/dt2) for floats or arrays, from Python and from numba kernels.
@register_jitable
def _first_blend(time: _Time, big_t: float, tau: float) -> tuple[_Time, _Time, float]:
    start = time + tau
    return start**2 / (4 * big_t * tau), start / (2 * big_t * tau), 1.0 / (2 * big_t * tau)


@register_jitable
def _cruise(time: _Time, big_t: float) -> tuple[_Time, float, float]:
    return time / big_t, 1.0 / big_t, 0.0


@register_jitable
def _last_blend(time: _Time, big_t: float, tau: float) -> tuple[_Time, _Time, float]:
    end = time - big_t + tau
    return (
        time / big_t - end**2 / (4 * big_t * tau),
        1.0 / big_t - end / (2 * big_t * tau),
        -1.0 / (2 * big_t * tau),
    )


@register_jitable
def lspb_scalar(t: float, tt: float, ta: float) -> tuple[float, float, float]:
    """The normalised law at one time since the start ``t`` for total time ``tt`` and blend
    ``ta`` in [s] (``tt >= 2 ta > 0``, unchecked), in plain floats: ``(s, ds/dt [1/s],
    d2s/dt2 [1/s^2])``; callable from numba kernels and per-sample loops."""
    tau, big_t = 0.5 * ta, tt - ta
    report_time = t - tau
    time = min(max(report_time, -tau), big_t + tau)
    if time >= big_t - tau:
        s, sd, sdd = _last_blend(time, big_t, tau)
    elif time <= tau:
        s, sd, sdd = _first_blend(time, big_t, tau)
    else:
        s, sd, sdd = _cruise(time, big_t)
    if report_time < -tau or report_time > big_t + tau:
        return s, 0.0, 0.0
    return s, sd, sdd


def unit_lspb_scalar(t: float, timing: LspbTiming) -> tuple[float, float, float]:
    """:func:`unit_lspb` at one time since the start ``t`` in [s], in plain floats."""
    return lspb_scalar(t, timing.tt, timing.ta)


def lspb_since_start(
    t: np.ndarray | float,
    a0: np.ndarray | float,
    da: np.ndarray | float,
    timing: LspbTiming,
) -> LspbState:
    """The LSPB law in time since the segment's start, ``t`` over ``[0, tt]``.

    Same as :func:`lspb` at report time ``t - tau``.
    """
    return lspb(np.asarray(t, dtype=float) - timing.tau, a0, da, timing)


def unit_lspb(t: np.ndarray | float, timing: LspbTiming) -> LspbState:
    """The normalised law ``s(t)`` from 0 to 1 in time since the segment's start, in [0, tt]."""
    return lspb_since_start(t, 0.0, 1.0, timing)
