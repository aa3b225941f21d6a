"""PNG figures of the planar 3-RRR: the 8 postures of a pose, the workspace with its loci.

matplotlib is imported inside the functions (Agg backend) so the core imports fast. Figures are
drawn in mm, as in the report.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan._plotting import pyplot, save_figure
from lynxplan.parallel.geometry import ParallelGeometry
from lynxplan.parallel.ik import WORKING_MODES, elbows, mode_index, platform_joints, solve_ik
from lynxplan.parallel.singular import type1_circles, type2_grid
from lynxplan.parallel.workspace import Workspace

_DEFAULT_GEOMETRY = ParallelGeometry()
_LEG_COLOURS = ("tab:red", "tab:green", "tab:blue")


def _draw_base(ax: Any, geometry: ParallelGeometry) -> None:
    base = geometry.base_joints * 1e3
    ax.fill(base[:, 0], base[:, 1], facecolor="0.92", edgecolor="0.4", lw=1, zorder=0)
    ax.plot(base[:, 0], base[:, 1], "ks", ms=5, zorder=3)
    for name, (bx, by) in zip("ABC", base, strict=True):
        ax.annotate(f"P{name}", (bx, by), textcoords="offset points", xytext=(-14, -12), fontsize=7)


def draw_posture(ax: Any, pose: np.ndarray, theta: np.ndarray, geometry: ParallelGeometry) -> None:
    """Draw base triangle, legs, platform and needle of one posture on ``ax`` (mm)."""
    _draw_base(ax, geometry)
    base = geometry.base_joints * 1e3
    elbow = elbows(theta, geometry) * 1e3
    joint = platform_joints(pose, geometry) * 1e3
    for leg in range(3):
        xs = [base[leg, 0], elbow[leg, 0], joint[leg, 0]]
        ys = [base[leg, 1], elbow[leg, 1], joint[leg, 1]]
        ax.plot(xs, ys, "-o", color=_LEG_COLOURS[leg], lw=2, ms=3)
    ax.fill(joint[:, 0], joint[:, 1], facecolor="gold", edgecolor="k", alpha=0.8, zorder=2)
    centre = pose[:2] * 1e3
    ax.plot(*centre, "k+", ms=9, mew=2, zorder=4)  # the needle
    ax.set_aspect("equal")
    ax.set_xlim(-120, 620)
    ax.set_ylim(-180, 520)
    ax.tick_params(labelsize=6)


def plot_postures(
    pose: np.ndarray, path: str | Path, geometry: ParallelGeometry = _DEFAULT_GEOMETRY
) -> Path:
    """The 8 working modes of ``pose`` (3,) in [m, m, rad] in a 2x4 grid (report figure 19)."""
    plt = pyplot()
    theta = solve_ik(pose, geometry)
    fig, axes = plt.subplots(2, 4, figsize=(16, 8.5))
    for m, ax in enumerate(axes.ravel()):
        draw_posture(ax, np.asarray(pose, dtype=float), theta[m], geometry)
        angles = ", ".join(f"{math.degrees(t):.2f}" for t in theta[m])
        ax.set_title(f"mode {m + 1} ({WORKING_MODES[m]}): θ = ({angles})°", fontsize=8)
    x, y, alpha = pose[0] * 1e3, pose[1] * 1e3, math.degrees(pose[2])
    fig.suptitle(f"3-RRR working modes for pose ({x:.1f} mm, {y:.1f} mm, {alpha:.1f}°)")
    return save_figure(fig, path)


def plot_workspace(
    workspace: Workspace,
    path: str | Path,
    geometry: ParallelGeometry = _DEFAULT_GEOMETRY,
    *,
    loci_mode: int | str | None = 0,
) -> Path:
    """The workspace points with the base triangle, Type I circles and the Type II locus of
    working mode ``loci_mode`` (None: no loci)."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 7.5))
    x_mm, y_mm = workspace.x * 1e3, workspace.y * 1e3
    extent = (
        x_mm[0] - workspace.step * 5e2,
        x_mm[-1] + workspace.step * 5e2,
        y_mm[0] - workspace.step * 5e2,
        y_mm[-1] + workspace.step * 5e2,
    )
    ax.imshow(
        np.where(workspace.mask, 1.0, np.nan),
        origin="lower",
        extent=extent,
        cmap="Blues",
        vmin=0,
        vmax=1.6,
        interpolation="nearest",
        zorder=1,
    )
    _draw_base(ax, geometry)
    region_x = [x_mm[0], x_mm[-1], x_mm[-1], x_mm[0], x_mm[0]]
    region_y = [y_mm[0], y_mm[0], y_mm[-1], y_mm[-1], y_mm[0]]
    ax.plot(region_x, region_y, ":", color="0.5", lw=1, label="scanned region")
    if loci_mode is not None:
        angle = np.linspace(0, 2 * math.pi, 721)
        for k, circle in enumerate(type1_circles(workspace.alpha, geometry)):
            ax.plot(
                (circle.centre[0] + circle.radius * np.cos(angle)) * 1e3,
                (circle.centre[1] + circle.radius * np.sin(angle)) * 1e3,
                color=_LEG_COLOURS[circle.leg],
                lw=0.8,
                ls="--" if circle.kind == "folded" else "-",
                label="Type I (leg stretched / folded)" if k == 0 else None,
                zorder=2,
            )
        det = type2_grid(workspace.x, workspace.y, workspace.alpha, loci_mode, geometry)
        ax.contour(x_mm, y_mm, det, levels=[0.0], colors="k", linewidths=1.5, zorder=3)
        ax.plot([], [], "k-", lw=1.5, label=f"Type II, mode {WORKING_MODES[mode_index(loci_mode)]}")
    ax.set_xlim(min(extent[0], -20), max(extent[1], 520))
    ax.set_ylim(min(extent[2], -20), max(extent[3], 450))
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    restricted = "" if workspace.mode is None else f", mode {WORKING_MODES[workspace.mode]}"
    ax.set_title(
        f"Constant-orientation workspace α = {math.degrees(workspace.alpha):.1f}°{restricted}: "
        f"{workspace.area_mm2:.0f} mm² (step {workspace.step * 1e3:g} mm)",
        fontsize=10,
    )
    ax.legend(loc="upper right", fontsize=8)
    return save_figure(fig, path)
