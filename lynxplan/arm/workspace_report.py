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


def _save(fig: Any, path: Path) -> None:
    """Write ``fig`` as PNG; its titles and axis labels (with their units) also go into the
    PNG's ``Description`` text chunk, so the file says what it shows in words too."""
    texts = []
    for ax in fig.axes:
        labels = [ax.get_title(), ax.get_xlabel(), ax.get_ylabel()]
        if hasattr(ax, "get_zlabel"):
            labels.append(ax.get_zlabel())
        texts.append(", ".join(t for t in labels if t))
    fig.savefig(path, dpi=110, bbox_inches="tight", metadata={"Description": " | ".join(texts)})


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
        title=f"Tool-point workspace (3-D), lengths in {length_unit}",
    )
    ax.set_box_aspect((2, 1, 1.2))
    paths.append(out_dir / "workspace_3d.png")
    _save(fig, paths[-1])
    plt.close(fig)

    fig, axes = plt.subplots(1, 3, figsize=(15, 5))
    views = (
        ("x", "y", 0, 1, "top view: projection onto the x-y plane"),
        ("x", "z", 0, 2, "front view: projection onto the x-z plane"),
        ("y", "z", 1, 2, "side view: projection onto the y-z plane"),
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
    _save(fig, paths[-1])
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
        title=f"Cross-section: reach envelope, volume "
        f"{estimate.volume_revolution / scale**3:.4g} {length_unit}^3 "
        f"(cell {env.cell / scale:.3g} {length_unit})",
        aspect="equal",
    )
    ax.legend(loc="lower right")
    ax.grid(alpha=0.3)
    paths.append(out_dir / "workspace_section.png")
    _save(fig, paths[-1])
    plt.close(fig)
    return paths


_HTML_TEMPLATE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>lynxplan workspace</title>
<style>body{margin:0;font-family:sans-serif;background:#fff}canvas{display:block}
#info{position:absolute;top:8px;left:10px;font-size:13px;color:#222}</style></head>
<body><div id="info">lynxplan workspace: __COUNT__ tool points coloured by height z, lengths in
__UNIT__; the robot (dark) at the middle of its joint ranges. Drag to rotate, wheel to zoom.</div>
<canvas id="c"></canvas>
<script>
const P = __POINTS__;
const ROBOT = __ROBOT__;
const E = __EXTENT__, ZLO = __ZLO__, ZHI = __ZHI__, UNIT = "__UNIT__";
const VIRIDIS = [[68,1,84],[59,82,139],[33,145,140],[94,201,98],[253,231,37]];
const cv = document.getElementById('c'), g = cv.getContext('2d');
let yaw = 0.8, pitch = 0.5, zoom = 1.0, drag = null;
function colour(z) {
  const t = Math.min(Math.max((z - ZLO) / Math.max(ZHI - ZLO, 1e-9), 0), 1) * 4;
  const i = Math.min(Math.floor(t), 3), f = t - i, a = VIRIDIS[i], b = VIRIDIS[i + 1];
  return `rgb(${a.map((c, k) => Math.round(c + f * (b[k] - c))).join(',')})`;
}
function project(x, y, z, s) {
  const cy = Math.cos(yaw), sy = Math.sin(yaw), cp = Math.cos(pitch), sp = Math.sin(pitch);
  const u = cy * x - sy * y, w = sy * x + cy * y;
  return [cv.width / 2 + s * u, cv.height / 2 - s * (cp * z - sp * w)];
}
function line(a, b, s, style, width) {
  const p = project(...a, s), q = project(...b, s);
  g.strokeStyle = style; g.lineWidth = width;
  g.beginPath(); g.moveTo(...p); g.lineTo(...q); g.stroke();
}
function resize(){ cv.width = innerWidth; cv.height = innerHeight; draw(); }
function draw(){
  g.fillStyle = '#fff'; g.fillRect(0, 0, cv.width, cv.height);
  const s = zoom * Math.min(cv.width, cv.height) / (2.4 * E);
  for (let i = 0; i < P.length; i += 3) {
    const p = project(P[i], P[i+1], P[i+2], s);
    g.fillStyle = colour(P[i+2]);
    g.fillRect(p[0], p[1], 1.5, 1.5);
  }
  const axes = [[[E, 0, 0], '#d62728', 'x'], [[0, E, 0], '#2ca02c', 'y'],
                [[0, 0, E], '#1f77b4', 'z']];
  g.font = '14px sans-serif';
  for (const [end, style, name] of axes) {
    line([0, 0, 0], end, s, style, 2);
    const p = project(...end, s);
    const label = `${name} (${E.toFixed(1)} ${UNIT})`;
    g.strokeStyle = '#fff'; g.lineWidth = 4; g.strokeText(label, p[0] + 4, p[1] - 4);
    g.fillStyle = style; g.fillText(label, p[0] + 4, p[1] - 4);
  }
  for (let i = 0; i + 1 < ROBOT.length; i++) line(ROBOT[i], ROBOT[i + 1], s, '#222', 6);
  g.fillStyle = '#000';
  for (const joint of ROBOT) {
    const p = project(...joint, s);
    g.beginPath(); g.arc(p[0], p[1], 4, 0, 2 * Math.PI); g.fill();
  }
  const x0 = cv.width - 40, top = 60, height = Math.min(240, cv.height - 120);
  for (let k = 0; k < height; k++) {
    g.fillStyle = colour(ZHI - (ZHI - ZLO) * k / height); g.fillRect(x0, top + k, 16, 1);
  }
  g.fillStyle = '#222'; g.textAlign = 'right';
  g.fillText(`z ${ZHI.toFixed(1)} ${UNIT}`, x0 - 4, top + 10);
  g.fillText(`${ZLO.toFixed(1)}`, x0 - 4, top + height);
  g.textAlign = 'left';
}
cv.onmousedown = e => drag = [e.clientX, e.clientY];
onmouseup = () => drag = null;
onmousemove = e => { if (!drag) return; yaw -= (e.clientX - drag[0]) * 0.01;
  pitch += (e.clientY - drag[1]) * 0.01; drag = [e.clientX, e.clientY]; draw(); };
cv.onwheel = e => { zoom *= e.deltaY < 0 ? 1.1 : 0.9; draw(); e.preventDefault(); };
onresize = resize; resize();
</script></body></html>
"""


def reference_skeleton(robot: Any) -> np.ndarray:
    """The robot drawn as a polyline: its joint origins and tool point at the middle of its
    joint ranges, shape (K, 3), in [m] (repeated points dropped)."""
    import pinocchio as pin

    model = robot.model
    lower = np.nan_to_num(np.asarray(model.lowerPositionLimit, float), posinf=0.0, neginf=0.0)
    upper = np.nan_to_num(np.asarray(model.upperPositionLimit, float), posinf=0.0, neginf=0.0)
    q = 0.5 * (np.clip(lower, -np.pi, np.pi) + np.clip(upper, -np.pi, np.pi))
    data = model.createData()
    pin.forwardKinematics(model, data, q)
    points = [np.zeros(3)] + [data.oMi[j].translation.copy() for j in range(1, model.njoints)]
    points.append(np.asarray(robot.fk(q))[:3, 3])
    kept = [points[0]]
    for point in points[1:]:
        if np.linalg.norm(point - kept[-1]) > 1e-6:
            kept.append(point)
    return np.array(kept)


def write_html(
    points: np.ndarray, path: Path, length_unit: str = "in", skeleton: np.ndarray | None = None
) -> None:
    """Self-contained interactive HTML point cloud (no network, no external scripts): the points
    coloured by height with a colour bar, the x, y, z axes at the base, and the robot as a
    polyline (``skeleton`` (K, 3) [m], see :func:`reference_skeleton`) when given."""
    scale = length_factor(length_unit)
    cloud = _subsample(points, _PLOT_POINTS) / scale
    robot = np.zeros((0, 3)) if skeleton is None else np.asarray(skeleton, float) / scale
    every = np.vstack([cloud, robot]) if cloud.size else robot
    extent = float(np.abs(every).max()) if every.size else 1.0
    z = cloud[:, 2] if cloud.size else np.zeros(1)
    flat = ",".join(f"{v:.3f}" for v in cloud.ravel())
    html = (
        _HTML_TEMPLATE.replace("__POINTS__", f"[{flat}]")
        .replace("__ROBOT__", json.dumps(np.round(robot, 4).tolist()))
        .replace("__UNIT__", length_unit)
        .replace("__COUNT__", f"{cloud.shape[0]:,}")
        .replace("__EXTENT__", f"{extent:.3f}")
        .replace("__ZLO__", f"{float(z.min()):.4f}")
        .replace("__ZHI__", f"{float(z.max()):.4f}")
    )
    path.write_text(html, encoding="utf-8")
