"""Lengths implausible for the robot: a scenario in mm read as metres warns before it runs."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from lynxplan.units import implausible_length, length_factor, warn_implausible_length


def reach_bound(robot: Any) -> float:
    """An upper bound of the tool's distance from the base, in [m]: the lengths of the chain's
    links (joint to joint, then to the tool frame) added up (``robot``: an AL5 ``Arm`` or a
    ``Robot``, anything with a Pinocchio ``model`` and a ``tool_frame_id``)."""
    model = robot.model
    frame = model.frames[robot.tool_frame_id]
    total = float(np.linalg.norm(frame.placement.translation))
    joint = int(frame.parentJoint)
    while joint > 0:
        total += float(np.linalg.norm(model.jointPlacements[joint].translation))
        joint = int(model.parents[joint])
    return total


def warn_implausible_lengths(
    robot: Any,
    length_unit: str,
    obstacles: Sequence[Any],
    targets: Sequence[tuple[str, Sequence[float]]],
) -> None:
    """One warning (:class:`lynxplan.units.ImplausibleLengthWarning`) when obstacle positions or
    sizes or target points exceed ``IMPLAUSIBLE_REACH_FACTOR`` times the robot's reach, naming
    the first and counting the others. A file in mm read as metres would otherwise pass
    silently or only show as "start is in collision" or "goal out of reach".

    Args:
        robot: The loaded robot (see :func:`reach_bound`).
        length_unit: The scenario's length unit.
        obstacles: The scenario's obstacle entries (``centre``, ``min_corner``, ``size``,
            ``radius``, ``length``), in ``length_unit``.
        targets: (key, point (3,)) of the target points, in ``length_unit``.
    """
    reach = reach_bound(robot)
    length = length_factor(length_unit)
    lengths: list[tuple[str, float]] = []
    for i, entry in enumerate(obstacles):
        for key in ("centre", "min_corner", "size", "radius", "length"):
            value = getattr(entry, key, None)
            if value is not None:
                largest = float(np.abs(np.atleast_1d(np.asarray(value, dtype=float))).max())
                lengths.append((f"obstacles[{i}].{key}", largest * length))
    for key, point in targets:
        lengths.append((key, float(np.linalg.norm(np.asarray(point, dtype=float))) * length))
    bad = [(key, value) for key, value in lengths if implausible_length(value, reach)]
    if bad:
        warn_implausible_length(bad[0][0], bad[0][1], reach, length_unit, len(bad) - 1)
