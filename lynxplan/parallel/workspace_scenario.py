"""Scenario kind ``parallel_workspace``: constant-orientation workspaces of the 3-RRR.

Example (``scenarios/parallel_workspace.yaml``)::

    kind: parallel_workspace
    units: {length: mm, angle: deg}
    alphas: [20, -10]
    step: 1
    loci_mode: "+++"
    expect: {min_area: 50000, max_area: 70000}   # per orientation, in (length unit)^2

Outputs: ``parallel_workspace.json`` (area and points per orientation) and, unless quick, one
``parallel_workspace_alpha<A>.png`` per orientation with the base triangle and singularity loci.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Literal

from pydantic import Field

from lynxplan.parallel.ik_scenario import GeometrySpec
from lynxplan.scenario import Outcome, StrictModel, Units
from lynxplan.units import angle_factor, length_factor


class Region(StrictModel):
    """Scanned region in the file's length unit (default: the report's, in mm)."""

    x: tuple[float, float] = (70.0, 420.0)
    y: tuple[float, float] = (0.0, 320.0)


class Expect(StrictModel):
    """Expected areas, in the file's length unit squared, for every orientation."""

    min_area: float | None = None
    max_area: float | None = None


class Scenario(StrictModel):
    """A ``parallel_workspace`` scenario."""

    kind: Literal["parallel_workspace"]
    name: str = ""
    units: Units = Units(length="mm", angle="deg")
    geometry: GeometrySpec = Field(default_factory=GeometrySpec)
    alphas: list[float] = Field(min_length=1, description="Platform orientations.")
    step: float = Field(gt=0, description="Grid step, in the file's length unit.")
    region: Region = Field(default_factory=Region)
    mode: str | None = Field(default=None, description="Restrict to this working mode, e.g. '+-+'.")
    loci_mode: str = Field(default="+++", description="Working mode whose Type II locus is drawn.")
    expect: Expect = Field(default_factory=Expect)


def run(scenario: Scenario, out_dir: Path | None, *, quick: bool = False) -> Outcome:
    """Compute each workspace, check the expected areas, write JSON and plots."""
    from lynxplan.parallel.ik import mode_index
    from lynxplan.parallel.workspace import constant_orientation_workspace

    geometry = scenario.geometry.build(scenario.units)
    length, angle = length_factor(scenario.units.length), angle_factor(scenario.units.angle)
    loci_mode = mode_index(scenario.loci_mode)
    results, failed = [], []
    for alpha in scenario.alphas:
        workspace = constant_orientation_workspace(
            alpha * angle,
            geometry,
            step=scenario.step * length,
            x_range=(scenario.region.x[0] * length, scenario.region.x[1] * length),
            y_range=(scenario.region.y[0] * length, scenario.region.y[1] * length),
            mode=scenario.mode,
        )
        area = workspace.area / length**2
        results.append(
            {
                "alpha": alpha,
                "area": area,
                "area_mm2": workspace.area_mm2,
                "points": workspace.points,
            }
        )
        low, high = scenario.expect.min_area, scenario.expect.max_area
        if (low is not None and area < low) or (high is not None and area > high):
            failed.append(f"alpha {alpha:g}: area {area:.6g} outside expected [{low}, {high}]")
        if out_dir is not None and not quick:
            from lynxplan.parallel.plots import plot_workspace

            plot_workspace(
                workspace,
                out_dir / f"parallel_workspace_alpha{alpha:g}.png",
                geometry,
                loci_mode=loci_mode,
            )
    if out_dir is not None:
        (out_dir / "parallel_workspace.json").write_text(
            json.dumps({"workspaces": results}, indent=2)
        )
    areas = ", ".join(f"alpha {r['alpha']:g}: {r['area_mm2']:.0f} mm^2" for r in results)
    return Outcome(
        summary=f"parallel_workspace {scenario.name}: {areas}", failed_expectations=tuple(failed)
    )
