"""Validation of joint-angle arrays (numba-free, so that light commands import fast)."""

from __future__ import annotations

import numpy as np

from lynxplan._arrays import as_rows


def as_configurations(
    q: np.ndarray | list[float] | tuple[float, ...], name: str = "q"
) -> np.ndarray:
    """Validate joint angles: shape (5,) or (N, 5), finite. Returns a float (N, 5) array."""
    from lynxplan.guards import float_array  # strings, ragged lists: InputError, not ValueError

    return as_rows(float_array(name, q), 5, name)
