"""Scenario kind ``parallel_ik``: the 8 working modes of a pose, checked by FK and Pinocchio.

Example (``scenarios/parallel_ik.yaml``)::

    kind: parallel_ik
    units: {length: mm, angle: deg}
    pose: [260, 180, 30]
    expect:
      solutions: [[58.0030, 159.7404, -64.4231], ...]   # 8 rows, optional
      tolerance: 1.0e-4                                 # in the file's angle unit

Outputs: ``parallel_ik.json`` (solutions, assembly modes of each, closure residuals) and, unless
quick, ``parallel_postures.png`` (the 2x4 figure).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Literal

import numpy as np
from pydantic import Field

from lynxplan.parallel.geometry import ParallelGeometry
from lynxplan.scenario import Outcome, StrictModel, Units
from lynxplan.units import angle_factor, length_factor


class GeometrySpec(StrictModel):
    """Robot dimensions in the file's length unit (defaults: the report's robot, in mm)."""

    base_circumradius: float | None = Field(default=None, gt=0)
    platform_circumradius: float | None = Field(default=None, gt=0)
    proximal: float | None = Field(default=None, gt=0)
    distal: float | None = Field(default=None, gt=0)

    def build(self, units: Units) -> ParallelGeometry:
        """The :class:`ParallelGeometry` in [m]."""
        scale = length_factor(units.length)
        given = {k: v * scale for k, v in self.model_dump().items() if v is not None}
        return ParallelGeometry(**given)


class Expect(StrictModel):
    """Expected results."""

    solutions: list[tuple[float, float, float]] | None = Field(
        default=None, min_length=8, max_length=8, description="8 rows of 3 angles, report order."
    )
    tolerance: float = Field(default=1e-4, gt=0, description="Angle tolerance, in the file's unit.")


class Scenario(StrictModel):
    """A ``parallel_ik`` scenario."""

    kind: Literal["parallel_ik"]
    name: str = ""
    units: Units = Units(length="mm", angle="deg")
    geometry: GeometrySpec = Field(default_factory=GeometrySpec)
    pose: tuple[float, float, float] = Field(description="xc, yc, alpha.")
    expect: Expect = Field(default_factory=Expect)


def run(scenario: Scenario, out_dir: Path | None, *, quick: bool = False) -> Outcome:
    """Solve the IK, verify each mode by FK and by the Pinocchio closure, write the outputs."""
    from lynxplan.parallel.fk import pose_distance, solve_fk
    from lynxplan.parallel.ik import WORKING_MODES, solve_ik
    from lynxplan.parallel.pinocchio_model import (
        build_closed_loop_model,
        closure_residual,
        configuration_from_pose,
    )

    geometry = scenario.geometry.build(scenario.units)
    length, angle = length_factor(scenario.units.length), angle_factor(scenario.units.angle)
    pose = np.array(
        [scenario.pose[0] * length, scenario.pose[1] * length, scenario.pose[2] * angle]
    )
    theta = solve_ik(pose, geometry)
    closed = build_closed_loop_model(geometry)
    modes = []
    for m, row in enumerate(theta):
        fk = solve_fk(row, geometry)
        modes.append(
            {
                "mode": WORKING_MODES[m],
                "theta": (row / angle).tolist(),
                "assembly_modes": fk.n_modes,
                "fk_error_m": float(pose_distance(fk.poses, pose, geometry).min()),
                "closure_residual_m": closure_residual(
                    closed, configuration_from_pose(closed, pose, row)
                ),
            }
        )
    failed = _check(scenario, theta / angle, modes)
    if out_dir is not None:
        (out_dir / "parallel_ik.json").write_text(
            json.dumps({"pose": list(scenario.pose), "modes": modes}, indent=2)
        )
        if not quick:
            from lynxplan.parallel.plots import plot_postures

            plot_postures(pose, out_dir / "parallel_postures.png", geometry)
    counts = ", ".join(str(m["assembly_modes"]) for m in modes)
    summary = (
        f"parallel_ik {scenario.name or ''}: pose {tuple(scenario.pose)} -> 8 working modes; "
        f"assembly modes per working mode: {counts}; largest closure residual "
        f"{max(m['closure_residual_m'] for m in modes) * 1e3:.2e} mm"
    )
    return Outcome(summary=summary, failed_expectations=tuple(failed))


def _check(scenario: Scenario, theta: np.ndarray, modes: list[dict]) -> list[str]:
    """Failed expectations: FK and closure checks of every mode, and the expected angles."""
    from lynxplan.parallel.ik import WORKING_MODES

    failed = []
    for item in modes:
        if item["fk_error_m"] > 1e-9:
            failed.append(
                f"mode {item['mode']}: FK does not recover the pose ({item['fk_error_m']:.3g} m)"
            )
        if item["closure_residual_m"] > 1e-12:
            failed.append(
                f"mode {item['mode']}: loops do not close ({item['closure_residual_m']:.3g} m)"
            )
    if scenario.expect.solutions is not None:
        expected = np.array(scenario.expect.solutions, dtype=float)
        error = np.abs(theta - expected)
        for m in np.flatnonzero(error.max(axis=1) > scenario.expect.tolerance):
            got = np.round(theta[m], 6).tolist()
            want = expected[m].tolist()
            tolerance = scenario.expect.tolerance
            failed.append(
                f"expect.solutions[{m}] ({WORKING_MODES[m]}): got {got}, expected {want} "
                f"within {tolerance:g}"
            )
    return failed
