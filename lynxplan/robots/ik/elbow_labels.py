"""Which branch is "elbow up": the elbow above the line from the shoulder to the wrist.

The solvers compute the two elbows of a side as the two signs of the two-link triangle's angle
(``family_geometry.two_link``); that sign is "above the line" only while the wrist lies ahead of
the shoulder. Where the wrist lies behind it (the arm leaning back over the base, most of the
back side), the sign means the opposite. :func:`orient_elbows` puts every branch in the slot of
its elbow as seen by a user: elbow up has the elbow joint above the shoulder-wrist line (along
the yaw axis), as in the AL5 report (SPEC: q3 < 0 with the wrist ahead).

Angles are in [rad]; ``prm`` is the packed family vector of :mod:`lynxplan.robots.family`.
"""

from __future__ import annotations

import numba
import numpy as np

from lynxplan._fastmath import sincos
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.family_geometry import TwoLink, two_link_shape
from lynxplan.robots.results import BranchSlots


@numba.njit(cache=True, nogil=True)
def elbow_up(prm: np.ndarray, shape: TwoLink, q: np.ndarray) -> bool:
    """Whether branch q (5,) [rad] has its elbow above the shoulder-wrist line.

    In the arm plane (x outwards, y along the yaw axis) the shoulder-elbow link points at
    t2 = psi2 + b2 and the elbow-wrist link at t2 + delta, delta = psi3 - b2 + b3 (psi: the
    canonical angles, q times the joint's sign). The elbow lies left of the shoulder-to-wrist
    direction where sin(delta) < 0; left is above while the wrist lies ahead (its x > 0).
    """
    la, lb, b2, b3 = shape
    psi2, psi3 = prm[F.SIGMA + 1] * q[1], prm[F.SIGMA + 2] * q[2]
    wrist_x = la * sincos(psi2 + b2)[1] + lb * sincos(psi2 + psi3 + b3)[1]
    return (sincos(psi3 - b2 + b3)[0] < 0.0) != (wrist_x < 0.0)


@numba.njit(cache=True, nogil=True, inline="always")
def pair_swapped(
    prm: np.ndarray, shape: TwoLink, q0: np.ndarray, v0: bool, q1: np.ndarray, v1: bool
) -> bool:
    """Whether the pair of slots (elbow up, elbow down) of one side and roll holds its
    branches the wrong way round: every valid one is in the other elbow's slot."""
    if not (v0 or v1):
        return False
    if v0 and v1 and q0[4] == q1[4]:  # one roll, one wrist point: one question
        return not elbow_up(prm, shape, q0)
    wrong0 = (not elbow_up(prm, shape, q0)) if v0 else True
    wrong1 = elbow_up(prm, shape, q1) if v1 else True
    return wrong0 and wrong1


@numba.njit(cache=True, nogil=True)
def orient_elbows(prm: np.ndarray, slots: BranchSlots) -> None:
    """Swap, in place, the two elbow slots (2k, 2k + 1) of each target where they hold their
    branches the wrong way round (:func:`pair_swapped`); slots of the batch layout: q (N, B, 5),
    the others (N, B)."""
    shape = two_link_shape(prm)
    q, valid, within = slots.q, slots.valid, slots.within
    position_error, orientation_error = slots.position_error, slots.orientation_error
    for n in range(valid.shape[0]):
        for b in range(0, valid.shape[1], 2):
            if not pair_swapped(prm, shape, q[n, b], valid[n, b], q[n, b + 1], valid[n, b + 1]):
                continue
            for j in range(5):
                q[n, b, j], q[n, b + 1, j] = q[n, b + 1, j], q[n, b, j]
            valid[n, b], valid[n, b + 1] = valid[n, b + 1], valid[n, b]
            within[n, b], within[n, b + 1] = within[n, b + 1], within[n, b]
            position_error[n, b], position_error[n, b + 1] = (
                position_error[n, b + 1],
                position_error[n, b],
            )
            orientation_error[n, b], orientation_error[n, b + 1] = (
                orientation_error[n, b + 1],
                orientation_error[n, b],
            )


@numba.njit(cache=True, nogil=True)
def orient_table(prm: np.ndarray, table: np.ndarray, valid: np.ndarray) -> None:
    """:func:`orient_elbows` of one target's slot table (B, columns): q in columns 0-4, 1/0 in
    ``valid`` (B,) (a column of the table); swapped pairs swap whole rows."""
    shape = two_link_shape(prm)
    for b in range(0, table.shape[0], 2):
        v0, v1 = valid[b] != 0.0, valid[b + 1] != 0.0
        if pair_swapped(prm, shape, table[b, :5], v0, table[b + 1, :5], v1):
            for j in range(table.shape[1]):
                table[b, j], table[b + 1, j] = table[b + 1, j], table[b, j]
