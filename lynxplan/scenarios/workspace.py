"""Scenario kind ``workspace``: sample the arm's workspace; volume, reach, plots, HTML.

Example (``scenarios/workspace.yaml``)::

    kind: workspace
    units: {length: in, angle: deg}
    samples: 2000000          # random configurations
    cell: 0.04                # planar (r, z) grid cell, in the file's length unit
    voxel_size: 0.4           # voxel edge of the voxel-count cross-check
    expect: {max_reach: 16.5, min_volume: 9000}

Metrics: ``volume`` [m^3] (revolution of the (r, z) region), ``volume_voxels`` [m^3],
``reach`` [m] (largest sampled distance from the shoulder), ``z_min``/``z_max`` [m].

``robot: {name: so101}`` (or ``{urdf: .., tool: ..}``, any chain): the sampled tool points of
:func:`lynxplan.robots.workspace.sample_workspace`; ``volume_voxels``, ``reach`` (from the base
origin), ``z_min``/``z_max`` (no planar ``volume``: that envelope is the AL5's).
Artifacts: ``workspace.json`` and, unless quick, ``workspace_*.png`` and ``workspace.html``.
"""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Any, ClassVar, Literal

from pydantic import Field

from lynxplan.scenarios.base import KindOutput, Quantity, RobotRef, ScenarioModel, Units
from lynxplan.units import length_factor

NAME = "workspace"

#: Largest number of random samples a scenario may ask for (about 16 bytes x 3 each).
MAX_SAMPLES = 50_000_000


class Input(ScenarioModel):
    """Workspace analysis of the arm (SPEC Part 1, Workspace)."""

    metrics: ClassVar[dict[str, Quantity]] = {
        "volume": "volume",
        "volume_voxels": "volume",
        "reach": "length",
        "z_min": "length",
        "z_max": "length",
    }

    kind: Literal["workspace"]
    name: str = "workspace"
    units: Units = Units(length="in", angle="deg")
    robot: RobotRef = Field(default_factory=RobotRef)
    samples: int = Field(2_000_000, ge=1, le=MAX_SAMPLES, description="Random configurations.")
    voxel_size: float = Field(0.4, gt=0, allow_inf_nan=False, description="Voxel edge.")
    cell: float = Field(0.04, gt=0, allow_inf_nan=False, description="Planar grid cell.")
    seed: int = Field(0, ge=0, lt=2**63)
    report_grid: bool = Field(True, description="Also sample the report's grid (plots use it).")

    def si_inputs(self) -> dict[str, Any]:
        """Inputs with lengths in [m]."""
        scale = length_factor(self.units.length)
        data = super().si_inputs()
        data.update(voxel_size=self.voxel_size * scale, cell=self.cell * scale)
        data["units"] = {"length": "m", "angle": "rad"}
        return data


def run(scenario: Input, *, quick: bool = False, cluster: Any = None) -> KindOutput:
    """Sample the workspace and measure it (no files): the AL5's planar envelope, or the
    sampled points of any other robot. ``cluster`` (a :class:`lynxplan.fanout.Cluster`): the
    sweep in chunks on Dask, the same estimate."""
    from lynxplan.arm.model import Arm
    from lynxplan.arm.workspace import estimate_workspace, report_grid, tool_positions
    from lynxplan.progress import progress_bar
    from lynxplan.scenarios.robot import load_robot_entry

    arm = load_robot_entry(scenario.robot)
    if not isinstance(arm, Arm):
        return _run_sampled(scenario, arm, cluster)
    if cluster is not None:
        from lynxplan.fanout.workspace import estimate_workspace_on_dask

        estimate_workspace = partial(estimate_workspace_on_dask, cluster=cluster)
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
    grid = tool_positions(report_grid(arm.limits), arm.geometry) if scenario.report_grid else None
    metrics = {"volume": estimate.volume_revolution, **_sampled_metrics(estimate)}
    summary = (
        f"workspace of {arm.urdf_path.name}: {estimate.samples:,} samples, volume "
        f"{estimate.volume_revolution / scale**3:.4g} {unit}^3 (voxel estimate "
        f"{estimate.volume_voxels / scale**3:.4g} {unit}^3), max reach "
        f"{estimate.max_reach / scale:.4f} {unit}, z from {estimate.z_range[0] / scale:.3f} to "
        f"{estimate.z_range[1] / scale:.3f} {unit}."
    )
    details = {
        "samples": estimate.samples,
        "grid_cell": estimate.envelope.cell,
        "voxel_size": estimate.voxel_size,
        "report_grid_points": None if grid is None else int(grid.shape[0]),
    }
    return KindOutput(metrics, summary, details, payload=(estimate, grid))


def _sampled_metrics(estimate: Any) -> dict[str, Any]:
    """The metrics every workspace estimate has (SI): voxel volume, reach and height range."""
    return {
        "volume_voxels": estimate.volume_voxels,
        "reach": estimate.max_reach,
        "z_min": estimate.z_range[0],
        "z_max": estimate.z_range[1],
    }


def _run_sampled(scenario: Input, robot: Any, cluster: Any) -> KindOutput:
    """Any robot of ``lynxplan.load_robot``: voxel volume, reach and height of sampled points."""
    from lynxplan.progress import progress_bar
    from lynxplan.robots.workspace import sample_workspace

    if cluster is not None:
        from lynxplan.fanout.workspace import sample_workspace_on_dask

        sample_workspace = partial(sample_workspace_on_dask, cluster=cluster)

    unit = scenario.units.length
    scale = length_factor(unit)
    with progress_bar("sampling workspace") as progress:
        estimate = sample_workspace(
            robot,
            samples=scenario.samples,
            voxel_size=scenario.voxel_size * scale,
            seed=scenario.seed,
            progress=progress,
        )
    metrics = _sampled_metrics(estimate)
    summary = (
        f"workspace of {robot.name}: {estimate.samples:,} samples, voxel volume "
        f"{estimate.volume_voxels / scale**3:.4g} {unit}^3 ({scenario.voxel_size:g} {unit} "
        f"voxels), max reach {estimate.max_reach / scale:.4f} {unit} from the base origin, z "
        f"from {estimate.z_range[0] / scale:.3f} to {estimate.z_range[1] / scale:.3f} {unit}."
    )
    details = {
        "robot": robot.name,
        "samples": estimate.samples,
        "voxel_size": estimate.voxel_size,
        "method": "tool points of uniform random configurations; voxel occupancy volume",
    }
    notes = {"volume": "the planar revolution volume is the AL5's; use volume_voxels"}
    return KindOutput(metrics, summary, details, payload=estimate, notes=notes)


def write_outputs(scenario: Input, output: KindOutput, out_dir: Path, *, quick: bool) -> list[str]:
    """``workspace.json`` (in the file's unit) and, unless quick, the plots and the HTML view."""
    from lynxplan.arm.workspace_report import (
        plot_workspace,
        reference_skeleton,
        workspace_summary,
        write_html,
    )
    from lynxplan.scenarios.report import write_json
    from lynxplan.scenarios.robot import load_robot_entry

    unit = scenario.units.length
    if not isinstance(output.payload, tuple):  # a URDF robot: the sampled points
        units = {"length": "m", "volume": "m^3"}
        write_json(out_dir / "workspace.json", {**output.details, **output.metrics, "units": units})
        if quick:
            return ["workspace.json"]
        skeleton = reference_skeleton(load_robot_entry(scenario.robot))
        write_html(output.payload.positions, out_dir / "workspace.html", unit, skeleton)
        return ["workspace.json", "workspace.html"]
    estimate, grid = output.payload
    write_json(out_dir / "workspace.json", workspace_summary(estimate, grid, unit))
    if quick:
        return ["workspace.json"]
    paths = plot_workspace(estimate, grid, out_dir, unit)
    skeleton = reference_skeleton(load_robot_entry(scenario.robot))
    write_html(estimate.positions, out_dir / "workspace.html", unit, skeleton)
    return ["workspace.json", "workspace.html", *(p.name for p in paths)]
