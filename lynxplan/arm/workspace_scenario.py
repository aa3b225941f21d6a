"""Scenario kind ``workspace``: sample the arm's workspace, write plots, HTML and JSON."""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import Field, PositiveFloat, PositiveInt

from lynxplan.scenario import Outcome, StrictModel, Units
from lynxplan.units import length_factor


class Expectations(StrictModel):
    """Checks on the result; lengths/volumes in the scenario's length unit."""

    min_volume: PositiveFloat | None = Field(None, description="Volume at least this.")
    max_volume: PositiveFloat | None = Field(None, description="Volume at most this.")
    max_reach: PositiveFloat | None = Field(None, description="Sampled reach at most this.")
    min_reach: PositiveFloat | None = Field(None, description="Sampled reach at least this.")


class Scenario(StrictModel):
    """Workspace analysis of the arm (SPEC Part 1, Workspace)."""

    kind: Literal["workspace"]
    name: str = "workspace"
    description: str = ""
    units: Units = Units(length="in", angle="deg")
    robot: str | None = Field(None, description="URDF path; default: the shipped AL5 arm.")
    samples: PositiveInt = Field(2_000_000, description="Random configurations to sample.")
    voxel_size: PositiveFloat = Field(0.4, description="Voxel edge for the voxel volume.")
    cell: PositiveFloat = Field(0.04, description="Planar grid cell for envelope and volume.")
    seed: int = 0
    report_grid: bool = Field(True, description="Also sample the report's grid (plots use it).")
    expect: Expectations = Expectations()


def run(scenario: Scenario, out_dir: Path | None, *, quick: bool = False) -> Outcome:
    """Run the workspace analysis; write outputs unless ``out_dir`` is None."""
    from lynxplan.arm.model import load_arm
    from lynxplan.arm.workspace import estimate_workspace, report_grid, tool_positions
    from lynxplan.arm.workspace_report import (
        plot_workspace,
        workspace_summary,
        write_html,
        write_json,
    )
    from lynxplan.progress import progress_bar

    arm = load_arm(scenario.robot)
    unit = scenario.units.length
    scale = length_factor(unit)
    with progress_bar("sampling workspace") as progress:
        estimate = estimate_workspace(
            arm.geometry,
            arm.limits,
            samples=scenario.samples,
            voxel_size=scenario.voxel_size * scale,
            cell=scenario.cell * scale,
            seed=scenario.seed,
            progress=progress,
        )
    grid_points = (
        tool_positions(report_grid(arm.limits), arm.geometry) if scenario.report_grid else None
    )
    summary = workspace_summary(estimate, grid_points, unit)
    if out_dir is not None:
        write_json(summary, out_dir / "workspace.json")
        if not quick:
            plot_workspace(estimate, grid_points, out_dir, unit)
            write_html(estimate.positions, out_dir / "workspace.html", unit)
    failed = []
    expect = scenario.expect
    if expect.min_volume is not None and summary["volume"] < expect.min_volume:
        failed.append(f"min_volume: {summary['volume']:.4g} < {expect.min_volume:g} {unit}^3")
    if expect.max_volume is not None and summary["volume"] > expect.max_volume:
        failed.append(f"max_volume: {summary['volume']:.4g} > {expect.max_volume:g} {unit}^3")
    if expect.max_reach is not None and summary["max_reach"] > expect.max_reach:
        failed.append(f"max_reach: {summary['max_reach']:.6g} > {expect.max_reach:g} {unit}")
    if expect.min_reach is not None and summary["max_reach"] < expect.min_reach:
        failed.append(f"min_reach: {summary['max_reach']:.6g} < {expect.min_reach:g} {unit}")
    text = (
        f"workspace of {arm.urdf_path.name}: {estimate.samples:,} samples, volume "
        f"{summary['volume']:.4g} {unit}^3 (planar cell {summary['grid_cell']:g} {unit}; voxel "
        f"estimate {summary['volume_voxels']:.4g} {unit}^3 at {summary['voxel_size']:g} {unit}), "
        f"max reach {summary['max_reach']:.4f} {unit}, z from {summary['z_min']:.3f} to "
        f"{summary['z_max']:.3f} {unit}."
    )
    return Outcome(text, tuple(failed))
