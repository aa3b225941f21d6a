"""Scenario kind ``parallel_ik``: the 8 working modes of a 3-RRR pose, checked by FK and Pinocchio.

Example (``scenarios/parallel_ik.yaml``)::

    kind: parallel_ik
    units: {length: mm, angle: deg}
    pose: [260, 180, 30]                       # xc, yc, alpha
    expect:
      solutions: {equals: [[58.0030, 159.7404, -64.4231], ...], tolerance: 1.0e-4}

Metrics: ``solutions`` [rad] (8 x 3, report order), ``fk_error`` [m] (per mode, distance from the
pose to the nearest FK assembly mode), ``closure_residual`` [m] (per mode, Pinocchio loop closure),
``assembly_modes`` (per mode). Every run checks ``max_fk_error <= 1e-9 m`` and
``max_closure_residual <= 1e-12 m``. Artifacts: ``parallel_ik.json`` and, unless quick,
``parallel_postures.png``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from pydantic import Field

from lynxplan.scenarios.base import KindOutput, Quantity, ScenarioModel, StrictModel, Units
from lynxplan.units import angle_factor, length_factor

NAME = "parallel_ik"


class GeometrySpec(StrictModel):
    """Robot dimensions in the file's length unit (defaults: the report's robot, in mm)."""

    base_circumradius: float | None = Field(default=None, gt=0, allow_inf_nan=False)
    platform_circumradius: float | None = Field(default=None, gt=0, allow_inf_nan=False)
    proximal: float | None = Field(default=None, gt=0, allow_inf_nan=False)
    distal: float | None = Field(default=None, gt=0, allow_inf_nan=False)

    def build(self, units: Units) -> Any:
        """The :class:`lynxplan.parallel.geometry.ParallelGeometry`, in [m]."""
        from lynxplan.parallel.geometry import ParallelGeometry

        scale = length_factor(units.length)
        given = {k: v * scale for k, v in self.model_dump().items() if v is not None}
        return ParallelGeometry(**given)

    def si(self, units: Units) -> dict[str, Any]:
        """The given dimensions in [m] (None: the default)."""
        scale = length_factor(units.length)
        return {k: None if v is None else v * scale for k, v in self.model_dump().items()}


class ParallelScenario(ScenarioModel):
    """Fields of every 3-RRR kind: the units (default mm and deg) and the robot's dimensions."""

    units: Units = Units(length="mm", angle="deg")
    geometry: GeometrySpec = Field(default_factory=GeometrySpec)

    def si_inputs(self) -> dict[str, Any]:
        """Kind, name and the dimensions in [m]; each kind adds its own inputs."""
        return {"kind": self.kind, "name": self.name, "geometry": self.geometry.si(self.units)}


class Input(ParallelScenario):
    """A ``parallel_ik`` scenario."""

    metrics: ClassVar[dict[str, Quantity]] = {
        "solutions": "angle",
        "fk_error": "length",
        "closure_residual": "length",
        "assembly_modes": "count",
    }
    default_expect: ClassVar[dict[str, Any]] = {
        "max_fk_error": "<= 1e-9 m",
        "max_closure_residual": "<= 1e-12 m",
    }

    kind: Literal["parallel_ik"]
    pose: tuple[float, float, float] = Field(description="xc, yc (length unit), alpha (angle).")

    def si_inputs(self) -> dict[str, Any]:
        """Inputs in [m] and [rad]."""
        length, angle = length_factor(self.units.length), angle_factor(self.units.angle)
        return {
            **super().si_inputs(),
            "pose": [self.pose[0] * length, self.pose[1] * length, self.pose[2] * angle],
        }


def run(scenario: Input, *, quick: bool = False) -> KindOutput:
    """Solve the IK, verify each mode by FK and by the Pinocchio closure."""
    from lynxplan.parallel.fk import pose_distance, solve_fk
    from lynxplan.parallel.ik import WORKING_MODES, solve_ik
    from lynxplan.parallel.pinocchio_model import (
        build_closed_loop_model,
        closure_residual,
        configuration_from_pose,
    )

    geometry = scenario.geometry.build(scenario.units)
    pose = np.array(scenario.si_inputs()["pose"])
    theta = solve_ik(pose, geometry)
    closed = build_closed_loop_model(geometry)
    modes = []
    for m, row in enumerate(theta):
        fk = solve_fk(row, geometry)
        modes.append(
            {
                "mode": WORKING_MODES[m],
                "theta": row,
                "assembly_modes": fk.n_modes,
                "fk_error": float(pose_distance(fk.poses, pose, geometry).min()),
                "closure_residual": closure_residual(
                    closed, configuration_from_pose(closed, pose, row)
                ),
            }
        )
    metrics = {
        "solutions": theta,
        "fk_error": [m["fk_error"] for m in modes],
        "closure_residual": [m["closure_residual"] for m in modes],
        "assembly_modes": [m["assembly_modes"] for m in modes],
    }
    counts = ", ".join(str(m["assembly_modes"]) for m in modes)
    summary = (
        f"parallel_ik {scenario.name}: pose {tuple(scenario.pose)} -> 8 working modes; "
        f"assembly modes per working mode: {counts}; largest closure residual "
        f"{max(m['closure_residual'] for m in modes) * 1e3:.2e} mm"
    )
    return KindOutput(metrics, summary, {"modes": modes}, payload=(pose, geometry))


def write_outputs(scenario: Input, output: KindOutput, out_dir: Path, *, quick: bool) -> list[str]:
    """``parallel_ik.json`` (angles in the file's unit) and, unless quick, the postures figure."""
    from lynxplan.scenarios.report import write_json

    angle = angle_factor(scenario.units.angle)
    modes = [{**m, "theta": np.asarray(m["theta"]) / angle} for m in output.details["modes"]]
    write_json(out_dir / "parallel_ik.json", {"pose": list(scenario.pose), "modes": modes})
    if quick:
        return ["parallel_ik.json"]
    from lynxplan.parallel.plots import plot_postures

    pose, geometry = output.payload
    plot_postures(pose, out_dir / "parallel_postures.png", geometry)
    return ["parallel_ik.json", "parallel_postures.png"]
