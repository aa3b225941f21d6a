"""Independent reference computations for the arm tests (plain numpy, no lynxplan code)."""

from __future__ import annotations

import numpy as np

INCH = 0.0254
#: Standard DH table of SPEC Part 1: (a [m], alpha [rad], d [m]) per joint.
DH_TABLE = (
    (0.0, np.pi / 2, 0.0),
    (5.75 * INCH, 0.0, 0.0),
    (7.375 * INCH, 0.0, 0.0),
    (0.0, np.pi / 2, 0.0),
    (0.0, 0.0, 3.375 * INCH),
)


def dh_frames(q: np.ndarray) -> list[np.ndarray]:
    """DH frames 1..5 of one configuration: products of A_i = Rz(q) Tz(d) Tx(a) Rx(alpha)."""
    frames, current = [], np.eye(4)
    for theta, (a, alpha, d) in zip(q, DH_TABLE, strict=True):
        ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
        link = np.array(
            [
                [ct, -st * ca, st * sa, a * ct],
                [st, ct * ca, -ct * sa, a * st],
                [0, sa, ca, d],
                [0, 0, 0, 1],
            ]
        )
        current = current @ link
        frames.append(current)
    return frames


def random_configurations(rng: np.random.Generator, n: int, lower, upper) -> np.ndarray:
    """Uniform random configurations within limits, shape (n, 5), in [rad]."""
    return rng.uniform(lower, upper, size=(n, 5))


def rotation_angle(R1: np.ndarray, R2: np.ndarray) -> np.ndarray:
    """Angle of R1^T R2 for stacks (..., 3, 3), in [rad], accurate near 0."""
    relative = np.swapaxes(R1, -1, -2) @ R2
    skew = 0.5 * np.stack(
        (
            relative[..., 2, 1] - relative[..., 1, 2],
            relative[..., 0, 2] - relative[..., 2, 0],
            relative[..., 1, 0] - relative[..., 0, 1],
        ),
        axis=-1,
    )
    cosine = 0.5 * (np.trace(relative, axis1=-2, axis2=-1) - 1.0)
    return np.arctan2(np.linalg.norm(skew, axis=-1), cosine)
