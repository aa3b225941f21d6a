"""A small deterministic random generator for the compiled planners (xorshift64*).

The state is a ``uint64`` array of shape (1,) owned by the caller, so a planner interrupted by
its time limit and resumed draws exactly the same numbers as one run in a single call: the
result depends on the seed only, never on how the work was split.
"""

from __future__ import annotations

import numba
import numpy as np

_MASK = (1 << 64) - 1


def seed_state(seed: int) -> np.ndarray:
    """Generator state, shape (1,), uint64, from any integer seed (splitmix64 scrambled)."""
    z = (int(seed) + 0x9E3779B97F4A7C15) & _MASK
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK
    z ^= z >> 31
    return np.array([z or 0x2545F4914F6CDD1D], dtype=np.uint64)


@numba.njit(cache=True)
def uniform(state: np.ndarray) -> float:
    """Next number in [0, 1) (53 random bits); advances ``state``."""
    x = state[0]
    x ^= x >> np.uint64(12)
    x ^= x << np.uint64(25)
    x ^= x >> np.uint64(27)
    state[0] = x
    return float((x * np.uint64(0x2545F4914F6CDD1D)) >> np.uint64(11)) * (1.0 / 9007199254740992.0)


@numba.njit(cache=True)
def integer(state: np.ndarray, count: int) -> int:
    """Uniform integer in [0, count)."""
    return min(int(uniform(state) * count), count - 1)
