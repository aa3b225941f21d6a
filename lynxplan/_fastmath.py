"""Branch-light sine/cosine and arctangent for the numba kernels.

libm's ``sin``, ``cos`` and ``atan2`` are opaque calls that numba cannot inline or fuse; these
versions (Cephes' range reductions and minimax polynomials, S. L. Moshier, "Methods and Programs
for Mathematical Functions", 1989) inline into the kernels, compute sine and cosine with one
range reduction, and stay within a few units in the last place of libm for the argument ranges
of joint angles (|x| < 1e6). The tests compare them with ``math`` over millions of arguments.

The only LLVM-level code of lynxplan is here too: :func:`wide_vectors` (an llvmlite function
attribute) and :func:`prefetch` / :func:`prefetch_write` (the ``llvm.prefetch`` intrinsic), used
by ``robots/ik/pose_block``. They stay because together they pay on a whole user call (issue 36:
at least 10 %): ``Robot.ik_batch`` of 10^5 SO-101 full poses, alternating processes on the same
2-core AVX-512 machine, median of the per-process medians of 7 calls: 39.2 ms without either,
33.9 ms with both (16 % more poses per second; 10 earlier alternating pairs: 40.8 against
33.1 ms); 36.5 ms with only the wide vectors, 36.2 ms with only the prefetches. The answers are
bit-identical with and without them. Checked with numba 0.61.2 / llvmlite 0.44 (LLVM 15,
typed pointers: LLVM renames ``llvm.prefetch.p0`` to ``llvm.prefetch.p0i8``) and 0.68.1 / 0.50.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, cast

import numba
import numba.extending
from llvmlite import ir
from numba.core import cgutils

# Cody-Waite split of pi/4 (Cephes DP1..DP3) and the sin/cos minimax polynomials on [0, pi/4].
_DP1 = 7.85398125648498535156e-1
_DP2 = 3.77489470793079817668e-8
_DP3 = 2.69515142907905952645e-15
_FOUR_OVER_PI = 1.27323954473516268615
_S0, _S1, _S2 = 1.58962301576546568060e-10, -2.50507477628578072866e-8, 2.75573136213857245213e-6
_S3, _S4, _S5 = -1.98412698295895385996e-4, 8.33333333332211858878e-3, -1.66666666666666307295e-1
_C0, _C1, _C2 = -1.13585365213876817300e-11, 2.08757008419747316778e-9, -2.75573141792967388112e-7
_C3, _C4, _C5 = 2.48015872888517045348e-5, -1.38888888888730564116e-3, 4.16666666666665929218e-2

# atan: rational approximation on [0, 0.66] after the reductions at tan(3 pi/8) and 0.66.
_P0, _P1, _P2 = -8.750608600031904122785e-1, -1.615753718733365076637e1, -7.500855792314704667340e1
_P3, _P4 = -1.228866684490136173410e2, -6.485021904942025371773e1
_Q0, _Q1, _Q2 = 2.485846490142306297962e1, 1.650270098316988542046e2, 4.328810604912902668951e2
_Q3, _Q4 = 4.853903996359136964868e2, 1.945506571482613964425e2
_T3P8 = 2.41421356237309504880
_MOREBITS = 6.123233995736765886130e-17


@numba.njit(cache=True, nogil=True, inline="always")
def sincos(x: float) -> tuple[float, float]:
    """(sin x, cos x) with one range reduction. x in [rad].

    Branch-free: the octant picks the polynomials and signs by selects, so random angles cost
    no mispredicted branches (they cost more than the polynomials)."""
    ax = abs(x)
    j = int(ax * _FOUR_OVER_PI)
    j += j & 1  # map zeros to the origin
    y = float(j)
    z = ((ax - y * _DP1) - y * _DP2) - y * _DP3
    zz = z * z
    s = z + z * zz * (((((_S0 * zz + _S1) * zz + _S2) * zz + _S3) * zz + _S4) * zz + _S5)
    c = (
        1.0
        - 0.5 * zz
        + zz * zz * (((((_C0 * zz + _C1) * zz + _C2) * zz + _C3) * zz + _C4) * zz + _C5)
    )
    # octant j in {0, 2, 4, 6} (mod 8): (s, c), (c, -s), (-s, -c), (-c, s)
    swap = (j & 2) != 0
    sign_s = 1.0 - 2.0 * float((j >> 2) & 1)
    sign_c = 1.0 - 2.0 * float(((j >> 2) ^ (j >> 1)) & 1)
    sine = c if swap else s
    cosine = s if swap else c
    return math.copysign(1.0, x) * sign_s * sine, sign_c * cosine


@numba.njit(cache=True, nogil=True, inline="always")
def _atan_unit(t: float) -> float:
    """atan(t) for 0 <= t <= 1 (the reduction at 0.66 by selects, no branch)."""
    big = t > 0.66
    x = (t - 1.0 if big else t) / (t + 1.0 if big else 1.0)
    z = x * x
    p = (((_P0 * z + _P1) * z + _P2) * z + _P3) * z + _P4
    q = ((((z + _Q0) * z + _Q1) * z + _Q2) * z + _Q3) * z + _Q4
    y, extra = (0.25 * math.pi, 0.5 * _MOREBITS) if big else (0.0, 0.0)
    return y + (x * z * p / q + x + extra)


@numba.njit(cache=True, nogil=True, inline="always")
def atan2(y: float, x: float) -> float:
    """Angle of the vector (x, y) in (-pi, pi], in [rad] (math.atan2 conventions for +-0).

    The octant is applied by selects, and so is the origin: no branch, so loops over arrays
    of vectors vectorise (in a caller compiled with ``error_model="numpy"``, whose divisions
    have no zero test)."""
    ay = abs(y)
    ax = abs(x)
    steep = ay > ax
    big = ay if steep else ax
    a = _atan_unit((ax if steep else ay) / (big if big > 0.0 else 1.0))
    a = 0.5 * math.pi - a if steep else a
    a = math.pi - a if x < 0.0 else a
    general = math.copysign(a, y)
    origin = math.copysign(math.pi, y) if math.copysign(1.0, x) < 0.0 else y
    return origin if (x == 0.0) & (y == 0.0) else general


#: The LLVM function attribute that lets the vectoriser use whole 512-bit registers where the CPU
#: has them: LLVM's tuning for recent Intel cores prefers 256-bit vectors (a lower clock was once
#: the price of 512-bit ones), which halves the lanes of the kernels' long loops without a
#: branch. Where the CPU has no AVX-512 it changes nothing.
_WIDE = '"prefer-vector-width"="512"'


@numba.extending.intrinsic
def _wide_vectors(typingctx: object) -> tuple[object, object]:
    """Call at the top of a kernel whose loops vectorise: its loops may use 512-bit vectors
    (``_WIDE``; the attribute is set on the compiled function, no code is emitted)."""

    def codegen(context: Any, builder: Any, signature: object, args: object) -> Any:
        # llvmlite's attribute set knows only the keyword attributes: the string attribute is
        # added to the set itself, which llvmlite writes out as given. Should a later llvmlite
        # store its attributes otherwise, the kernel compiles as before (LLVM's own width).
        attributes = builder.function.attributes
        if isinstance(attributes, set):
            set.add(attributes, _WIDE)
        return context.get_dummy_value()

    return numba.types.none(), codegen


#: Typed for callers: the intrinsic takes no argument in a kernel (numba passes ``typingctx``).
wide_vectors = cast("Callable[[], None]", _wide_vectors)


def _prefetcher(write: int) -> Any:
    """An intrinsic ``(array, index)``: LLVM's prefetch of the cache line of element ``index``
    of a C-contiguous array (its flat index; no bounds check: a prefetch never faults), for a
    read (write 0) or a write (1). No other effect: the kernels start the memory traffic of
    the next block of poses while they compute one."""

    @numba.extending.intrinsic
    def _prefetch(typingctx: object, array: Any, index: Any) -> tuple[object, object]:
        def codegen(context: Any, builder: Any, signature: Any, args: Any) -> Any:
            data = context.make_array(signature.args[0])(context, builder, args[0]).data
            byte = ir.IntType(8).as_pointer()
            address = builder.bitcast(builder.gep(data, [args[1]]), byte)
            word = ir.IntType(32)
            function = cgutils.get_or_insert_function(  # type: ignore[no-untyped-call]
                builder.module,
                ir.FunctionType(ir.VoidType(), [byte, word, word, word]),
                "llvm.prefetch.p0",
            )
            # (address, write, locality 3: keep in every cache level, data cache)
            builder.call(function, [address, word(write), word(3), word(1)])
            return context.get_dummy_value()

        return numba.types.none(array, numba.types.intp), codegen

    return _prefetch


#: Typed for callers: ``prefetch(array, index)`` before reading, ``prefetch_write`` before
#: writing (the line is fetched for ownership).
prefetch = cast("Callable[[Any, int], None]", _prefetcher(0))
prefetch_write = cast("Callable[[Any, int], None]", _prefetcher(1))
