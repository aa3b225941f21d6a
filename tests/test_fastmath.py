"""The inlined sine/cosine/arctangent used by the kernels, against libm."""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest

from lynxplan._fastmath import atan2, prefetch, prefetch_write, sincos, wide_vectors

ULP_TOLERANCE = 4.5e-16  # a few units in the last place for values of order 1


@numba.njit(cache=True)
def _sincos_many(x: np.ndarray, s: np.ndarray, c: np.ndarray) -> None:
    for i in range(x.size):
        s[i], c[i] = sincos(x[i])


@numba.njit(cache=True)
def _atan2_many(y: np.ndarray, x: np.ndarray, out: np.ndarray) -> None:
    for i in range(x.size):
        out[i] = atan2(y[i], x[i])


def test_sincos_matches_libm() -> None:
    rng = np.random.default_rng(0)
    x = np.concatenate(
        (rng.uniform(-50, 50, 2_000_000), np.arange(-64, 65) * np.pi / 4, [0.0, -0.0, 1e-300, 1e5])
    )
    s, c = np.empty_like(x), np.empty_like(x)
    _sincos_many(x, s, c)
    assert np.abs(s - np.sin(x)).max() <= ULP_TOLERANCE
    assert np.abs(c - np.cos(x)).max() <= ULP_TOLERANCE


def test_atan2_matches_libm_over_magnitudes() -> None:
    rng = np.random.default_rng(1)
    n = 2_000_000
    y = rng.normal(size=n) * 10.0 ** rng.uniform(-8, 8, n)
    x = rng.normal(size=n) * 10.0 ** rng.uniform(-8, 8, n)
    out = np.empty(n)
    _atan2_many(y, x, out)
    assert np.abs(out - np.arctan2(y, x)).max() <= 2 * ULP_TOLERANCE


@pytest.mark.parametrize(
    ("y", "x"),
    [
        (0.0, -1.0),
        (-0.0, -1.0),
        (0.0, 0.0),
        (-0.0, 0.0),
        (0.0, -0.0),
        (-0.0, -0.0),
        (1.0, 0.0),
        (-1.0, 0.0),
        (1.0, -1.0),
        (-1.0, -1.0),
        (1e-300, -1.0),
        (3.0, 1e-300),
    ],
)
def test_atan2_special_values(y: float, x: float) -> None:
    out = np.empty(1)
    _atan2_many(np.array([y]), np.array([x]), out)
    assert out[0] == pytest.approx(math.atan2(y, x), abs=1e-15)
    assert math.copysign(1.0, out[0]) == math.copysign(1.0, math.atan2(y, x))


def test_wide_vectors_reaches_the_compiled_function() -> None:
    """The 512-bit vector attribute is on the kernel that asks for it, and only there."""

    @numba.njit
    def wide(x: np.ndarray) -> float:
        wide_vectors()
        return float(x.sum())

    @numba.njit
    def plain(x: np.ndarray) -> float:
        return float(x.sum())

    x = np.arange(8.0)
    assert wide(x) == plain(x) == 28.0
    (wide_ir,) = wide.inspect_llvm().values()
    (plain_ir,) = plain.inspect_llvm().values()
    assert '"prefer-vector-width"="512"' in wide_ir
    assert '"prefer-vector-width"="512"' not in plain_ir


def test_prefetch_is_emitted_and_changes_nothing() -> None:
    """The prefetches reach LLVM (a read and a write prefetch) and leave the arrays as they
    were, also for an index past the end (a prefetch never faults)."""

    @numba.njit
    def touched(x: np.ndarray, y: np.ndarray) -> float:
        for k in range(0, x.size + 64, 8):
            prefetch(x, k)
            prefetch_write(y, k)
        return float(x.sum())

    x, y = np.arange(16.0).reshape(4, 4), np.zeros(16)
    assert touched(x, y) == 120.0
    assert np.array_equal(x, np.arange(16.0).reshape(4, 4)) and not y.any()
    (ir,) = touched.inspect_llvm().values()
    assert "@llvm.prefetch" in ir
    assert "i32 0, i32 3, i32 1" in ir and "i32 1, i32 3, i32 1" in ir
