"""The numba kernel that checks a stack of 4x4 poses in one pass (finite, translation in range,
last row ``0 0 0 1``, rotation block orthonormal and proper), compiled on first use."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from lynxplan.constants import RIGIDITY_REPAIR_TOLERANCE

POSE_OK, POSE_NON_FINITE, POSE_FAR, POSE_BOTTOM_ROW = 0, 1, 2, 3
POSE_NOT_ORTHONORMAL, POSE_REFLECTION = 4, 5


_COMPILED: dict[str, Any] = {}


def pose_check_kernel(T: np.ndarray, max_length: float, approach_only: bool) -> np.ndarray:
    """The first bad pose (:func:`_pose_check`), compiled by numba on first use (``import
    lynxplan.guards`` stays cheap for the CLI)."""
    kernel = _COMPILED.get("pose_check")
    if kernel is None:
        import numba

        kernel = _COMPILED["pose_check"] = numba.njit(cache=True, nogil=True)(_pose_check)
    result: np.ndarray = kernel(T, max_length, approach_only)
    return result


def _pose_check(T: np.ndarray, max_length: float, approach_only: bool) -> np.ndarray:
    """First bad pose of ``T`` (N, 4, 4): ``[index, code, detail]``; code 0: all good, and the
    detail is then the largest deviation of a rotation block from orthonormal (0 with
    ``approach_only``).

    A first pass without early exits or a floating-point reduction (vectorised: each pose's
    deviation to a row, their largest found on the bit patterns, whose integer order is the
    order of non-negative floats) checks every pose; only when one fails does the second pass
    look for the first bad one."""
    out = np.zeros(3)
    deviations = np.empty(T.shape[0])  # 0 with approach_only
    good = True
    for k in range(T.shape[0]):
        r0 = (T[k, 0, 0] + T[k, 0, 1]) + (T[k, 0, 2] + T[k, 0, 3])
        r1 = (T[k, 1, 0] + T[k, 1, 1]) + (T[k, 1, 2] + T[k, 1, 3])
        r2 = (T[k, 2, 0] + T[k, 2, 1]) + (T[k, 2, 2] + T[k, 2, 3])
        r3 = (T[k, 3, 0] + T[k, 3, 1]) + (T[k, 3, 2] + T[k, 3, 3])
        nan = ((r0 + r1) + (r2 + r3)) * 0.0  # NaN when an element is not finite
        far = max(abs(T[k, 0, 3]), abs(T[k, 1, 3]), abs(T[k, 2, 3]))
        bottom = max(abs(T[k, 3, 0]), abs(T[k, 3, 1]), abs(T[k, 3, 2]), abs(T[k, 3, 3] - 1.0))
        if approach_only:
            deviation = abs(T[k, 0, 2] ** 2 + T[k, 1, 2] ** 2 + T[k, 2, 2] ** 2 - 1.0)
            det = 1.0
        else:
            deviation = 0.0
            for i in range(3):
                for j in range(i, 3):  # R^T R is symmetric
                    dot = (
                        T[k, 0, i] * T[k, 0, j] + T[k, 1, i] * T[k, 1, j] + T[k, 2, i] * T[k, 2, j]
                    )
                    deviation = max(deviation, abs(dot - (1.0 if i == j else 0.0)))
            det = (
                T[k, 0, 0] * (T[k, 1, 1] * T[k, 2, 2] - T[k, 1, 2] * T[k, 2, 1])
                - T[k, 0, 1] * (T[k, 1, 0] * T[k, 2, 2] - T[k, 1, 2] * T[k, 2, 0])
                + T[k, 0, 2] * (T[k, 1, 0] * T[k, 2, 1] - T[k, 1, 1] * T[k, 2, 0])
            )
        deviations[k] = 0.0 if approach_only else deviation
        good &= (
            (nan == 0.0)
            & (far <= max_length)
            & (bottom <= 1e-9)
            & (deviation <= RIGIDITY_REPAIR_TOLERANCE)
            & (det >= 0.0)
        )
    if good:  # every deviation finite and >= 0: the largest bit pattern is the largest value
        bits = deviations.view(np.int64)
        top = np.int64(0)
        for k in range(bits.size):
            top = max(top, bits[k])
        out.view(np.int64)[2] = top
        return out
    worst = 0.0
    for k in range(T.shape[0]):
        t = T[k]
        for i in range(4):
            for j in range(4):
                if not math.isfinite(t[i, j]):
                    out[0], out[1] = k, POSE_NON_FINITE
                    return out
        for i in range(3):
            if abs(t[i, 3]) > max_length:
                out[0], out[1], out[2] = k, POSE_FAR, t[i, 3]
                return out
        bottom = max(abs(t[3, 0]), abs(t[3, 1]), abs(t[3, 2]), abs(t[3, 3] - 1.0))
        if bottom > 1e-9:
            out[0], out[1], out[2] = k, POSE_BOTTOM_ROW, bottom
            return out
        if approach_only:
            norm2 = t[0, 2] ** 2 + t[1, 2] ** 2 + t[2, 2] ** 2
            if abs(norm2 - 1.0) > RIGIDITY_REPAIR_TOLERANCE:
                out[0], out[1], out[2] = k, POSE_NOT_ORTHONORMAL, abs(norm2 - 1.0)
                return out
            continue
        deviation = 0.0
        for i in range(3):
            for j in range(3):
                dot = t[0, i] * t[0, j] + t[1, i] * t[1, j] + t[2, i] * t[2, j]
                deviation = max(deviation, abs(dot - (1.0 if i == j else 0.0)))
        if deviation > RIGIDITY_REPAIR_TOLERANCE:
            out[0], out[1], out[2] = k, POSE_NOT_ORTHONORMAL, deviation
            return out
        worst = max(worst, deviation)
        det = (
            t[0, 0] * (t[1, 1] * t[2, 2] - t[1, 2] * t[2, 1])
            - t[0, 1] * (t[1, 0] * t[2, 2] - t[1, 2] * t[2, 0])
            + t[0, 2] * (t[1, 0] * t[2, 1] - t[1, 1] * t[2, 0])
        )
        if det < 0.0:
            out[0], out[1], out[2] = k, POSE_REFLECTION, det
            return out
    out[2] = worst
    return out
