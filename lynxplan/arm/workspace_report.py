"""Workspace outputs: PNG plots (matplotlib), an interactive HTML view, workspace.json.

matplotlib is imported inside the functions so that the core imports fast.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.arm.workspace import WorkspaceEstimate
from lynxplan.units import length_factor

_PLOT_POINTS = 60_000  # points drawn in scatter plots


def workspace_summary(
    estimate: WorkspaceEstimate, report_points: np.ndarray | None, length_unit: str
) -> dict[str, Any]:
    """JSON-ready summary. Lengths in ``length_unit``, volumes in its cube (also in m^3)."""
    scale = length_factor(length_unit)
    summary: dict[str, Any] = {
        "units": {"length": length_unit, "volume": f"{length_unit}^3"},
        "samples": estimate.samples,
        "volume": estimate.volume_revolution / scale**3,
        "volume_m3": estimate.volume_revolution,
        "volume_method": "revolution of the (r, z) region over the q1 range, midpoint rule",
        "grid_cell": estimate.envelope.cell / scale,
        "volume_voxels": estimate.volume_voxels / scale**3,
        "voxel_size": estimate.voxel_size / scale,
        "max_reach": estimate.max_reach / scale,
        "z_min": estimate.z_range[0] / scale,
        "z_max": estimate.z_range[1] / scale,
    }
    if report_points is not None:
        summary["report_grid_points"] = int(report_points.shape[0])
    return summary


def write_json(summary: dict[str, Any], path: Path) -> None:
    """Write the summary as indented JSON."""
    path.write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")


def _subsample(points: np.ndarray, count: int) -> np.ndarray:
    if points.shape[0] <= count:
        return points
    index = np.random.default_rng(0).choice(points.shape[0], count, replace=False)
    return points[index]


def plot_workspace(
    estimate: WorkspaceEstimate,
    report_points: np.ndarray | None,
    out_dir: Path,
    length_unit: str = "in",
) -> list[Path]:
    """Write workspace_3d.png, workspace_projections.png and workspace_section.png."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scale = length_factor(length_unit)
    cloud = (
        _subsample(report_points if report_points is not None else estimate.positions, _PLOT_POINTS)
        / scale
    )
    colour = cloud[:, 2]
    paths = []

    fig = plt.figure(figsize=(7, 6))
    ax = fig.add_subplot(projection="3d")
    ax.scatter(cloud[:, 0], cloud[:, 1], cloud[:, 2], s=0.3, c=colour, cmap="viridis")
    ax.set(
        xlabel=f"x [{length_unit}]",
        ylabel=f"y [{length_unit}]",
        zlabel=f"z [{length_unit}]",
        title="Tool-point workspace (3-D)",
    )
    ax.set_box_aspect((2, 1, 1.2))
    paths.append(out_dir / "workspace_3d.png")
    fig.savefig(paths[-1], dpi=110, bbox_inches="tight")
    plt.close(fig)

    fig, axes = plt.subplots(1, 3, figsize=(15, 5))
    views = (
        ("x", "y", 0, 1, "in Z (x-y)"),
        ("x", "z", 0, 2, "in Y (x-z)"),
        ("y", "z", 1, 2, "in X (y-z)"),
    )
    for ax, (h, v, i, j, title) in zip(axes, views, strict=True):
        ax.scatter(cloud[:, i], cloud[:, j], s=0.2, c=colour, cmap="viridis")
        ax.set(
            xlabel=f"{h} [{length_unit}]",
            ylabel=f"{v} [{length_unit}]",
            title=title,
            aspect="equal",
        )
        ax.grid(alpha=0.3)
    paths.append(out_dir / "workspace_projections.png")
    fig.savefig(paths[-1], dpi=110, bbox_inches="tight")
    plt.close(fig)

    env = estimate.envelope
    fig, ax = plt.subplots(figsize=(7, 7))
    ax.pcolormesh(
        env.r_edges / scale,
        env.z_edges / scale,
        env.occupied,
        cmap="Blues",
        shading="flat",
        vmin=0,
        vmax=1.5,
    )
    ax.contour(
        0.5 * (env.r_edges[1:] + env.r_edges[:-1]) / scale,
        0.5 * (env.z_edges[1:] + env.z_edges[:-1]) / scale,
        env.occupied.astype(float),
        levels=[0.5],
        colors="navy",
        linewidths=1.2,
    )
    ax.plot([0], [0], "k^", label="shoulder")
    ax.set(
        xlabel=f"radial distance [{length_unit}]",
        ylabel=f"height z [{length_unit}]",
        title=f"Cross-section: reach envelope, volume {estimate.volume_revolution * 1e3:.1f} L "
        f"(cell {env.cell * 1e3:g} mm)",
        aspect="equal",
    )
    ax.legend(loc="lower right")
    ax.grid(alpha=0.3)
    paths.append(out_dir / "workspace_section.png")
    fig.savefig(paths[-1], dpi=110, bbox_inches="tight")
    plt.close(fig)
    return paths


_HTML_TEMPLATE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>lynxplan workspace</title>
<style>body{margin:0;font-family:sans-serif;background:#fff}canvas{display:block}
#info{position:absolute;top:8px;left:10px;font-size:13px;color:#222}</style></head>
<body><div id="info">lynxplan workspace: __COUNT__ tool points, lengths in __UNIT__.
Drag to rotate, wheel to zoom.</div><canvas id="c"></canvas>
<script>
const P = __POINTS__;
const cv = document.getElementById('c'), g = cv.getContext('2d');
let yaw = 0.8, pitch = 0.5, zoom = 1.0, drag = null;
function resize(){ cv.width = innerWidth; cv.height = innerHeight; draw(); }
function draw(){
  g.fillStyle = '#fff'; g.fillRect(0, 0, cv.width, cv.height);
  const s = zoom * Math.min(cv.width, cv.height) / (2.4 * __EXTENT__);
  const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
  for (let i = 0; i < P.length; i += 3) {
    const x = P[i], y = P[i+1], z = P[i+2];
    const u = cy * x - sy * y, w = sy * x + cy * y;
    const v = cp * z - sp * w;
    const t = (z + __EXTENT__) / (2 * __EXTENT__);
    const red = Math.round(40 + 200 * t), green = Math.round(90 + 80 * (1 - t));
    g.fillStyle = `rgb(${red},${green},${Math.round(200 - 150 * t)})`;
    g.fillRect(cv.width / 2 + s * u, cv.height / 2 - s * v, 1.5, 1.5);
  }
}
cv.onmousedown = e => drag = [e.clientX, e.clientY];
onmouseup = () => drag = null;
onmousemove = e => { if (!drag) return; yaw -= (e.clientX - drag[0]) * 0.01;
  pitch += (e.clientY - drag[1]) * 0.01; drag = [e.clientX, e.clientY]; draw(); };
cv.onwheel = e => { zoom *= e.deltaY < 0 ? 1.1 : 0.9; draw(); e.preventDefault(); };
onresize = resize; resize();
</script></body></html>
"""


def write_html(points: np.ndarray, path: Path, length_unit: str = "in") -> None:
    """Self-contained interactive HTML point cloud (no network, no external scripts)."""
    cloud = _subsample(points, _PLOT_POINTS) / length_factor(length_unit)
    extent = float(np.abs(cloud).max()) if cloud.size else 1.0
    flat = ",".join(f"{v:.3f}" for v in cloud.ravel())
    html = (
        _HTML_TEMPLATE.replace("__POINTS__", f"[{flat}]")
        .replace("__UNIT__", length_unit)
        .replace("__COUNT__", f"{cloud.shape[0]:,}")
        .replace("__EXTENT__", f"{extent:.3f}")
    )
    path.write_text(html, encoding="utf-8")
