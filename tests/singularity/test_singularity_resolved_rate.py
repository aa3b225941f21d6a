"""Resolved-rate strategies on the shipped singular line, TR shape functions, error paths."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from lynxplan.arm import Arm
from lynxplan.exceptions import (
    InputError,
    ShapeError,
    SingularityParameterError,
    TaskError,
)
from lynxplan.scenarios import load_scenario
from lynxplan.scenarios.singularity import build_problem
from lynxplan.singularity.measures import manipulability, task_jacobian
from lynxplan.singularity.resolved_rate import (
    PathReference,
    RateOutputs,
    ResolvedRateProblem,
    ResolvedRateRun,
    Strategy,
    TrParameters,
    k1_kernel,
    k2_kernel,
    run_all,
    run_metrics,
    run_reference,
    run_resolved_rate,
)

SCENARIO = Path(__file__).resolve().parents[2] / "scenarios" / "singularity_line.yaml"
#: numba kernel (closed form) vs Python reference (Pinocchio): same arithmetic up to rounding,
#: amplified by the near-singular solves over a few hundred steps.
KERNEL_VS_REFERENCE_ATOL = 1e-9


@pytest.fixture(scope="module")
def problem() -> ResolvedRateProblem:
    scenario = load_scenario(SCENARIO).scenario
    return build_problem(scenario)  # type: ignore[arg-type]


@pytest.fixture(scope="module")
def runs(problem: ResolvedRateProblem) -> dict[Strategy, ResolvedRateRun]:
    return run_all(problem)


def test_shipped_line_passes_within_1mm_of_the_singular_set(
    arm: Arm, problem: ResolvedRateProblem
) -> None:
    points = problem.path.points
    s = np.linspace(0.0, 1.0, 20001)[:, None]
    xy = points[0, :2] + s * (points[-1, :2] - points[0, :2])
    assert np.min(np.linalg.norm(xy, axis=1)) <= 1e-3 + 1e-12
    # The pseudo-inverse run follows the line: its smallest m is that of the closest point.
    g = arm.geometry
    q = runs_pinv_closest(problem)
    assert manipulability(q, "position_pitch") == pytest.approx(
        1e-3 * g.a2 * g.a3 * abs(np.sin(q[2])), rel=0.05
    )


def runs_pinv_closest(problem: ResolvedRateProblem) -> np.ndarray:
    run = run_resolved_rate(problem, "pinv")
    return run.q[np.argmin(run.m)]


def test_pinv_blows_up_and_the_others_stay_within_speed_limits(
    arm: Arm, problem: ResolvedRateProblem, runs: dict[Strategy, ResolvedRateRun]
) -> None:
    metrics = {s: run_metrics(r, problem, arm.limits) for s, r in runs.items()}
    assert metrics[Strategy.PINV].speed_limit_exceeded
    assert metrics[Strategy.PINV].peak_speed_ratio > 3.0
    for strategy in (Strategy.SPEED_LIMIT, Strategy.DLS, Strategy.TR):
        assert not metrics[strategy].speed_limit_exceeded, strategy
        ratio = np.max(np.abs(runs[strategy].qd) / arm.limits.velocity)
        assert ratio <= 1.0 + 1e-9
    # Every strategy ends on the end point of the line.
    for strategy, run in runs.items():
        assert run.position_error[-1] < 1e-3, strategy


def test_speed_limit_tracks_the_line_and_takes_longer(
    arm: Arm, problem: ResolvedRateProblem, runs: dict[Strategy, ResolvedRateRun]
) -> None:
    m = run_metrics(runs[Strategy.SPEED_LIMIT], problem, arm.limits)
    assert m.max_tracking_error < 1e-4
    assert m.completion_time is not None
    assert m.completion_time > problem.path.duration + 0.1
    assert m.peak_speed_ratio == pytest.approx(1.0, abs=1e-9)


def test_tr_leaves_the_surface_and_returns_to_the_path(
    problem: ResolvedRateProblem, runs: dict[Strategy, ResolvedRateRun]
) -> None:
    run = runs[Strategy.TR]
    m_bar, sigma = problem.parameters.m_bar, problem.parameters.sigma
    error = run.position_error
    # It never goes deeper than a few percent below the surface m = m_bar ...
    assert run.m.min() > 0.95 * m_bar
    # ... slides along it (k1 ~ 1, within 10 % of m_bar) while far from the line ...
    on_surface = (run.k1 > 0.9) & (run.m < 1.1 * m_bar) & (error > 0.01)
    assert on_surface.sum() * problem.dt > 0.2
    last_on_surface = np.flatnonzero(on_surface)[-1]
    # ... then leaves it (k1 = 0: m above m_bar + sigma) and comes back to the line.
    after = slice(last_on_surface, None)
    assert np.any(run.m[after] > m_bar + sigma)
    assert error[-1] < 1e-4
    back = np.flatnonzero(error[after] < 1e-3)[0] + last_on_surface
    assert np.all(error[back:] < 1e-3)
    assert np.all(run.k1[back:] == 0.0)


def test_tr_escape_gain_pushes_out_of_the_singular_region(arm: Arm) -> None:
    # Start inside m < m_bar with a stationary reference: only k2 moves the arm.
    q0 = np.array([0.5, 1.6, -0.69, 2.2, 0.0])
    g = arm.geometry
    A = g.a2 + g.a3 * np.cos(q0[2]) + g.d5 * np.sin(q0[2] + q0[3])
    B = -g.a3 * np.sin(q0[2]) + g.d5 * np.cos(q0[2] + q0[3])
    q0[1] = np.arctan2(A, -B) + 0.002  # tool ~0.6 mm off the base axis
    T = arm.fk(q0)
    m0 = manipulability(q0, "position_pitch")
    point = [*T[:3, 3]]
    pitch = float(q0[1] + q0[2] + q0[3])
    path = PathReference.line(point, point, pitch, duration=1.0, blend=0.5, hold=1.0)
    params = TrParameters(m_bar=50 * m0, sigma=20 * m0, k_r=0.2 / m0)
    problem = ResolvedRateProblem(path, q0, "position_pitch", params, gain=0.0)
    tr = run_resolved_rate(problem, "tr")
    assert tr.m[-1] >= 0.95 * params.m_bar
    pinv = run_resolved_rate(problem, "pinv")
    np.testing.assert_allclose(pinv.q[-1], q0, atol=1e-12)


def test_a_run_holds_the_kernel_outputs_in_their_order() -> None:
    # Runs are built as ResolvedRateRun(strategy, task, *outputs): the two field lists must agree.
    assert ResolvedRateRun._fields[2:] == RateOutputs._fields


def test_k1_values_and_continuity() -> None:
    m_bar, sigma = 2.0, 0.5
    assert k1_kernel(0.0, m_bar, sigma) == 1.0
    assert k1_kernel(m_bar, m_bar, sigma) == 1.0
    assert k1_kernel(m_bar + sigma, m_bar, sigma) == 0.0
    assert k1_kernel(m_bar + 0.5 * sigma, m_bar, sigma) == pytest.approx(0.5, abs=1e-15)
    assert k1_kernel(m_bar + 0.25 * sigma, m_bar, sigma) == pytest.approx(
        2 * 0.25**3 - 3 * 0.25**2 + 1, abs=1e-15
    )
    assert k1_kernel(10.0, m_bar, sigma) == 0.0
    h = 1e-7
    for edge, value in ((m_bar, 1.0), (m_bar + sigma, 0.0)):
        below, above = k1_kernel(edge - h, m_bar, sigma), k1_kernel(edge + h, m_bar, sigma)
        # Continuous, with zero slope on both sides (C1): the change is O(h^2).
        assert abs(below - value) < 10 * h**2 / sigma**2
        assert abs(above - value) < 10 * h**2 / sigma**2
    u = np.linspace(0.0, 1.0, 1001)
    values = [k1_kernel(m_bar + x * sigma, m_bar, sigma) for x in u]
    assert np.all(np.diff(values) <= 0.0)


def test_k2_values() -> None:
    assert k2_kernel(1.0, 2.0, 3.0) == pytest.approx(3.0)
    assert k2_kernel(2.0, 2.0, 3.0) == 0.0
    assert k2_kernel(2.5, 2.0, 3.0) == 0.0


def test_kernel_matches_python_pinocchio_reference(arm: Arm, problem: ResolvedRateProblem) -> None:
    # A short stretch through the singular region exercises every branch of every strategy.
    q_mid = run_resolved_rate(problem, "pinv").q
    start = q_mid[np.argmin(np.abs(run_resolved_rate(problem, "pinv").t - 5.0))]
    line = PathReference.line(
        arm.fk(start)[:3, 3], [-0.03, 0.001, 0.38], np.pi, duration=1.0, blend=0.3
    )
    short = ResolvedRateProblem(line, start, "position_pitch", problem.parameters, gain=1.0)
    for strategy in Strategy:
        fast = run_resolved_rate(short, strategy, max_steps=400)
        slow = run_reference(short, strategy, arm, max_steps=400)
        np.testing.assert_allclose(
            fast.q, slow.q, atol=KERNEL_VS_REFERENCE_ATOL, err_msg=str(strategy)
        )
        np.testing.assert_allclose(fast.qd, slow.qd, atol=1e3 * KERNEL_VS_REFERENCE_ATOL)
        np.testing.assert_allclose(fast.m, slow.m, atol=KERNEL_VS_REFERENCE_ATOL)


def test_dls_step_is_the_damped_solution(arm: Arm, problem: ResolvedRateProblem) -> None:
    run = run_resolved_rate(problem, "dls", max_steps=1)
    q = run.q[0]
    J = task_jacobian(q, "position_pitch")
    p = problem.parameters
    m = manipulability(q, "position_pitch")
    lam2 = p.lambda_min**2 + (p.lambda_max * (1 - m / p.as_array()[5])) ** 2 * (m < p.as_array()[5])
    _, xd = problem.path.sample(np.array([0.0]))
    e = run.x_ref[0] - run.x[0]
    xc = xd[0] + problem.gain * e
    # Push-through identity: (J^T J + l I)^-1 J^T = J^T (J J^T + l I)^-1.
    expected = J.T @ np.linalg.solve(J @ J.T + lam2 * np.eye(4), xc)
    np.testing.assert_allclose(run.qd[0], expected, atol=1e-12)


def test_path_reference_lspb() -> None:
    path = PathReference.line([0.0, 0.0, 0.0], [1.0, 0.0, 0.0], 0.0, duration=2.0, blend=0.5)
    t = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 3.0])
    x, xd = path.sample(t)
    np.testing.assert_allclose(x[:, 0], [0.0, 1 / 6, 0.5, 5 / 6, 1.0, 1.0], atol=1e-15)
    np.testing.assert_allclose(xd[:, 0], [0.0, 2 / 3, 2 / 3, 2 / 3, 0.0, 0.0], atol=1e-15)


def test_parameter_errors(problem: ResolvedRateProblem) -> None:
    with pytest.raises(
        SingularityParameterError, match=r"sigma = 0\.0 must be a finite number > 0"
    ):
        TrParameters(m_bar=1e-3, sigma=0.0, k_r=1.0)
    with pytest.raises(SingularityParameterError, match=r"sigma = -1\.0 must be"):
        TrParameters(m_bar=1e-3, sigma=-1.0, k_r=1.0)
    with pytest.raises(SingularityParameterError, match="m_bar = nan must be"):
        TrParameters(m_bar=float("nan"), sigma=1e-3, k_r=1.0)
    with pytest.raises(
        SingularityParameterError, match=r"k_r = -2\.0 must be a finite number >= 0"
    ):
        TrParameters(m_bar=1e-3, sigma=1e-3, k_r=-2.0)
    with pytest.raises(SingularityParameterError, match=r"lambda_min = 0\.0"):
        TrParameters(m_bar=1e-3, sigma=1e-3, k_r=1.0, lambda_min=0.0)
    with pytest.raises(SingularityParameterError, match=r"blend = 2\.0 must be <= duration / 2"):
        PathReference.line([0, 0, 0], [1, 0, 0], 0.0, duration=3.0, blend=2.0)
    with pytest.raises(ShapeError, match=r"points must have shape \(M, 4\)"):
        PathReference(np.zeros((1, 4)), 1.0, 0.1)
    params = problem.parameters
    with pytest.raises(TaskError, match="rows among vx, vy, vz, pitch"):
        ResolvedRateProblem(problem.path, problem.q0, ["vx", "vy", "wz"], params)
    with pytest.raises(SingularityParameterError, match=r"dt = 0\.0 must be"):
        ResolvedRateProblem(problem.path, problem.q0, "position", params, dt=0.0)
    with pytest.raises(InputError, match="velocity_limits must be finite and > 0"):
        ResolvedRateProblem(
            problem.path, problem.q0, "position", params, velocity_limits=np.zeros(5)
        )
    with pytest.raises(ShapeError, match=r"q0 must have shape \(5,\)"):
        ResolvedRateProblem(problem.path, np.zeros((2, 5)), "position", params)
    with pytest.raises(InputError, match="unknown strategy 'newton'; valid strategies: pinv"):
        run_resolved_rate(problem, "newton")
    with pytest.raises(InputError, match="max_steps must be >= 1"):
        run_resolved_rate(problem, "pinv", max_steps=0)


def test_position_only_task_runs_the_line(arm: Arm, problem: ResolvedRateProblem) -> None:
    # Redundant task (3 rows, 4 moving joints): the minimum-norm pseudo-inverse also has to turn
    # the base through half a revolution near the axis; the damped strategies do not.
    position = ResolvedRateProblem(
        problem.path, problem.q0, "position", problem.parameters, gain=problem.gain
    )
    metrics = {s: run_metrics(r, position, arm.limits) for s, r in run_all(position).items()}
    assert metrics[Strategy.PINV].speed_limit_exceeded
    assert not metrics[Strategy.SPEED_LIMIT].speed_limit_exceeded
    assert metrics[Strategy.SPEED_LIMIT].max_tracking_error < 1e-4
    assert metrics[Strategy.PINV].max_pitch_error == 0.0  # pitch is not a task row
