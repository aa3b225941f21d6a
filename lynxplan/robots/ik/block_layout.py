"""The vectorised full-pose solver's data layout (``pose_block``): block sizes, the scratch
rows (named records of row indices), the accessors that move a pose or a candidate between the
rows and registers, and the chain and link shape in the form the kernels read.

A block of :data:`BLOCK` poses is transposed into the pose rows (one row per quantity, one
column per pose: :data:`POSE`, each flip's rows :data:`FLIP`) and its candidate branches into
the candidate rows (:data:`CANDIDATE`, :data:`CANDIDATE_WIDTH` lanes), so that one loop without
branches or calls solves a quantity for the whole block (vector instructions). The rows live
in one flat array at constant distances, so LLVM needs no aliasing checks.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numba
import numpy as np
from numba.np.unsafe.ndarray import to_fixed_tuple

from lynxplan import _fastmath
from lynxplan._fastmath import wide_vectors
from lynxplan.robots import family as F  # noqa: N812
from lynxplan.robots.ik.family_geometry import two_link_shape

FAST = {"contract", "arcp"}  # fused multiply-adds, reciprocals: as in ``arm.ik_kernel``
#: Floats in registers: a pose (12, row-major 3 x 4), a Jacobian column (6), the parameters.
Floats = tuple[float, ...]
#: The sine and cosine of an angle.
SinCos = tuple[float, float]
#: One flip (``flip_geometry``): its geometry (12, where ``flip_branches`` finds the angles),
#: candidate, fallback, side, near a fold.
FlipBranches = tuple[Floats, bool, bool, float, bool]
#: One flip's branches (``flip_branches``): q of elbow up, q of elbow down, the sines and
#: cosines of elbow up's q, those of elbow down's (5 each).
Branches = tuple[Floats, Floats, Floats, Floats, Floats, Floats]
# The branch-free sine/cosine and arctangent, inlined by LLVM rather than by numba: numba's own
# inlining (``inline="always"``) of their ~40 call sites would multiply the compile time by 5.
# (Their Python functions: ``py_func``, or the functions themselves under numba's debugging
# switch NUMBA_DISABLE_JIT, where a jitted function is the Python function.)
sincos: Callable[[float], tuple[float, float]] = numba.njit(nogil=True, fastmath=FAST)(
    getattr(_fastmath.sincos, "py_func", _fastmath.sincos)
)
atan2: Callable[[float, float], float] = numba.njit(nogil=True, fastmath=FAST)(
    getattr(_fastmath.atan2, "py_func", _fastmath.atan2)
)
#: Poses per block (a constant width: the scratch rows never alias).
BLOCK = 32
#: The candidate loops run on a multiple of this many lanes (AVX-512: 8 doubles).
LANES = 8
#: The base, four joint-to-joint links, the tool (``chain_tuple``).
CHAIN_SIZE = 12 + 4 * 6 + 12


class FlipRows(NamedTuple):
    """One flip's pose rows, from its first (``flip_geometry``'s results)."""

    geometry: int = 0
    """12 rows: where ``flip_branches`` finds the angles."""
    wrist_x: int = 9
    """The shoulder-to-wrist vector's outward component (a geometry row) [m]."""
    candidate: int = 12
    """1/0: the flip is a candidate."""
    fallback: int = 13
    """1/0: the pose goes to the scalar solver."""
    side: int = 14
    """The side of the lateral offset whose yaw matches (0/1)."""
    fold: int = 15
    """1/0: near a fold of the elbow."""
    rows: int = 16
    """Rows per flip."""


class PoseRows(NamedTuple):
    """The pose rows of a block (one column per pose)."""

    target: int = 0
    """12 rows: the target, row-major 3 x 4."""
    flips: int = 12
    """Flip 0's rows (:class:`FlipRows`), then flip 1's."""
    fallback: int = 12 + 2 * 16
    """1/0: the whole pose goes to the scalar solver."""
    other: int = 12 + 2 * 16 + 1
    """1 + the flip computed where the other is left for ``other_flip`` (0: none)."""
    rows: int = 12 + 2 * 16 + 2
    """Rows."""


class CandidateRows(NamedTuple):
    """The candidate rows (up to 4 lanes per pose of a block)."""

    target: int = 0
    """12 rows: the candidate's target."""
    q: int = 12
    """5 rows: the angles [rad]."""
    fold: int = 17
    """1/0: near a fold of the elbow."""
    previous_error: int = 18
    """The error before the polish's last step."""
    taken: int = 19
    """1/0: an exact branch."""
    fallback: int = 20
    """1/0: finished by the scalar polish."""
    within: int = 21
    """1/0: within the joint limits."""
    position_error: int = 22
    """[m]."""
    orientation_error: int = 23
    """[rad]."""
    start: int = 24
    """5 rows: the closed-form q, where a candidate that falls back starts."""
    sines: int = 29
    """5 rows: the sines of q where the polish starts."""
    cosines: int = 34
    """5 rows: their cosines."""
    rows: int = 39
    """Rows."""


FLIP = FlipRows()
POSE = PoseRows()
CANDIDATE = CandidateRows()
#: The candidate rows' width (lanes).
CANDIDATE_WIDTH = 4 * BLOCK
#: Every slot of a pose taken (``is_duplicate``'s mask).
ALL_TAKEN = np.ones(4, dtype=np.bool_)


@numba.njit(cache=True, nogil=True, inline="always")
def put_flip(x: np.ndarray, i: int, flip: int, branches: FlipBranches) -> None:
    """One flip of pose i (``flip_geometry``) into the scratch rows x (``closed_forms``)."""
    geometry, cand, fall, side, fold = branches
    base = (POSE.flips + flip * FLIP.rows) * BLOCK + i
    x[base], x[base + BLOCK], x[base + 2 * BLOCK] = geometry[0], geometry[1], geometry[2]
    x[base + 3 * BLOCK], x[base + 4 * BLOCK] = geometry[3], geometry[4]
    x[base + 5 * BLOCK], x[base + 6 * BLOCK] = geometry[5], geometry[6]
    x[base + 7 * BLOCK], x[base + 8 * BLOCK] = geometry[7], geometry[8]
    x[base + 9 * BLOCK], x[base + 10 * BLOCK] = geometry[9], geometry[10]
    x[base + 11 * BLOCK] = geometry[11]
    x[base + FLIP.candidate * BLOCK] = 1.0 if cand else 0.0
    x[base + FLIP.fallback * BLOCK] = 1.0 if fall else 0.0
    x[base + FLIP.side * BLOCK] = side
    x[base + FLIP.fold * BLOCK] = 1.0 if fold else 0.0


@numba.njit(cache=True, nogil=True, inline="always")
def put_candidate(
    x: np.ndarray, lane: int, t: Floats, q: Floats, sines: Floats, cosines: Floats, fold: bool
) -> None:
    """A candidate of target t (12) at angles q (5) of these sines and cosines into lane
    ``lane`` of the candidate rows of x (``closed_forms``), its flags cleared (written out:
    a loop here would keep the caller's loop from vectorising)."""
    b = POSE.rows * BLOCK + lane
    x[b], x[b + CANDIDATE_WIDTH], x[b + 2 * CANDIDATE_WIDTH], x[b + 3 * CANDIDATE_WIDTH] = (
        t[0],
        t[1],
        t[2],
        t[3],
    )
    (
        x[b + 4 * CANDIDATE_WIDTH],
        x[b + 5 * CANDIDATE_WIDTH],
        x[b + 6 * CANDIDATE_WIDTH],
        x[b + 7 * CANDIDATE_WIDTH],
    ) = t[4], t[5], t[6], t[7]
    (
        x[b + 8 * CANDIDATE_WIDTH],
        x[b + 9 * CANDIDATE_WIDTH],
        x[b + 10 * CANDIDATE_WIDTH],
        x[b + 11 * CANDIDATE_WIDTH],
    ) = t[8], t[9], t[10], t[11]
    put5(x, b + CANDIDATE.q * CANDIDATE_WIDTH, q)
    put5(x, b + CANDIDATE.start * CANDIDATE_WIDTH, q)
    put5(x, b + CANDIDATE.sines * CANDIDATE_WIDTH, sines)
    put5(x, b + CANDIDATE.cosines * CANDIDATE_WIDTH, cosines)
    x[b + CANDIDATE.fold * CANDIDATE_WIDTH] = 1.0 if fold else 0.0
    x[b + CANDIDATE.fallback * CANDIDATE_WIDTH] = 0.0
    x[b + CANDIDATE.previous_error * CANDIDATE_WIDTH] = 0.0


@numba.njit(cache=True, nogil=True, inline="always")
def put5(x: np.ndarray, b: int, v: Floats) -> None:
    """v (5) into x[b + k * CANDIDATE_WIDTH], k = 0..4 (five candidate rows)."""
    (
        x[b],
        x[b + CANDIDATE_WIDTH],
        x[b + 2 * CANDIDATE_WIDTH],
        x[b + 3 * CANDIDATE_WIDTH],
        x[b + 4 * CANDIDATE_WIDTH],
    ) = v[0], v[1], v[2], v[3], v[4]


@numba.njit(cache=True, nogil=True, inline="always")
def column_of(rows: np.ndarray, width: int, first: int, i: int) -> Floats:
    """The 12 values rows[(first + k) * width + i], k = 0..11 (a target, row-major 3 x 4)."""
    b = first * width + i
    return (
        rows[b], rows[b + width], rows[b + 2 * width], rows[b + 3 * width],
        rows[b + 4 * width], rows[b + 5 * width], rows[b + 6 * width], rows[b + 7 * width],
        rows[b + 8 * width], rows[b + 9 * width], rows[b + 10 * width], rows[b + 11 * width],
    )  # fmt: skip


@numba.njit(cache=True, nogil=True, inline="always")
def column_of5(c: np.ndarray, first: int, i: int) -> Floats:
    """The 5 values c[(first + k) * CANDIDATE_WIDTH + i], k = 0..4, of the candidate rows c."""
    b = first * CANDIDATE_WIDTH + i
    return (
        c[b],
        c[b + CANDIDATE_WIDTH],
        c[b + 2 * CANDIDATE_WIDTH],
        c[b + 3 * CANDIDATE_WIDTH],
        c[b + 4 * CANDIDATE_WIDTH],
    )


@numba.njit(cache=True, nogil=True, inline="always")
def angles_of(c: np.ndarray, i: int) -> Floats:
    """Candidate i's five angles from the candidate rows c."""
    b = CANDIDATE.q * CANDIDATE_WIDTH + i
    return (
        c[b],
        c[b + CANDIDATE_WIDTH],
        c[b + 2 * CANDIDATE_WIDTH],
        c[b + 3 * CANDIDATE_WIDTH],
        c[b + 4 * CANDIDATE_WIDTH],
    )


@numba.njit(cache=True, nogil=True, inline="always")
def put_angles(
    c: np.ndarray, i: int, q0: float, q1: float, q2: float, q3: float, q4: float
) -> None:
    """Candidate i's five angles into the candidate rows c."""
    b = CANDIDATE.q * CANDIDATE_WIDTH + i
    (
        c[b],
        c[b + CANDIDATE_WIDTH],
        c[b + 2 * CANDIDATE_WIDTH],
        c[b + 3 * CANDIDATE_WIDTH],
        c[b + 4 * CANDIDATE_WIDTH],
    ) = q0, q1, q2, q3, q4


@numba.njit(cache=True, nogil=True)
def clear_slots(
    first: int,
    last: int,
    q: np.ndarray,
    valid: np.ndarray,
    within: np.ndarray,
    position_error: np.ndarray,
    orientation_error: np.ndarray,
) -> None:
    """Slots first..last - 1 of the flat outputs (q: 5 values a slot) empty: NaN / False (one
    contiguous run each, in whole vectors: unsigned indices, which numba does not wrap around,
    so LLVM sees consecutive addresses rather than scattering the stores)."""
    wide_vectors()
    begin, end = np.uint64(first), np.uint64(last)
    for k in range(np.uint64(5) * begin, np.uint64(5) * end):
        q[k] = np.nan
    for k in range(begin, end):
        valid[k] = False
    for k in range(begin, end):
        within[k] = False
    for k in range(begin, end):
        position_error[k] = np.nan
    for k in range(begin, end):
        orientation_error[k] = np.nan


@numba.njit(cache=True, nogil=True)
def chain_tuple(placements: np.ndarray, axes: np.ndarray) -> Floats:
    """The chain in frames that make each link between two joints sparse, as one tuple: the
    base block N_1 (3 x 4, row-major, below), four links (6 each, ``joint_turned``), the tool block
    (3 x 4); placements (6, 4, 4), axes (5, 3).

    T(q) = M_1 R(u_1, q_1) M_2 ... R(u_5, q_5) M_tool with G_i = [A_i | lambda_i u_i] a frame on
    joint i's axis (A_i takes z to u_i) and R(u_i, q) = G_i R(z, q) G_i^-1:
    T(q) = N_1 R(z, q_1) N_2 ... R(z, q_5) N_tool, N_1 = M_1 G_1, N_i = G_{i-1}^-1 M_i G_i,
    N_tool = G_5^-1 M_tool. Frame i's x axis is normal to both joint axes i - 1 and i (any
    normal to u_i where they are parallel) and frame 1's is frame 2's, so N_i's rotation is
    R(z, phi_i) R(x, beta_i) (phi_2 = 0); lambda_i puts frame i's origin where N_{i+1} has no
    translation along z (back from the tool). The same poses to rounding: the fourth entries
    (N_i's z-x rotation entry and z translation) are rounding, left out.
    """
    frames = np.zeros((5, 4, 4))
    xs = np.zeros((5, 3))
    for k in range(4, -1, -1):
        u = axes[k].copy()
        w = np.zeros(3)
        if k >= 1:  # normal to u and to the axis before it (in joint k's frame)
            v = np.ascontiguousarray(placements[k, :3, :3]).T @ axes[k - 1]
            w = v - (v @ u) * u
        if k >= 1 and w @ w > 1e-300:
            x = np.cross(u, w)
        elif k == 0:  # frame 2's x axis in joint 1's frame: phi_2 = 0
            x = np.ascontiguousarray(placements[1, :3, :3]) @ xs[1]
        else:  # parallel: any normal
            a = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
            x = a - (a @ u) * u
        x = x - (x @ u) * u
        x /= math.sqrt(x @ x)
        xs[k] = x
        frames[k, :3, 0], frames[k, :3, 1], frames[k, :3, 2] = x, np.cross(u, x), u
        frames[k, 3, 3] = 1.0
    # lambda: back from the tool, each frame's origin where the next link has no z translation
    lam = np.zeros(5)
    lam[4] = axes[4] @ np.ascontiguousarray(placements[5, :3, 3])
    for k in range(3, -1, -1):
        m = placements[k + 1]
        lam[k] = axes[k] @ (np.ascontiguousarray(m[:3, :3]) @ (lam[k + 1] * axes[k + 1]) + m[:3, 3])
    for k in range(5):
        frames[k, :3, 3] = lam[k] * axes[k]
    inverse = np.zeros((5, 4, 4))
    for k in range(5):
        r = frames[k, :3, :3].T.copy()
        inverse[k, :3, :3] = r
        inverse[k, :3, 3] = -(r @ np.ascontiguousarray(frames[k, :3, 3]))
        inverse[k, 3, 3] = 1.0
    flat = np.empty(CHAIN_SIZE)
    base = np.ascontiguousarray(placements[0]) @ frames[0]
    tool = inverse[4] @ np.ascontiguousarray(placements[5])
    for r in range(3):
        for col in range(4):
            flat[4 * r + col] = base[r, col]
            flat[36 + 4 * r + col] = tool[r, col]
    for k in range(1, 5):
        link = inverse[k - 1] @ np.ascontiguousarray(placements[k]) @ frames[k]
        cf, sf = link[0, 0], link[1, 0]
        b = 12 + 6 * (k - 1)
        flat[b], flat[b + 1] = cf, sf
        flat[b + 2], flat[b + 3] = link[2, 2], link[2, 1]
        # the translation in the frame turned by phi: R(z, -phi) (tx, ty)
        tx, ty = link[0, 3], link[1, 3]
        flat[b + 4], flat[b + 5] = cf * tx + sf * ty, cf * ty - sf * tx
    chain: Floats = to_fixed_tuple(flat, CHAIN_SIZE)  # type: ignore[call-arg]
    return chain


@numba.njit(cache=True, nogil=True)
def link_shape(prm: np.ndarray) -> Floats:
    """The two links' shape (``flip_geometry``) from the packed parameters: their lengths la, lb
    [m],
    their angles b2, b3 [rad], sin, cos of gamma0 and gamma0, sin and cos of b2 and of
    b2 - b3."""
    la, lb, b2, b3 = two_link_shape(prm)
    gamma0 = prm[F.GAMMA0]
    return (
        la,
        lb,
        b2,
        b3,
        math.sin(gamma0),
        math.cos(gamma0),
        gamma0,
        math.sin(b2),
        math.cos(b2),
        math.sin(b2 - b3),
        math.cos(b2 - b3),
    )
