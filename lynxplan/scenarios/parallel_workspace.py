"""Scenario kind ``parallel_workspace``: constant-orientation workspaces of the 3-RRR.

Example (``scenarios/parallel_workspace.yaml``)::

    kind: parallel_workspace
    units: {length: mm, angle: deg}
    alphas: [20, -10]
    step: 1
    loci_mode: "+++"
    expect: {min_area: 50000, max_area: 70000}   # every orientation, (length unit)^2

Metrics: ``area`` [m^2], one value per orientation (an expectation holds when it holds for all).
Artifacts: ``parallel_workspace.json`` and, unless quick, ``parallel_workspace_alpha<A>.png``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, ClassVar, Literal

from pydantic import Field, model_validator

from lynxplan.scenarios.base import KindOutput, Quantity, StrictModel
from lynxplan.scenarios.parallel_ik import ParallelScenario
from lynxplan.units import angle_factor, length_factor

NAME = "parallel_workspace"

#: Largest grid (cells per orientation) a scenario may ask for.
MAX_GRID_CELLS = 20_000_000


class Region(StrictModel):
    """Scanned region in the file's length unit (default: the report's, in mm)."""

    x: tuple[float, float] = (70.0, 420.0)
    y: tuple[float, float] = (0.0, 320.0)


class Input(ParallelScenario):
    """A ``parallel_workspace`` scenario."""

    metrics: ClassVar[dict[str, Quantity]] = {"area": "area"}

    kind: Literal["parallel_workspace"]
    alphas: list[float] = Field(min_length=1, max_length=360, description="Orientations.")
    step: float = Field(gt=0, allow_inf_nan=False, description="Grid step (length unit).")
    region: Region = Field(default_factory=Region)
    mode: str | None = Field(default=None, description="Restrict to this working mode, e.g. '+-+'.")
    loci_mode: str = Field(default="+++", description="Working mode whose Type II locus is drawn.")

    @model_validator(mode="after")
    def _bounded_grid(self) -> Input:
        (x0, x1), (y0, y1) = self.region.x, self.region.y
        if not (x1 > x0 and y1 > y0):
            raise ValueError(f"region must have x0 < x1 and y0 < y1, got {self.region}")
        cells = ((x1 - x0) / self.step + 1) * ((y1 - y0) / self.step + 1)
        if cells > MAX_GRID_CELLS:
            raise ValueError(
                f"step {self.step:g} over region {self.region.x} x {self.region.y} implies "
                f"{cells:.3g} grid cells per orientation, more than the {MAX_GRID_CELLS:,} "
                "allowed; use a larger step or a smaller region"
            )
        return self

    def si_inputs(self) -> dict[str, Any]:
        """Inputs in [m] and [rad]."""
        length, angle = length_factor(self.units.length), angle_factor(self.units.angle)
        return {
            **super().si_inputs(),
            "alphas": [a * angle for a in self.alphas],
            "step": self.step * length,
            "region": {
                "x": [v * length for v in self.region.x],
                "y": [v * length for v in self.region.y],
            },
            "mode": self.mode,
            "loci_mode": self.loci_mode,
        }


def run(scenario: Input, *, quick: bool = False) -> KindOutput:
    """Compute each orientation's workspace."""
    from lynxplan.parallel.workspace import constant_orientation_workspace

    geometry = scenario.geometry.build(scenario.units)
    si = scenario.si_inputs()
    workspaces = [
        constant_orientation_workspace(
            alpha,
            geometry,
            step=si["step"],
            x_range=tuple(si["region"]["x"]),
            y_range=tuple(si["region"]["y"]),
            mode=scenario.mode,
        )
        for alpha in si["alphas"]
    ]
    areas = [w.area for w in workspaces]
    rows = [
        {"alpha": alpha, "area": w.area, "points": w.points}
        for alpha, w in zip(si["alphas"], workspaces, strict=True)
    ]
    text = ", ".join(
        f"alpha {a:g}: {w.area_mm2:.0f} mm^2"
        for a, w in zip(scenario.alphas, workspaces, strict=True)
    )
    return KindOutput(
        {"area": areas},
        f"parallel_workspace {scenario.name}: {text}",
        {"workspaces": [{k: v for k, v in r.items() if k != "points"} for r in rows]},
        payload=(geometry, workspaces, rows),
    )


def write_outputs(scenario: Input, output: KindOutput, out_dir: Path, *, quick: bool) -> list[str]:
    """``parallel_workspace.json`` and, unless quick, one plot per orientation."""
    from lynxplan.parallel.ik import mode_index
    from lynxplan.scenarios.report import write_json

    geometry, workspaces, rows = output.payload
    length = length_factor(scenario.units.length)
    table = [
        {
            "alpha": alpha,
            "area": r["area"] / length**2,
            "area_mm2": w.area_mm2,
            "points": r["points"],
        }
        for alpha, r, w in zip(scenario.alphas, rows, workspaces, strict=True)
    ]
    write_json(out_dir / "parallel_workspace.json", {"workspaces": table})
    written = ["parallel_workspace.json"]
    if quick:
        return written
    from lynxplan.parallel.plots import plot_workspace

    for alpha, workspace in zip(scenario.alphas, workspaces, strict=True):
        name = f"parallel_workspace_alpha{alpha:g}.png"
        plot_workspace(
            workspace, out_dir / name, geometry, loci_mode=mode_index(scenario.loci_mode)
        )
        written.append(name)
    return written
