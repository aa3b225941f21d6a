"""Validation of row-vector inputs shared by the domain packages (numba-free, light to import)."""

from __future__ import annotations

from typing import Any

import numpy as np

from lynxplan.exceptions import NonFiniteInputError, ShapeError


def as_rows(values: Any, width: int, name: str) -> np.ndarray:
    """Validate one row, shape (width,), or a batch, shape (N, width), of finite numbers.

    Returns:
        A C-contiguous float array of shape (N, width) (N = 1 for one row).

    Raises:
        ShapeError: another shape. NonFiniteInputError: NaN or infinity.
    """
    array = np.asarray(values, dtype=float)
    if array.ndim not in (1, 2) or array.shape[-1] != width:
        raise ShapeError(name, f"({width},) or (N, {width})", array.shape)
    if not np.isfinite(array).all():
        raise NonFiniteInputError(name)
    return np.ascontiguousarray(array.reshape(-1, width))


def kernel_input(array: np.ndarray) -> np.ndarray:
    """A kernel's input as a writable C-contiguous array: the array itself when it is one, a copy
    otherwise (a read-only or strided array).

    numba compiles a kernel once per argument type, and a read-only array, a writable one and a
    non-contiguous one are three types. The kernels build their own work arrays writable, so
    passing every input from Python writable too keeps one compiled signature per kernel (each
    costs seconds to tens of seconds of compile on first use). The kernels do not write their
    inputs.
    """
    flags = array.flags
    if flags.c_contiguous and flags.writeable:
        return array
    return np.array(array, order="C")
