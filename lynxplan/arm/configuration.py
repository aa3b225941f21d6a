"""Validation of joint-angle arrays (numba-free, so that light commands import fast)."""

from __future__ import annotations

import numpy as np

from lynxplan.exceptions import NonFiniteInputError, ShapeError


def as_configurations(
    q: np.ndarray | list[float] | tuple[float, ...], name: str = "q"
) -> np.ndarray:
    """Validate joint angles: shape (5,) or (N, 5), finite. Returns a float (N, 5) array."""
    array = np.asarray(q, dtype=float)
    if array.ndim not in (1, 2) or array.shape[-1] != 5:
        raise ShapeError(name, "(5,) or (N, 5)", array.shape)
    if not np.isfinite(array).all():
        raise NonFiniteInputError(name)
    return np.ascontiguousarray(array.reshape(-1, 5))
