"""The sizes a request implies, computed from its inputs with Python numbers and checked against
the server's limits before anything is allocated or any worker is asked (Problem 413 naming
the field, the size and the limit).

Sizes checked: trajectory samples (duration x rate, the duration bounded below by the time law
of the limits given, :func:`lynxplan.trajectory.timing.min_rest_to_rest_duration`), collision
pairs (configurations x obstacles) and the answer's bytes (poses x bytes per pose, samples x
bytes per sample). The library checks the exact sample count again before it samples
(:func:`lynxplan.trajectory.retime.sample_times`), under the same limit.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from typing import Any

import numpy as np

from lynxplan.service.config import ServiceConfig
from lynxplan.service.problems import Problem

#: Bytes one number takes in a JSON answer, at most (orjson: up to 24 characters and a comma).
JSON_NUMBER_BYTES = 25
#: Numbers per sample of a trajectory answer: t and q, qd, qdd of 5 joints.
SAMPLE_NUMBERS = 16
#: Answer bytes per configuration of ``/fk`` (a 4x4 pose): binary float64, JSON.
FK_POSE_BYTES = {"binary": 8 * 16, "json": JSON_NUMBER_BYTES * 16}
#: Numbers per configuration of a ``/check`` answer besides one clearance per obstacle.
CHECK_CONFIG_NUMBERS = 3
#: Most configuration x obstacle distance queries in one ``/check`` (about 3 us each).
MAX_CHECK_PAIRS = 2_000_000


def sample_limit(config: ServiceConfig) -> int:
    """Most trajectory samples in one answer: what fits in ``max_answer`` as JSON."""
    return max(2, max_answer(config) // (SAMPLE_NUMBERS * JSON_NUMBER_BYTES))


def max_answer(config: ServiceConfig) -> int:
    """Largest answer, in [bytes]."""
    return config.max_answer


def _mb(n: float) -> str:
    return f"{n / 1e6:.3g} MB"


def check_answer(config: ServiceConfig, field: str, count: int, per_item: int, what: str) -> None:
    """Problem 413 when ``count`` ``what`` of ``per_item`` bytes exceed the answer limit."""
    limit = max_answer(config)
    if count * per_item > limit:
        raise Problem(
            413,
            f"{field}: an answer of {count} {what} would take about {_mb(count * per_item)}, "
            f"more than the limit of {_mb(limit)}; send at most {limit // per_item} per request",
            field,
        )


def ik_pose_bytes(answer: str, slots: int, dof: int) -> int:
    """Answer bytes per pose of an ``/ik`` batch of ``slots`` branch slots of ``dof`` joints,
    at most (q, four flags or errors per slot, two per pose): ``answer`` binary or json."""
    numbers = slots * (dof + 4) + 2
    return 8 * numbers + 64 if answer == "binary" else JSON_NUMBER_BYTES * numbers


def check_pairs(config: ServiceConfig, configurations: int, obstacles: int) -> None:
    """``/check``: configurations x obstacles within :data:`MAX_CHECK_PAIRS` and the answer."""
    pairs = configurations * obstacles
    if pairs > MAX_CHECK_PAIRS:
        raise Problem(
            413,
            f"obstacles: {configurations} configurations x {obstacles} obstacles = {pairs} "
            f"distance queries, more than the limit of {MAX_CHECK_PAIRS} per request",
            "obstacles",
        )
    per_config = JSON_NUMBER_BYTES * (obstacles + CHECK_CONFIG_NUMBERS)
    check_answer(config, "q", configurations, per_config, "configurations")


def motion_samples(
    waypoints: np.ndarray,
    velocity: np.ndarray,
    acceleration: np.ndarray,
    rate: float,
    duration: float | None = None,
) -> tuple[float, float]:
    """(samples, seconds) of a rest-to-rest motion through ``waypoints`` (M, n) [rad] at
    ``rate`` [Hz]: each segment lasts ``duration`` [s] when given, else at least the time law's
    shortest time under the limits (a lower bound for every method). Python floats (inf when
    they overflow), nothing allocated but the deltas."""
    from lynxplan.trajectory.timing import min_rest_to_rest_duration, samples_implied

    samples = seconds = 0.0
    for a, b in itertools.pairwise(waypoints):
        time = (
            duration
            if duration is not None
            else min_rest_to_rest_duration(b - a, velocity, acceleration)
        )
        samples += samples_implied(time, rate) - 1.0  # the segments share their ends
        seconds += time
    return samples + 1.0, seconds


def check_samples(
    config: ServiceConfig,
    count: Callable[[dict[str, Any]], tuple[float, float]],
    values: dict[str, Any],
    defaults: dict[str, Any],
    rate_field: str,
) -> None:
    """Problem 413 when the motion ``count(values)`` -> (samples, seconds) implies more samples
    than :func:`sample_limit`. ``values``: the fields that set the samples, by request field
    name; ``defaults``: the server's values of those the request gave itself. The field named
    is the first given one whose default brings the motion within the limit, else
    ``rate_field``."""
    limit = sample_limit(config)
    samples, seconds = count(values)
    if samples <= limit:
        return
    field = rate_field
    for name, default in defaults.items():
        if name != rate_field and count({**values, name: default})[0] <= limit:
            field = name
            break
    raise Problem(
        413,
        f"{field}: the trajectory would have {samples:.4g} samples ({seconds:.4g} s or more at "
        f"{values[rate_field]:g} Hz), more than the limit of {limit} (an answer of at most "
        f"{_mb(max_answer(config))}); raise the velocity or acceleration limits, or lower the "
        "rate",
        field,
    )


__all__ = [
    "FK_POSE_BYTES",
    "MAX_CHECK_PAIRS",
    "check_answer",
    "check_pairs",
    "check_samples",
    "ik_pose_bytes",
    "motion_samples",
    "sample_limit",
]
