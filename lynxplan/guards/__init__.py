"""Valid ranges of every input quantity, and resource limits checked before any allocation.

Public entry points (``Arm.fk/ik/ik_batch/jacobian``, the 3-RRR IK/FK/workspace, trajectory
builders, collision checks, the CLI) call these checks first, so bad input ends in one
:class:`~lynxplan.exceptions.LynxplanInputError` that names the value, never in a numba typing
error, a wrapped angle, a NaN result, a hang or a MemoryError.

Valid ranges (SI units):

==========================  =====================================================================
quantity                    valid range
==========================  =====================================================================
joint / platform angle      finite, ``|q| <=`` :data:`MAX_ABS_ANGLE` (100 rad; never wrapped)
angle in degrees (CLI)      the same bound, about 5730 deg
position / length           finite, ``|x| <=`` :data:`MAX_ABS_LENGTH` (1 km)
size, step, cell, radius    finite, ``0 <`` value ``<=`` :data:`MAX_ABS_LENGTH`
duration (tt, ta, ...)      finite, ``0 <`` t ``<=`` :data:`MAX_DURATION` (one day)
sample rate                 finite, ``0 <`` rate ``<=`` :data:`MAX_SAMPLE_RATE` (1 MHz)
tolerance                   finite, ``>= 0`` (a NaN tolerance would silently disable a check)
rotation block              3x3, finite, orthonormal within 1e-3 (repaired), ``det = +1``
pose                        4x4, last row ``0 0 0 1``, rotation block as above
seed                        integer, ``0 <= seed < 2**63``
==========================  =====================================================================

Resource limits (:class:`ResourceLimits`): the number of elements (random samples, grid cells,
poses in a batch, trajectory samples) a computation may create is at most ``max_samples``
(default :data:`DEFAULT_MAX_SAMPLES`); a planning time limit is at most ``max_planning_time``.
``max_samples`` is raised with ``--max-samples N`` on the command line (any command, ``run``
included) and both with :func:`raised_limits` in Python (the way for the scenario layer to
apply a file's own limits).
"""

from lynxplan.guards.arrays import (
    angles,
    configurations,
    finite_array,
    float_array,
    planar_poses,
    poses,
    rotation,
)
from lynxplan.guards.limits import (
    DEFAULT_MAX_PLANNING_TIME,
    DEFAULT_MAX_SAMPLES,
    HOW_TO_RAISE,
    ResourceLimits,
    check_size,
    current_limits,
    grid_cells,
)
from lynxplan.guards.scalars import (
    MAX_ABS_ANGLE,
    MAX_ABS_LENGTH,
    MAX_DURATION,
    MAX_SAMPLE_RATE,
    MAX_SEED,
    angle,
    angle_deg,
    count,
    duration,
    in_range,
    length,
    planning_time,
    positive,
    positive_length,
    raised_limits,
    real,
    sample_rate,
    seed,
    tolerance,
)

__all__ = [
    "DEFAULT_MAX_PLANNING_TIME",
    "DEFAULT_MAX_SAMPLES",
    "HOW_TO_RAISE",
    "MAX_ABS_ANGLE",
    "MAX_ABS_LENGTH",
    "MAX_DURATION",
    "MAX_SAMPLE_RATE",
    "MAX_SEED",
    "ResourceLimits",
    "angle",
    "angle_deg",
    "angles",
    "check_size",
    "configurations",
    "count",
    "current_limits",
    "duration",
    "finite_array",
    "float_array",
    "grid_cells",
    "in_range",
    "length",
    "planar_poses",
    "planning_time",
    "poses",
    "positive",
    "positive_length",
    "raised_limits",
    "real",
    "rotation",
    "sample_rate",
    "seed",
    "tolerance",
]
