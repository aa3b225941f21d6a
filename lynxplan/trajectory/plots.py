"""Trajectory figures (matplotlib, Agg backend, PNG): the report's q2(t) and x(t), durations."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lynxplan._plotting import pyplot, save_figure
from lynxplan.trajectory.plan import Plan, PlanSamples
from lynxplan.trajectory.retime import METHODS, PlanComparison, SegmentComparison

_STYLE = {
    "lspb": ("LSPB (scenario timing)", "-"),
    "lspb_auto": ("LSPB auto-timed", "--"),
    "ruckig": ("ruckig time-optimal", "-."),
    "ruckig_lspb_duration": ("ruckig, LSPB duration", ":"),
    "toppra": ("toppra time-optimal", (0, (5, 1, 1, 1))),
}


def plot_joint_profiles(comparison: SegmentComparison, joint: int, path: Path) -> None:
    """Angle, velocity and acceleration of one joint vs time, one curve per method.

    Args:
        comparison: The segment's comparison (sampled profiles).
        joint: 0-based joint index (1 = q2, the report's figure).
        path: PNG file to write.
    """
    plt = pyplot()
    fig, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
    labels = ("angle [deg]", "velocity [deg/s]", "acceleration [deg/s²]")
    for name in METHODS:
        if name not in comparison.profiles:
            continue
        profile = comparison.profiles[name]
        label, style = _STYLE[name]
        for ax, values in zip(axes, (profile.q, profile.qd, profile.qdd), strict=True):
            ax.plot(profile.t, np.degrees(values[:, joint]), linestyle=style, label=label)
    for ax, label in zip(axes, labels, strict=True):
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time since segment start [s]")
    axes[0].legend(fontsize=8)
    fig.suptitle(f"q{joint + 1}(t), segment {comparison.segment} ({comparison.kind})")
    save_figure(fig, path)


def plot_tool_xyz(plan: Plan, samples: PlanSamples, segment: int, path: Path) -> None:
    """Tool point x, y, z vs time on one segment (the report's x(t) figure), in [mm]."""
    plt = pyplot()
    mask = samples.segment == segment
    t = samples.t[mask] - plan.start_times[segment]
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for ax, axis, name in zip(axes, range(3), "xyz", strict=True):
        ax.plot(t, samples.tool[mask, axis, 3] * 1000.0)
        ax.set_ylabel(f"{name} [mm]")
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time since segment start [s]")
    kind = plan.segments[segment].kind
    fig.suptitle(f"tool point, segment {segment} ({kind})")
    save_figure(fig, path)


def plot_durations(comparison: PlanComparison, path: Path) -> None:
    """Grouped bar chart of each segment's duration per method."""
    plt = pyplot()
    count = len(comparison.segments)
    fig, ax = plt.subplots(figsize=(max(6.0, 0.8 * count + 2), 4.5))
    width = 0.8 / len(METHODS)
    for k, name in enumerate(METHODS):
        values = [
            c.stats[name].duration if name in c.stats else np.nan for c in comparison.segments
        ]
        ax.bar(np.arange(count) + (k - 2) * width, values, width, label=_STYLE[name][0])
    ax.set_xticks(np.arange(count))
    ax.set_xticklabels([f"{c.segment}\n{c.kind}" for c in comparison.segments], fontsize=8)
    ax.set_ylabel("duration [s]")
    ax.set_xlabel("segment")
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("segment durations per time-parameterisation")
    save_figure(fig, path)
