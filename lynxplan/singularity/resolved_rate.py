"""Resolved-rate Cartesian motion along a path, four ways of handling singularities (SPEC Part 5).

The reference is a path of task coordinates ``x = (x, y, z, pitch)`` (tool point in [m], approach
pitch ``q2 + q3 + q4`` in [rad]), sampled at uniform path parameter ``s`` in [0, 1] (two samples
for a straight line) and timed by an LSPB law ``s(t)`` of duration ``duration`` with blends
``blend``, then held at its end for ``hold`` seconds. Each step of ``dt`` commands the task rate
``xdot_c = xdot_ref + gain (x_ref - x(q))`` (closed loop, so a strategy that leaves the path comes
back to it) and integrates ``q += qdot dt``:

1. ``pinv``: ``qdot = J^+ xdot_c`` with ``J^+ = J^T (J J^T)^-1`` (baseline; blows up).
2. ``speed_limit``: the report's solution 1; the reference clock advances at ``sigma <= 1`` chosen
   each step so that ``J^+ (sigma xdot_ref + gain e)`` respects every joint-speed limit: the tool
   slows down and the path takes longer.
3. ``dls``: damped least squares solved in the 5x5 form ``(J^T J + lambda^2 I) qdot = J^T xdot_c``
   with ``lambda^2 = lambda_min^2 + lambda_max^2 (1 - m/m_dls)^2`` for ``m < m_dls``.
4. ``tr``: the report's task reconstruction, with ``d = (dm/dq J^+)^T``, ``n = d/|d|`` and
   ``xdot_p = (I - 1/2 (1 - sign(xdot_c . n)) k1(m) n n^T) xdot_c + k2(m) n``,
   ``qdot = J^+ xdot_p``;
   ``k1`` = 1 for m <= m_bar, ``2u^3 - 3u^2 + 1`` with ``u = (m - m_bar)/sigma`` on
   (m_bar, m_bar + sigma), 0 above; ``k2 = k_r (m_bar - m)`` for m <= m_bar, else 0. SPEC writes it
   for a displacement ``dr``; it is applied here to the commanded rate (``dr / dt``), so ``k_r`` is
   in task units per second per unit of m and the result does not depend on ``dt``.

The loop runs in numba (closed-form kernels); :func:`run_reference` is the same algorithm in plain
Python/numpy with Pinocchio's Jacobian and Jacobian time variation, used to cross-check the kernel
and as the bench baseline.
"""

from __future__ import annotations

import numpy as np

from lynxplan import guards
from lynxplan.exceptions import InputError
from lynxplan.singularity.rate_kernel import (
    RateOutputs,
    RatePath,
    RateSettings,
    RateTask,
    k1_kernel,
    k2_kernel,
    lspb_kernel,
    path_sample_kernel,
    resolved_rate_kernel,
)
from lynxplan.singularity.rate_metrics import RunMetrics, run_metrics
from lynxplan.singularity.rate_problem import (
    PATH_ROWS,
    STRATEGY_NAMES,
    PathReference,
    ResolvedRateProblem,
    ResolvedRateRun,
    Strategy,
    TrParameters,
    parse_strategy,
)
from lynxplan.singularity.rate_reference import run_reference

__all__ = [
    "PATH_ROWS",
    "STRATEGY_NAMES",
    "PathReference",
    "RateOutputs",
    "RatePath",
    "RateSettings",
    "RateTask",
    "ResolvedRateProblem",
    "ResolvedRateRun",
    "RunMetrics",
    "Strategy",
    "TrParameters",
    "k1_kernel",
    "k2_kernel",
    "lspb_kernel",
    "parse_strategy",
    "path_sample_kernel",
    "resolved_rate_kernel",
    "run_all",
    "run_metrics",
    "run_reference",
    "run_resolved_rate",
]


def run_resolved_rate(
    problem: ResolvedRateProblem, strategy: str | Strategy, *, max_steps: int | None = None
) -> ResolvedRateRun:
    """Run one strategy along the problem's path (numba kernel).

    Args:
        problem: Path, start, task, parameters.
        strategy: ``"pinv"``, ``"speed_limit"``, ``"dls"`` or ``"tr"``.
        max_steps: Stop after this many steps (default: the problem's budget).
    """
    chosen = parse_strategy(strategy)
    steps = problem.max_steps if max_steps is None else int(max_steps)
    if steps < 1:
        raise InputError(f"max_steps must be >= 1. Got: {steps}")
    # Per step: t, m, q (5), qd (5), task error and reference (about 20 floats).
    guards.check_size(f"resolved-rate steps (path time / dt = {problem.dt:.3g} s)", steps, 160.0)
    out = RateOutputs.empty(steps)
    g, path = problem.geometry, problem.path
    m_bar, sigma, k_r, lambda_min, lambda_max, m_dls = problem.parameters.as_array().tolist()
    settings = RateSettings(
        int(chosen),
        float(problem.dt),
        float(problem.gain),
        np.array(problem.velocity_limits),
        m_bar,
        sigma,
        k_r,
        lambda_min,
        lambda_max,
        m_dls,
    )
    count = resolved_rate_kernel(
        np.array(problem.q0),
        (float(g.a2), float(g.a3), float(g.d5)),
        RateTask(problem.task.rows_array, problem.columns),
        RatePath(
            np.ascontiguousarray(path.points),
            float(path.duration),
            float(path.blend),
            float(path.hold),
        ),
        settings,
        out,
    )
    return ResolvedRateRun(chosen, problem.task, *(array[:count] for array in out))


def run_all(problem: ResolvedRateProblem) -> dict[Strategy, ResolvedRateRun]:
    """Every strategy on the same problem, in :class:`Strategy` order."""
    return {strategy: run_resolved_rate(problem, strategy) for strategy in Strategy}
