"""Recognise the yaw-pitch-pitch-pitch-roll family from a Pinocchio model (geometry, not names).

The test runs on the joint axes and origins at the zero configuration, in the base frame:
joint 1 (yaw, axis ``k``), joints 2-4 with parallel axes perpendicular to ``k`` (pitch, axis
``p``), joint 5 perpendicular to ``p`` (roll, axis ``r``). Anything else is allowed: link offsets
in any direction, built-in angles between links, axes of either sign, joints whose zero is not
the "straight" pose, a tool point anywhere (also off the roll axis). The chain is rewritten in a
canonical frame (``h = k x p`` outward, ``k`` up, ``p`` lateral), which is all the closed-form
solver needs; axis signs become the ``signs`` ``sigma_i`` (joint angle = ``sigma_i`` x canonical
angle).

Geometry measured on real URDFs is rarely exact (SO-101: angles written as 1.5708 and 3.14159,
3.7e-6 rad off), so recognition has a tolerance (:data:`FAMILY_AXIS_TOLERANCE`); the solver then
polishes every closed-form answer on the exact model (``exact`` False below).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from lynxplan.constants import (
    FAMILY_AXIS_TOLERANCE,
    FAMILY_EXACT_TOLERANCE,
    ON_AXIS_TOLERANCE,
)

# Layout of the packed parameter vector read by the numba kernels.
C1, K, P, H, R = 0, 3, 6, 9, 12
O2, O3, O4 = 15, 17, 19
LAM4 = 21
W0, E1, E2 = 22, 25, 28
GAMMA0 = 31
SIGMA = 32
LOWER, UPPER = 37, 42
LIMIT_TOL = 47
OFF_AXIS = 48
RT0 = 49  # 9 entries, row-major tool rotation at q = 0
EXACT = 58
DEVIATION = 59  # the largest angle the model misses the ideal family by [rad]
N_PARAMS = 60


@dataclass(frozen=True)
class FamilyParameters:
    """The yaw-pitch-pitch-pitch-roll arm in canonical form (lengths [m], angles [rad]).

    Attributes:
        yaw_axis: ``k``, unit, base frame (upward where possible).
        pitch_axis: ``p``, unit, base frame at q = 0 (chosen so ``h = k x p`` points at the tool).
        roll_axis: ``r``, unit, base frame at q = 0, pointing from the wrist towards the tool.
        signs: ``sigma_i`` = +1 or -1 per joint: the URDF axis is sigma_i times the canonical one.
        link_lengths: Shoulder-elbow and elbow-wrist distances in the pitch plane.
        built_in_angles: Angles of those two links in the pitch plane at q = 0 (the zero offsets
            and built-in bends of the URDF).
        lateral_offset: Offset of the wrist from the yaw axis along ``p``.
        tool_offset: Tool point relative to the roll joint: along the roll axis and off it.
        approach_in_tool: The roll axis in tool-frame coordinates (the tool's approach axis).
        deviation: Largest angle by which the model misses the ideal family [rad].
        exact: Whether ``deviation`` is below :data:`FAMILY_EXACT_TOLERANCE` (no polishing).
        packed: The packed vector the kernels read (read-only).
    """

    yaw_axis: tuple[float, float, float]
    pitch_axis: tuple[float, float, float]
    roll_axis: tuple[float, float, float]
    signs: tuple[int, ...]
    link_lengths: tuple[float, float]
    built_in_angles: tuple[float, float]
    lateral_offset: float
    tool_offset: tuple[float, float]
    approach_in_tool: tuple[float, float, float]
    deviation: float
    exact: bool
    packed: np.ndarray

    @property
    def tool_on_roll_axis(self) -> bool:
        """Whether the tool point lies on the roll axis (then the IK is fully closed-form)."""
        return self.tool_offset[1] <= ON_AXIS_TOLERANCE


def _unit(v: np.ndarray) -> np.ndarray:
    return np.asarray(v / np.linalg.norm(v), dtype=float)


def _angle_from_perpendicular(u: np.ndarray, v: np.ndarray) -> float:
    return abs(math.asin(min(1.0, abs(float(u @ v)))))


def _angle_from_parallel(u: np.ndarray, v: np.ndarray) -> float:
    return float(math.asin(min(1.0, float(np.linalg.norm(np.cross(u, v))))))


def recognise_family(  # noqa: PLR0915 (one pass over the zero configuration, kept in reading order)
    model: Any, tool_frame_id: int, lower: np.ndarray, upper: np.ndarray, limit_tolerance: float
) -> tuple[FamilyParameters | None, str]:
    """The canonical parameters if the chain is yaw-pitch^3-roll, else ``(None, reason)``."""
    import pinocchio as pin

    if model.nq != 5 or model.njoints != 6:
        return None, f"{model.nq} joints (the family has 5)"
    data = model.createData()
    pin.forwardKinematics(model, data, np.zeros(5))
    pin.updateFramePlacements(model, data)
    from lynxplan.robots.chain import _local_axis

    axes = [_unit(data.oMi[j].rotation @ _local_axis(model.joints[j])) for j in range(1, 6)]
    origins = [np.array(data.oMi[j].translation) for j in range(1, 6)]
    k = axes[0]
    checks = {
        "yaw axis perpendicular to joint 2": _angle_from_perpendicular(k, axes[1]),
        "joints 2 and 3 parallel": _angle_from_parallel(axes[1], axes[2]),
        "joints 2 and 4 parallel": _angle_from_parallel(axes[1], axes[3]),
        "roll axis perpendicular to the pitch axes": _angle_from_perpendicular(axes[1], axes[4]),
    }
    worst = max(checks, key=lambda name: checks[name])
    if checks[worst] > FAMILY_AXIS_TOLERANCE:
        return None, f"not yaw-pitch-pitch-pitch-roll: {worst} fails by {checks[worst]:.3g} rad"
    tool = data.oMf[tool_frame_id]
    t0, rt0 = np.array(tool.translation), np.array(tool.rotation)
    if k[2] < 0:
        k = -k
    c1 = origins[0]
    p = _unit(axes[1] - (axes[1] @ k) * k)
    h = np.cross(k, p)
    if (t0 - c1) @ h < 0:
        p, h = -p, -h
    r = _unit(axes[4] - (axes[4] @ p) * p)
    if (t0 - origins[4]) @ r < 0:
        r = -r
    signs = (
        1 if axes[0] @ k > 0 else -1,
        *(1 if axes[i] @ p > 0 else -1 for i in (1, 2, 3)),
        1 if axes[4] @ r > 0 else -1,
    )

    def planar(x: np.ndarray) -> np.ndarray:
        return np.array([(x - c1) @ h, (x - c1) @ k])

    o2, o3, o4 = planar(origins[1]), planar(origins[2]), planar(origins[3])
    l2, l3 = o3 - o2, o4 - o3
    if min(np.linalg.norm(l2), np.linalg.norm(l3)) < 1e-6:
        return None, "a pitch link has zero length in the pitch plane"
    # Tool relative to joint 4's origin at roll angle theta: w0 + cos(theta) e1 + sin(theta) e2.
    rel = t0 - origins[4]
    along = float(rel @ r)
    perp = rel - along * r
    w0 = origins[4] - origins[3] + along * r
    e1, e2 = perp, np.cross(r, perp)

    def hkp(v: np.ndarray) -> list[float]:
        return [float(v @ h), float(v @ k), float(v @ p)]

    packed = np.zeros(N_PARAMS)
    packed[C1 : C1 + 3] = c1
    packed[K : K + 3] = k
    packed[P : P + 3] = p
    packed[H : H + 3] = h
    packed[R : R + 3] = r
    packed[O2 : O2 + 2], packed[O3 : O3 + 2], packed[O4 : O4 + 2] = o2, o3, o4
    packed[LAM4] = (origins[3] - c1) @ p
    packed[W0 : W0 + 3], packed[E1 : E1 + 3], packed[E2 : E2 + 3] = hkp(w0), hkp(e1), hkp(e2)
    packed[GAMMA0] = math.atan2(float(r @ k), float(r @ h))
    packed[SIGMA : SIGMA + 5] = signs
    packed[LOWER : LOWER + 5] = lower
    packed[UPPER : UPPER + 5] = upper
    packed[LIMIT_TOL] = limit_tolerance
    off_axis = float(np.linalg.norm(perp))
    packed[OFF_AXIS] = 1.0 if off_axis > ON_AXIS_TOLERANCE else 0.0
    packed[RT0 : RT0 + 9] = rt0.reshape(-1)
    deviation = max(checks.values())
    exact = deviation <= FAMILY_EXACT_TOLERANCE
    packed[EXACT] = 1.0 if exact else 0.0
    packed[DEVIATION] = deviation
    packed.setflags(write=False)
    approach = rt0.T @ r
    return (
        FamilyParameters(
            yaw_axis=(float(k[0]), float(k[1]), float(k[2])),
            pitch_axis=(float(p[0]), float(p[1]), float(p[2])),
            roll_axis=(float(r[0]), float(r[1]), float(r[2])),
            signs=signs,
            link_lengths=(float(np.linalg.norm(l2)), float(np.linalg.norm(l3))),
            built_in_angles=(
                float(math.atan2(l2[1], l2[0])),
                float(math.atan2(l3[1], l3[0])),
            ),
            lateral_offset=float(packed[LAM4]),
            tool_offset=(along, off_axis),
            approach_in_tool=(float(approach[0]), float(approach[1]), float(approach[2])),
            deviation=float(deviation),
            exact=exact,
            packed=packed,
        ),
        "yaw-pitch-pitch-pitch-roll",
    )
