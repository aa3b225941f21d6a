"""Scenario kind ``singularity``: the four resolved-rate strategies side by side on one path.

Metrics: ``pinv_exceeds_speed_limit``, ``within_speed_limits`` and ``returns_to_path`` (flags per
strategy: pinv, speed_limit, dls, tr), ``distance_to_singularity`` [m] (closest approach of the
line to the base axis). ``report.json`` details hold the parameters, the singular conditions of
the task and the metrics table; unless quick, the plots of :mod:`lynxplan.singularity.plots`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import Field, model_validator

from lynxplan.arm import Arm, load_arm
from lynxplan.scenarios.base import (
    SI_UNITS,
    KindOutput,
    Quantity,
    ScenarioModel,
    StrictModel,
    Units,
    scaled,
)
from lynxplan.singularity.classify import (
    max_manipulability,
    singular_conditions,
    singularity_distances,
)
from lynxplan.singularity.resolved_rate import (
    STRATEGY_NAMES,
    PathReference,
    ResolvedRateProblem,
    ResolvedRateRun,
    RunMetrics,
    Strategy,
    TrParameters,
    run_all,
    run_metrics,
)
from lynxplan.singularity.tasks import make_task
from lynxplan.units import angle_factor, length_factor

NAME = "singularity"

StrategyName = Literal["pinv", "speed_limit", "dls", "tr"]


class Line(StrictModel):
    """A straight line of the tool point at constant approach pitch."""

    start: tuple[float, float, float] = Field(description="Start point (file length unit).")
    end: tuple[float, float, float] = Field(description="End point (file length unit).")
    pitch: float = Field(description="Approach pitch q2+q3+q4 (file angle unit).")


class Timing(StrictModel):
    """LSPB timing of the line, in [s]."""

    duration: float = Field(gt=0, description="Time to traverse the line, s.")
    blend: float = Field(gt=0, description="LSPB blend time, s (<= duration / 2).")
    hold: float = Field(0.0, ge=0, description="Time the reference stays at the end, s.")


class Control(StrictModel):
    """Resolved-rate loop."""

    dt: float = Field(1e-3, gt=0, description="Step, s.")
    gain: float = Field(1.0, ge=0, description="Tracking gain on the task error, 1/s.")


class TrSettings(StrictModel):
    """Task-reconstruction parameters: absolute, or as fractions of the largest m in limits."""

    m_bar: float | None = Field(None, gt=0, description="Safety threshold (task units).")
    sigma: float | None = Field(None, gt=0, description="Acting range (task units).")
    m_bar_fraction: float | None = Field(None, gt=0, lt=1, description="m_bar / max m.")
    sigma_fraction: float | None = Field(None, gt=0, lt=1, description="sigma / max m.")
    k_r: float = Field(ge=0, description="Escape gain (task units/s per unit of m).")

    @model_validator(mode="after")
    def _one_of_each(self) -> TrSettings:
        for name in ("m_bar", "sigma"):
            given = (getattr(self, name) is not None) + (
                getattr(self, f"{name}_fraction") is not None
            )
            if given != 1:
                raise ValueError(f"give exactly one of {name} and {name}_fraction")
        return self


class DlsSettings(StrictModel):
    """Damped-least-squares damping, in task units (m/rad for position rows)."""

    lambda_max: float = Field(0.02, gt=0, description="Damping at m = 0.")
    lambda_min: float = Field(1e-4, gt=0, description="Damping everywhere (5x5 regular).")


class Input(ScenarioModel):
    """A singularity scenario: one path, four strategies."""

    metrics: ClassVar[dict[str, Quantity]] = {
        "pinv_exceeds_speed_limit": "bool",
        "within_speed_limits": "flags",
        "returns_to_path": "flags",
        "distance_to_singularity": "length",
    }

    kind: Literal["singularity"]
    units: Units = Units()
    task: Literal["position", "position_pitch"] = "position_pitch"
    line: Line
    timing: Timing
    q_reference: tuple[float, float, float, float, float] | None = Field(
        None, description="Configuration the start IK stays near (file angle unit)."
    )
    control: Control = Control()
    tr: TrSettings
    dls: DlsSettings = DlsSettings()

    def si_inputs(self) -> dict[str, Any]:
        """Inputs in [m] and [rad]."""
        length, angle = length_factor(self.units.length), angle_factor(self.units.angle)
        data = super().si_inputs()
        data["units"] = dict(SI_UNITS)
        data["line"].update(
            start=scaled(self.line.start, length),
            end=scaled(self.line.end, length),
            pitch=scaled(self.line.pitch, angle),
        )
        data["q_reference"] = scaled(self.q_reference, angle)
        return data


Scenario = Input


def build_problem(scenario: Scenario) -> ResolvedRateProblem:
    """Scenario -> resolved-rate problem in SI units (start configuration by IK)."""
    arm = load_arm()
    lf, af = length_factor(scenario.units.length), angle_factor(scenario.units.angle)
    start = np.array(scenario.line.start) * lf
    end = np.array(scenario.line.end) * lf
    pitch = scenario.line.pitch * af
    path = PathReference.line(
        start, end, pitch, scenario.timing.duration, scenario.timing.blend, scenario.timing.hold
    )
    reference = None if scenario.q_reference is None else np.array(scenario.q_reference) * af
    q0 = start_configuration(arm, start, pitch, reference)
    task = make_task(scenario.task)
    tr = scenario.tr
    m_max = max_manipulability(task, arm.limits.lower, arm.limits.upper, arm.geometry)
    m_bar = tr.m_bar if tr.m_bar is not None else float(tr.m_bar_fraction or 0.0) * m_max
    sigma = tr.sigma if tr.sigma is not None else float(tr.sigma_fraction or 0.0) * m_max
    parameters = TrParameters(
        m_bar=m_bar,
        sigma=sigma,
        k_r=tr.k_r,
        lambda_max=scenario.dls.lambda_max,
        lambda_min=scenario.dls.lambda_min,
    )
    return ResolvedRateProblem(
        path,
        q0,
        task,
        parameters,
        dt=scenario.control.dt,
        gain=scenario.control.gain,
        velocity_limits=arm.limits.velocity,
        geometry=arm.geometry,
    )


def start_configuration(
    arm: Arm, point: np.ndarray, pitch: float, q_reference: np.ndarray | None
) -> np.ndarray:
    """IK of the tool point (3,) in [m] at approach pitch [rad], within limits, near a reference."""
    q1 = math.atan2(point[1], point[0])
    approach = np.array(
        [math.cos(q1) * math.sin(pitch), math.sin(q1) * math.sin(pitch), -math.cos(pitch)]
    )
    y4 = np.array([math.sin(q1), -math.cos(q1), 0.0])
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = np.cross(y4, approach), y4, approach, point
    return np.array(arm.ik(pose, q_reference=q_reference, approach_only=True).q)


def line_distance_to_base_axis(start: np.ndarray, end: np.ndarray) -> float:
    """Closest distance of the segment start-end (3,) in [m] to the base (z) axis, in [m]."""
    a, b = np.asarray(start[:2], dtype=float), np.asarray(end[:2], dtype=float)
    direction = b - a
    length2 = float(direction @ direction)
    s = 0.0 if length2 == 0.0 else min(max(-float(a @ direction) / length2, 0.0), 1.0)
    return float(np.linalg.norm(a + s * direction))


def run(scenario: Input, *, quick: bool = False) -> KindOutput:
    """Run the four strategies on the scenario's path (no files)."""
    problem = build_problem(scenario)
    arm = load_arm()
    runs = run_all(problem)
    metrics = {s: run_metrics(r, problem, arm.limits) for s, r in runs.items()}
    path_points = problem.path.points
    axis_distance = line_distance_to_base_axis(path_points[0, :3], path_points[-1, :3])
    conditions = [c.value for c in singular_conditions(problem.task, arm.geometry)]
    by_name = {m.strategy: m for m in metrics.values()}
    values = {
        "pinv_exceeds_speed_limit": by_name["pinv"].speed_limit_exceeded,
        "within_speed_limits": {n: not m.speed_limit_exceeded for n, m in by_name.items()},
        "returns_to_path": {n: m.completion_time is not None for n, m in by_name.items()},
        "distance_to_singularity": axis_distance,
    }
    text = summary(problem, metrics, axis_distance, conditions)
    details = report_details(scenario, problem, runs, metrics, axis_distance, conditions)
    return KindOutput(values, text, details, payload=(runs, problem))


def write_outputs(scenario: Input, output: KindOutput, out_dir: Path, *, quick: bool) -> list[str]:
    """Unless quick, the plots of :mod:`lynxplan.singularity.plots`."""
    if quick:
        return []
    from lynxplan.singularity.plots import plot_runs

    runs, problem = output.payload
    return [str(Path(p).relative_to(out_dir)) for p in plot_runs(runs, problem, out_dir)]


def summary(
    problem: ResolvedRateProblem,
    metrics: dict[Strategy, RunMetrics],
    axis_distance: float,
    conditions: list[str],
) -> str:
    """Metrics table as text."""
    lines = [
        f"singularity: task {problem.task.name} (singular when: {', '.join(conditions)}); the "
        f"line passes {axis_distance * 1e3:.3f} mm from the base axis; "
        f"m_bar = {problem.parameters.m_bar:.4g}, sigma = {problem.parameters.sigma:.4g}",
        f"{'strategy':<12} {'peak qd':>9} {'x limit':>8} {'max err':>9} {'rms err':>9} "
        f"{'min m':>10} {'done at':>8} {'q viol':>8}",
    ]
    for m in metrics.values():
        done = "never" if m.completion_time is None else f"{m.completion_time:.3f}"
        lines.append(
            f"{m.strategy:<12} {m.peak_joint_speed:>7.3f}/s {m.peak_speed_ratio:>8.3f} "
            f"{m.max_tracking_error * 1e3:>6.2f} mm {m.rms_tracking_error * 1e3:>6.2f} mm "
            f"{m.min_manipulability:>10.3e} {done:>8} "
            f"{math.degrees(m.joint_limit_violation):>6.2f}deg"
        )
    return "\n".join(lines)


def report_details(
    scenario: Input,
    problem: ResolvedRateProblem,
    runs: dict[Strategy, ResolvedRateRun],
    metrics: dict[Strategy, RunMetrics],
    axis_distance: float,
    conditions: list[str],
) -> dict[str, Any]:
    """Parameters, the start configuration and its singular distances, the metrics table."""
    q0 = problem.q0
    return {
        "description": scenario.description,
        "task": {"name": problem.task.name, "rows": list(problem.task.row_names)},
        "singular_conditions": conditions,
        "line_distance_to_base_axis_m": axis_distance,
        "start_configuration_rad": q0.tolist(),
        "start_singularity_distances": [
            {"kind": d.kind.value, "distance": float(d.distance), "unit": d.unit}
            for d in singularity_distances(q0, problem.geometry)
        ],
        "parameters": {
            "m_bar": problem.parameters.m_bar,
            "sigma": problem.parameters.sigma,
            "k_r": problem.parameters.k_r,
            "lambda_max": problem.parameters.lambda_max,
            "lambda_min": problem.parameters.lambda_min,
            "dt_s": problem.dt,
            "gain_per_s": problem.gain,
            "velocity_limits_rad_s": problem.velocity_limits.tolist(),
        },
        "metrics": {STRATEGY_NAMES[s]: m._asdict() for s, m in metrics.items()},
        "steps": {STRATEGY_NAMES[s]: int(r.t.size) for s, r in runs.items()},
    }
