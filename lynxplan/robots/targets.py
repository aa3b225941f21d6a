"""IK targets of a robot in packed form: full poses, position + approach, position + pitch."""

from __future__ import annotations

from typing import Any

import numpy as np

from lynxplan.constants import ORTHONORMAL_TOLERANCE
from lynxplan.exceptions import NonFiniteInputError, ShapeError, TargetError

KIND_POSE, KIND_APPROACH, KIND_PITCH = 0, 1, 2


class Target:
    """IK targets in packed form (internal): poses (N, 4, 4), kind, pitch (N,), roll (N,)."""

    def __init__(self, poses: np.ndarray, kind: int, pitch: np.ndarray, roll: np.ndarray) -> None:
        self.poses, self.kind, self.pitch, self.roll = poses, kind, pitch, roll


def as_array(x: Any, name: str, shape_tail: tuple[int, ...]) -> np.ndarray:
    array = np.asarray(x, dtype=float)
    nd = len(shape_tail)
    if array.shape[array.ndim - nd :] != shape_tail or array.ndim not in (nd, nd + 1):
        expected = ", ".join(map(str, shape_tail))
        raise ShapeError(name, f"({expected}) or (N, {expected})", array.shape)
    if not np.isfinite(array).all():
        raise NonFiniteInputError(name)
    return array.reshape((-1, *shape_tail))


def _rigid_poses(poses: Any) -> np.ndarray:
    """Full target poses (N, 4, 4): checked by ``lynxplan.guards.poses`` (finite, in range,
    last row 0 0 0 1, rotation within the repair tolerance of proper orthonormal), then
    rotation blocks off orthonormal replaced by the nearest rotation (polar decomposition)."""
    from lynxplan.guards.arrays import poses_with_deviation

    checked, deviation = poses_with_deviation("pose", poses)
    if deviation <= ORTHONORMAL_TOLERANCE:  # the common case: nothing to repair
        return checked.reshape(-1, 4, 4)
    array = np.array(checked, dtype=float).reshape(-1, 4, 4)
    rotations = array[:, :3, :3]
    gram = np.einsum("nji,njk->nik", rotations, rotations) - np.eye(3)
    off = np.abs(gram).max(axis=(1, 2)) > ORTHONORMAL_TOLERANCE
    if off.any():
        u, _, vt = np.linalg.svd(rotations[off])
        array[off, :3, :3] = u @ vt
    return array


def make_target(  # noqa: PLR0912 (one branch per target form)
    poses: Any = None,
    positions: Any = None,
    approaches: Any = None,
    pitches: Any = None,
    rolls: Any = None,
) -> Target:
    """Pack one kind of target. Raises TargetError for a missing/contradictory combination."""
    if poses is not None:
        if positions is not None or approaches is not None or pitches is not None:
            raise TargetError("give a pose, or a position with an approach or a pitch; not both")
        array = _rigid_poses(poses)
        kind = KIND_POSE
        n = array.shape[0]
    else:
        if positions is None:
            raise TargetError("give a pose (4x4) or a position (x, y, z)")
        pos = as_array(positions, "position", (3,))
        n = pos.shape[0]
        array = np.tile(np.eye(4), (n, 1, 1))
        array[:, :3, 3] = pos
        if approaches is not None and pitches is not None:
            raise TargetError("give an approach direction or a pitch, not both")
        if approaches is not None:
            app = as_array(approaches, "approach", (3,))
            norms = np.linalg.norm(app, axis=1)
            if (norms < 1e-12).any():
                raise TargetError("the approach direction must be a non-zero vector")
            app = app / norms[:, None]
            if app.shape[0] not in (1, n):
                raise ShapeError("approach", f"(3,) or ({n}, 3)", app.shape)
            array[:, :3, 2] = app
            kind = KIND_APPROACH
        elif pitches is not None:
            kind = KIND_PITCH
        else:
            raise TargetError("a position needs an approach direction or a pitch")
    pitch = np.zeros(n)
    if pitches is not None:
        p = np.asarray(pitches, dtype=float).reshape(-1)
        if p.shape[0] not in (1, n) or not np.isfinite(p).all():
            raise TargetError(f"pitch must be finite, one value or {n}")
        pitch[:] = p
    roll = np.full(n, np.nan)
    if rolls is not None:
        r = np.asarray(rolls, dtype=float).reshape(-1)
        if r.shape[0] not in (1, n):
            raise TargetError(f"roll must be one value or {n}")
        roll[:] = r
    return Target(np.ascontiguousarray(array), kind, pitch, roll)
