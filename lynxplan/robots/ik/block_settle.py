"""The verdict on the vectorised solver's candidates (``pose_block``, step 3): the angles
wrapped into the limits, the errors of the exact chain at the final angles, and which
candidates are taken, rejected or left to a second polish / the scalar polish.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from lynxplan._fastmath import wide_vectors
from lynxplan.constants import (
    BLOCK_FAR_STEP,
    BLOCK_ILL_CONDITIONED,
    BLOCK_NOT_A_BRANCH,
    BLOCK_STALLED,
    BLOCK_TAYLOR_STEP,
    VECTOR_EXACT,
)
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.block_layout import (
    CANDIDATE,
    CANDIDATE_WIDTH,
    FAST,
    LANES,
    Floats,
    angles_of,
    column_of,
    column_of5,
    put_angles,
    sincos,
)
from lynxplan.robots.ik.block_newton import (
    chain_pose,
    fk_turned,
    offsets,
    polish_twice,
    pose_rotation_angle,
    turn,
)
from lynxplan.robots.ik.family_geometry import wrap_into_limits


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def wrapped(pr: Floats, q: Floats) -> Floats:
    """The angles q (5) wrapped into the limits (``wrap_into_limits``), and whether all are
    within them (1/0)."""
    tol = pr[F.LIMIT_TOL]
    lo = (pr[F.LOWER], pr[F.LOWER + 1], pr[F.LOWER + 2], pr[F.LOWER + 3], pr[F.LOWER + 4])
    hi = (pr[F.UPPER], pr[F.UPPER + 1], pr[F.UPPER + 2], pr[F.UPPER + 3], pr[F.UPPER + 4])
    q0, in0 = wrap_into_limits(q[0], lo[0], hi[0], tol)
    q1, in1 = wrap_into_limits(q[1], lo[1], hi[1], tol)
    q2, in2 = wrap_into_limits(q[2], lo[2], hi[2], tol)
    q3, in3 = wrap_into_limits(q[3], lo[3], hi[3], tol)
    q4, in4 = wrap_into_limits(q[4], lo[4], hi[4], tol)
    return q0, q1, q2, q3, q4, 1.0 if in0 & in1 & in2 & in3 & in4 else 0.0


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def snapped_any(pr: Floats, q: Floats, w: Floats) -> bool:
    """Whether the wrapped angles w (``wrapped``'s, 5) of q (5) moved an angle onto a limit:
    more than whole turns (``wrap_into_limits`` without a tolerance). Such a candidate that is
    not taken goes to the scalar polish, which keeps it outside the limits where the snap
    moves the tool off the pose (``family_polish.settle_pose``)."""
    lo = (pr[F.LOWER], pr[F.LOWER + 1], pr[F.LOWER + 2], pr[F.LOWER + 3], pr[F.LOWER + 4])
    hi = (pr[F.UPPER], pr[F.UPPER + 1], pr[F.UPPER + 2], pr[F.UPPER + 3], pr[F.UPPER + 4])
    moved: bool = (
        (wrap_into_limits(q[0], lo[0], hi[0], 0.0)[0] != w[0])
        | (wrap_into_limits(q[1], lo[1], hi[1], 0.0)[0] != w[1])
        | (wrap_into_limits(q[2], lo[2], hi[2], 0.0)[0] != w[2])
        | (wrap_into_limits(q[3], lo[3], hi[3], 0.0)[0] != w[3])
        | (wrap_into_limits(q[4], lo[4], hi[4], 0.0)[0] != w[4])
    )
    return moved


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def snapped(q: float, w: float) -> float:
    """The angle [rad] between q and its wrapped w, less whole turns: what the limits snapped."""
    d = q - w
    return d - math.floor(d * (0.5 / math.pi) + 0.5) * (2.0 * math.pi)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def verdict(t: Floats, p: Floats, prev: float, fold: float) -> Floats:
    """A candidate's position and orientation errors from its pose p on the exact chain at its
    final angles, taken (1/0), and whether it is not a branch (1/0: its error is above
    BLOCK_NOT_A_BRANCH and stopped falling, from prev before the last step, away from a fold (fold
    0); see the module docstring)."""
    dx, dy, dz = p[3] - t[3], p[7] - t[7], p[11] - t[11]
    err = math.sqrt(dx * dx + dy * dy + dz * dz)
    angle = pose_rotation_angle(p, t)
    good = (err <= VECTOR_EXACT) & (angle <= VECTOR_EXACT)
    final = max(err, angle)
    far = (final > BLOCK_NOT_A_BRANCH) & (final >= BLOCK_STALLED * prev) & (fold == 0.0)
    return err, angle, 1.0 if good else 0.0, 1.0 if far else 0.0


@numba.njit(cache=True, nogil=True, fastmath=FAST, error_model="numpy")
def settle_all(m: int, pr: Floats, ch: Floats, c: np.ndarray) -> None:
    """The m candidates in the rows c (flat: row k is c[k * CANDIDATE_WIDTH:]) as they are (an
    exact model
    of the family: no polish), wrapped into the limits, and the verdict (``verdict``) at the
    final angles: taken, fallback (see the module docstring), or neither (not a branch)."""
    wide_vectors()
    for i in range(m):
        t = column_of(c, CANDIDATE_WIDTH, 0, i)
        raw = angles_of(c, i)
        q0, q1, q2, q3, q4, inside = wrapped(pr, raw)
        moved = snapped_any(pr, raw, (q0, q1, q2, q3, q4))
        p = chain_pose(ch, q0, q1, q2, q3, q4)
        prev, fold = (
            c[CANDIDATE.previous_error * CANDIDATE_WIDTH + i],
            c[CANDIDATE.fold * CANDIDATE_WIDTH + i],
        )
        err, angle, good, far = verdict(t, p, prev, fold)
        put_angles(c, i, q0, q1, q2, q3, q4)
        c[CANDIDATE.taken * CANDIDATE_WIDTH + i] = good
        fall = (good == 0.0) & ((far == 0.0) | moved)
        c[CANDIDATE.fallback * CANDIDATE_WIDTH + i] = 1.0 if fall else 0.0
        c[CANDIDATE.within * CANDIDATE_WIDTH + i] = inside
        c[CANDIDATE.position_error * CANDIDATE_WIDTH + i] = err
        c[CANDIDATE.orientation_error * CANDIDATE_WIDTH + i] = angle


@numba.njit(cache=True, nogil=True, fastmath=FAST, error_model="numpy")
def polish_settle_all(m: int, pr: Floats, ch: Floats, c: np.ndarray) -> None:
    """``polish_settle_all_of`` with the normal equations' steps (``newton_ldl``)."""
    wide_vectors()
    polish_settle_all_of(m, pr, ch, c, False)


@numba.njit(cache=True, nogil=True, fastmath=FAST, error_model="numpy")
def polish_settle_all_parallel(m: int, pr: Floats, ch: Floats, c: np.ndarray) -> None:
    """``polish_settle_all_of`` with the steps of parallel pitch axes (``newton_parallel``)."""
    wide_vectors()
    polish_settle_all_of(m, pr, ch, c, True)


@numba.njit(cache=True, nogil=True)
def polish_settle(m: int, pr: Floats, ch: Floats, c: np.ndarray, ldl: bool | None) -> None:
    """``polish_settle_all_parallel`` where the pitch axes are parallel (``ldl`` None), else
    ``polish_settle_all`` (``ldl`` True). numba prunes the ``is None`` branch when it compiles:
    only the one an arm needs is compiled."""
    if ldl is None:
        polish_settle_all_parallel(m, pr, ch, c)
    else:
        polish_settle_all(m, pr, ch, c)


@numba.njit(cache=True, nogil=True, inline="always", fastmath=FAST)
def polish_settle_all_of(m: int, pr: Floats, ch: Floats, c: np.ndarray, parallel: bool) -> None:
    """The polish (``polish_twice``) of the m candidates in the rows c (flat: row k is c[k *
    CANDIDATE_WIDTH:];
    a model only close to the family), the error before its last step, the angles wrapped into
    the limits, and the verdict (``verdict``) at the final angles, whose sines and cosines
    follow from the polish's by what the limits snapped (``turn``): only where every step
    and snap is within BLOCK_TAYLOR_STEP is a candidate taken, within BLOCK_FAR_STEP found not to
    be a
    branch; the others, and an ill-conditioned polish, are left to the second polish.
    parallel: a constant (``newton_step``)."""
    for i in range(m):
        t = column_of(c, CANDIDATE_WIDTH, 0, i)
        sines, cosines = offsets(
            ch, column_of5(c, CANDIDATE.sines, i), column_of5(c, CANDIDATE.cosines, i)
        )
        q, sn, cs, ratio, size, big = polish_twice(ch, t, angles_of(c, i), sines, cosines, parallel)
        w0, w1, w2, w3, w4, inside = wrapped(pr, q)
        moved = snapped_any(pr, q, (w0, w1, w2, w3, w4))
        r0, r1, r2 = snapped(q[0], w0), snapped(q[1], w1), snapped(q[2], w2)
        r3, r4 = snapped(q[3], w3), snapped(q[4], w4)
        s0, c0 = turn(sn[0], cs[0], r0)
        s1, c1 = turn(sn[1], cs[1], r1)
        s2, c2 = turn(sn[2], cs[2], r2)
        s3, c3 = turn(sn[3], cs[3], r3)
        s4, c4 = turn(sn[4], cs[4], r4)
        p = fk_turned(ch, (s0, s1, s2, s3, s4), (c0, c1, c2, c3, c4))
        big = max(big, abs(r0), abs(r1), abs(r2), abs(r3), abs(r4))
        err, angle, good, far = verdict(t, p, size, c[CANDIDATE.fold * CANDIDATE_WIDTH + i])
        good = good if big <= BLOCK_TAYLOR_STEP else 0.0
        far = far if big <= BLOCK_FAR_STEP else 0.0
        put_angles(c, i, w0, w1, w2, w3, w4)
        c[CANDIDATE.previous_error * CANDIDATE_WIDTH + i] = size
        c[CANDIDATE.taken * CANDIDATE_WIDTH + i] = good
        fall = (ratio < BLOCK_ILL_CONDITIONED) | ((good == 0.0) & ((far == 0.0) | moved))
        c[CANDIDATE.fallback * CANDIDATE_WIDTH + i] = 1.0 if fall else 0.0
        c[CANDIDATE.within * CANDIDATE_WIDTH + i] = inside
        c[CANDIDATE.position_error * CANDIDATE_WIDTH + i] = err
        c[CANDIDATE.orientation_error * CANDIDATE_WIDTH + i] = angle


@numba.njit(cache=True, nogil=True)
def repolish(
    m: int,
    pr: Floats,
    ch: Floats,
    c_flat: np.ndarray,
    c2_flat: np.ndarray,
    index: np.ndarray,
    ldl: bool | None,
) -> None:
    """The m candidates in the rows c_flat that the polish left unfinished next to a branch
    (final errors below BLOCK_NOT_A_BRANCH: next to a fold of the elbow the steps converge
    slowly) polished once more from where they stopped, gathered into the rows c2_flat (whole
    vectors): those that reach VECTOR_EXACT are taken, the others stay with the scalar polish
    (from their closed-form start). ldl: the Newton step, as in ``polish_settle``."""
    c, c2 = (
        c_flat.reshape((CANDIDATE.rows, CANDIDATE_WIDTH)),
        c2_flat.reshape((CANDIDATE.rows, CANDIDATE_WIDTH)),
    )
    count = 0
    for k in range(m):
        if (c[CANDIDATE.fallback, k] != 0.0) & (
            max(c[CANDIDATE.position_error, k], c[CANDIDATE.orientation_error, k])
            <= BLOCK_NOT_A_BRANCH
        ):
            index[count] = k
            count += 1
    if count == 0:
        return
    lanes = min((count + LANES - 1) // LANES * LANES, CANDIDATE_WIDTH)
    for j in range(lanes):
        k = index[min(j, count - 1)]
        for row in range(CANDIDATE.rows):
            c2[row, j] = c[row, k]
        for row in range(5):  # the sines and cosines where the first polish stopped
            c2[CANDIDATE.sines + row, j], c2[CANDIDATE.cosines + row, j] = sincos(
                c2[CANDIDATE.q + row, j]
            )
    polish_settle(lanes, pr, ch, c2_flat, ldl)
    for j in range(count):
        if c2[CANDIDATE.taken, j] == 0.0:
            continue
        k = index[j]
        for row in (
            CANDIDATE.q,
            CANDIDATE.q + 1,
            CANDIDATE.q + 2,
            CANDIDATE.q + 3,
            CANDIDATE.q + 4,
            CANDIDATE.within,
            CANDIDATE.position_error,
            CANDIDATE.orientation_error,
        ):
            c[row, k] = c2[row, j]
        c[CANDIDATE.taken, k], c[CANDIDATE.fallback, k] = 1.0, 0.0
