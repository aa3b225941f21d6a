"""PNG figures of a task run: the pen path in side and top views (the report's figures 16-17:
straight lines red, free motions blue, obstacles drawn), joint trajectories, clearance vs time.

Lengths are drawn in the scenario's length unit, angles in its angle unit.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from lynxplan._plotting import pyplot, save_figure
from lynxplan.units import angle_factor, length_factor

if TYPE_CHECKING:
    from lynxplan.scenarios.expect import ParsedExpectation
    from lynxplan.task.run import TaskResult
    from lynxplan.task.schema import Scenario

MOTION_COLOURS = {"line": "tab:red", "free": "tab:blue"}
OBSTACLE_COLOUR = "tab:orange"
#: Clearance vs time is evaluated at this rate, in [Hz] (exact distances; the check itself uses
#: every sample).
CLEARANCE_PLOT_RATE = 100.0

#: View name -> (horizontal axis, vertical axis, title).
VIEWS = {
    "side": (1, 2, "side view (y-z plane)"),
    "top": (0, 1, "top view (x-y plane)"),
}


def _obstacle_points(obstacle: Any) -> np.ndarray:
    """Points on the obstacle's surface (corners, or circles), shape (K, 3), in [m]."""
    rotation, centre = np.asarray(obstacle.rotation), np.asarray(obstacle.centre)
    if hasattr(obstacle, "size"):
        signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
        local = signs * np.asarray(obstacle.size) / 2.0
    else:
        angles = np.linspace(0.0, 2.0 * np.pi, 48, endpoint=False)
        circle = np.column_stack((np.cos(angles), np.sin(angles), np.zeros_like(angles)))
        if hasattr(obstacle, "length"):
            rim = circle * obstacle.radius
            half = np.array([0.0, 0.0, obstacle.length / 2.0])
            local = np.vstack((rim + half, rim - half))
        else:  # a sphere: three great circles
            local = obstacle.radius * np.vstack(
                (circle, circle[:, [2, 0, 1]], circle[:, [1, 2, 0]])
            )
    return np.asarray(centre + local @ rotation.T)


def _draw_obstacles(ax: Any, setup: Any, axes: tuple[int, int], scale: float) -> None:
    from matplotlib.patches import Polygon
    from scipy.spatial import ConvexHull

    for obstacle in setup.obstacles:
        points = _obstacle_points(obstacle)[:, list(axes)] / scale
        hull = points[ConvexHull(points).vertices]
        ax.add_patch(Polygon(hull, closed=True, fc=OBSTACLE_COLOUR, ec="k", alpha=0.45, lw=0.8))
        centre = hull.mean(axis=0)
        ax.annotate(obstacle.name, centre, ha="center", va="center", fontsize=7)


def _draw_plane(ax: Any, setup: Any, axes: tuple[int, int], scale: float) -> None:
    plane = setup.writing_plane
    if plane is None:
        return
    u, v = plane.rotation[:, 0], plane.rotation[:, 1]
    corners = np.array(
        [
            plane.point + a * plane.size[0] / 2 * u + b * plane.size[1] / 2 * v
            for a, b in ((-1, -1), (1, -1), (1, 1), (-1, 1))
        ]
    )
    from matplotlib.patches import Polygon

    projected = corners[:, list(axes)] / scale
    ax.add_patch(
        Polygon(
            projected,
            closed=True,
            fc="tab:cyan",
            ec="tab:cyan",
            alpha=0.15,
            lw=1.5,
            label="writing plane",
        )
    )


def plot_task_view(scenario: Scenario, result: TaskResult, view: str, path: Path) -> Path:
    """The pen path in one view (``"side"`` or ``"top"``), lines red, free motions blue."""
    plt = pyplot()

    horizontal, vertical, title = VIEWS[view]
    unit = scenario.units.length
    scale = length_factor(unit)
    setup, samples = result.setup, result.samples
    points = samples.tool[:, :3, 3] / scale
    fig, ax = plt.subplots(figsize=(7, 6))
    _draw_plane(ax, setup, (horizontal, vertical), scale)
    _draw_obstacles(ax, setup, (horizontal, vertical), scale)
    drawn: set[str] = set()
    for i, segment in enumerate(setup.plan.segments):
        mask = samples.segment == i
        label = {"line": "straight line", "free": "free motion"}[segment.kind]
        ax.plot(
            points[mask, horizontal],
            points[mask, vertical],
            color=MOTION_COLOURS[segment.kind],
            lw=1.6,
            label=None if label in drawn else label,
        )
        drawn.add(label)
    waypoint_points: dict[str, np.ndarray] = {}
    for i, (start, end) in enumerate(setup.route):
        mask = np.flatnonzero(samples.segment == i)
        waypoint_points.setdefault(start, points[mask[0]])
        waypoint_points.setdefault(end, points[mask[-1]])
    for name, point in waypoint_points.items():
        ax.plot(point[horizontal], point[vertical], "k.", ms=4)
        ax.annotate(
            name,
            (point[horizontal], point[vertical]),
            fontsize=7,
            xytext=(3, 3),
            textcoords="offset points",
        )
    names = "xyz"
    ax.set_xlabel(f"{names[horizontal]} [{unit}]")
    ax.set_ylabel(f"{names[vertical]} [{unit}]")
    ax.set_title(f"{scenario.name or 'task'}: pen path, {title}")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return save_figure(fig, path, dpi=120)


def _shade_lines(ax: Any, result: TaskResult) -> None:
    starts = result.setup.plan.start_times
    for i, segment in enumerate(result.setup.plan.segments):
        if segment.kind == "line":
            ax.axvspan(starts[i], starts[i] + segment.duration, color="tab:red", alpha=0.07, lw=0)


def plot_joints(scenario: Scenario, result: TaskResult, path: Path) -> Path:
    """Joint angles and speeds vs time (straight-line segments shaded red)."""
    plt = pyplot()

    unit = scenario.units.angle
    scale = angle_factor(unit)
    samples = result.samples
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
    for j in range(samples.q.shape[1]):
        top.plot(samples.t, samples.q[:, j] / scale, lw=1.2, label=f"q{j + 1}")
        bottom.plot(samples.t, samples.qd[:, j] / scale, lw=1.0, label=f"q{j + 1}")
    for ax in (top, bottom):
        _shade_lines(ax, result)
        ax.grid(True, alpha=0.3)
    top.set_ylabel(f"joint angle [{unit}]")
    bottom.set_ylabel(f"joint speed [{unit}/s]")
    bottom.set_xlabel("time [s]")
    top.legend(loc="upper right", fontsize=8, ncol=5)
    top.set_title(f"{scenario.name or 'task'}: joint trajectories (straight lines shaded)")
    return save_figure(fig, path, dpi=120)


def plot_clearance(
    scenario: Scenario,
    result: TaskResult,
    path: Path,
    required: ParsedExpectation | None = None,
) -> Path | None:
    """Clearance to each obstacle vs time: exact distances (coal, minimum over the arm's
    primitives) at 100 Hz, the overall minimum marked, the required clearance as a line."""
    if not result.setup.obstacles:
        return None
    plt = pyplot()

    from lynxplan.collision import clearance_profile

    unit = scenario.units.length
    scale = length_factor(unit)
    samples = result.samples
    step = max(1, round(scenario.sample_rate / CLEARANCE_PLOT_RATE))
    index = np.unique(np.append(np.arange(0, len(samples.t), step), len(samples.t) - 1))
    profile = clearance_profile(result.world, samples.q[index])
    fig, ax = plt.subplots(figsize=(9, 4.5))
    for o, obstacle in enumerate(result.setup.obstacles):
        ax.plot(samples.t[index], profile[:, o] / scale, lw=1.3, label=obstacle.name)
    best = result.collision.min_clearance
    ax.plot(
        best.time,
        best.clearance / scale,
        "kv",
        ms=7,
        label=f"minimum {best.clearance / scale:.4g} {unit} ({best.geometry})",
    )
    if required is not None:
        ax.axhline(
            required.value / scale, color="k", ls="--", lw=1, label=f"required {required.text}"
        )
    _shade_lines(ax, result)
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"clearance [{unit}]")
    ax.set_ylim(bottom=min(0.0, float(profile.min()) / scale))
    ax.set_title(f"{scenario.name or 'task'}: clearance of the arm to each obstacle")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper right", fontsize=8)
    return save_figure(fig, path, dpi=120)


def write_plots(
    scenario: Scenario,
    result: TaskResult,
    out_dir: Path,
    required_clearance: ParsedExpectation | None = None,
) -> list[str]:
    """Write every figure into ``out_dir``; returns the names of the files written."""
    written = [
        plot_task_view(scenario, result, "side", out_dir / "task_side.png"),
        plot_task_view(scenario, result, "top", out_dir / "task_top.png"),
        plot_joints(scenario, result, out_dir / "joints.png"),
    ]
    clearance = plot_clearance(scenario, result, out_dir / "clearance.png", required_clearance)
    return [p.name for p in written + ([clearance] if clearance is not None else [])]
