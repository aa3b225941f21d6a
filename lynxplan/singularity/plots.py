"""PNG plots of resolved-rate runs: m(q), joint speeds, tracking error vs time, tool paths.

matplotlib is imported inside the functions (Agg backend), never at module import.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lynxplan._plotting import pyplot, save_figure
from lynxplan.singularity.resolved_rate import (
    STRATEGY_NAMES,
    ResolvedRateProblem,
    ResolvedRateRun,
    Strategy,
)

COLORS = {
    Strategy.PINV: "tab:red",
    Strategy.SPEED_LIMIT: "tab:blue",
    Strategy.DLS: "tab:green",
    Strategy.TR: "tab:purple",
}


def plot_runs(
    runs: dict[Strategy, ResolvedRateRun], problem: ResolvedRateProblem, out_dir: Path
) -> list[Path]:
    """Write manipulability.png, joint_speeds.png, tracking_error.png, tool_paths.png."""
    out_dir.mkdir(parents=True, exist_ok=True)
    return [
        plot_manipulability(runs, problem, out_dir / "manipulability.png"),
        plot_joint_speeds(runs, problem, out_dir / "joint_speeds.png"),
        plot_tracking_error(runs, out_dir / "tracking_error.png"),
        plot_tool_paths(runs, out_dir / "tool_paths.png"),
    ]


def plot_manipulability(
    runs: dict[Strategy, ResolvedRateRun], problem: ResolvedRateProblem, path: Path
) -> Path:
    """m(q(t)) per strategy (log scale) with the TR thresholds m_bar and m_bar + sigma."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for strategy, run in runs.items():
        ax.semilogy(run.t, np.maximum(run.m, 1e-12), color=COLORS[strategy], label=_name(strategy))
    p = problem.parameters
    ax.axhline(p.m_bar, color="k", ls="--", lw=0.8, label="m̄")
    ax.axhline(p.m_bar + p.sigma, color="k", ls=":", lw=0.8, label="m̄ + σ")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"manipulability m(q), task {problem.task.name}")
    ax.set_title("Manipulability along the path")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="lower right")
    return save_figure(fig, path)


def plot_joint_speeds(
    runs: dict[Strategy, ResolvedRateRun], problem: ResolvedRateProblem, path: Path
) -> Path:
    """Joint speeds vs time, one panel per strategy, with the speed limits."""
    plt = pyplot()
    fig, axes = plt.subplots(len(runs), 1, figsize=(8, 2.4 * len(runs)), sharex=True)
    for ax, (strategy, run) in zip(np.atleast_1d(axes), runs.items(), strict=True):
        for joint in range(5):
            ax.plot(run.t, run.qd[:, joint], lw=1.0, label=f"q{joint + 1}")
        limit = float(np.max(problem.velocity_limits))
        ax.axhline(limit, color="k", ls="--", lw=0.8)
        ax.axhline(-limit, color="k", ls="--", lw=0.8)
        peak = np.max(np.abs(run.qd))
        ax.set_title(f"{_name(strategy)}: peak {peak:.2f} rad/s (limit {limit:.2f})", fontsize=9)
        ax.set_ylabel("[rad/s]")
        ax.grid(True, alpha=0.3)
    np.atleast_1d(axes)[0].legend(loc="upper right", ncol=5, fontsize=7)
    np.atleast_1d(axes)[-1].set_xlabel("time [s]")
    return save_figure(fig, path)


def plot_tracking_error(runs: dict[Strategy, ResolvedRateRun], path: Path) -> Path:
    """Tool-point distance from the reference vs time (log scale), in [mm]."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for strategy, run in runs.items():
        error = np.maximum(run.position_error * 1e3, 1e-9)
        ax.semilogy(run.t, error, color=COLORS[strategy], label=_name(strategy))
    ax.set_xlabel("time [s]")
    ax.set_ylabel("tracking error [mm]")
    ax.set_title("Distance of the tool point from the reference")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    return save_figure(fig, path)


def plot_tool_paths(runs: dict[Strategy, ResolvedRateRun], path: Path) -> Path:
    """Tool paths seen from above (x-y) and from the side (x-z), with the reference, in [mm]."""
    plt = pyplot()
    fig, (top, side) = plt.subplots(1, 2, figsize=(11, 4.8))
    reference = next(iter(runs.values())).x_ref * 1e3
    for ax, (i, j), title in ((top, (0, 1), "top view"), (side, (0, 2), "side view")):
        ax.plot(reference[:, i], reference[:, j], color="k", lw=2.5, alpha=0.3, label="reference")
        for strategy, run in runs.items():
            x = run.x * 1e3
            ax.plot(x[:, i], x[:, j], color=COLORS[strategy], lw=1.0, label=_name(strategy))
        ax.set_xlabel("x [mm]")
        ax.set_ylabel("y [mm]" if j == 1 else "z [mm]")
        ax.set_title(title)
        ax.grid(True, alpha=0.3)
    top.plot([0.0], [0.0], "k+", ms=12, mew=2, label="base axis")
    top.set_aspect("equal", adjustable="datalim")
    top.legend(fontsize=8)
    return save_figure(fig, path)


def _name(strategy: Strategy) -> str:
    return STRATEGY_NAMES[strategy]
