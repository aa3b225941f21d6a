"""Clearance plot of a planned trajectory (matplotlib, imported on use)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.units import length_factor


def plot_clearance(
    trajectory: Any,
    clearances: np.ndarray,
    out_path: Path,
    *,
    length_unit: str = "m",
    closest: tuple[str, str] | None = None,
) -> Path:
    """Exact smallest distance at every sample vs time, the required clearance as a line and the
    worst sample marked.

    Args:
        trajectory: A :class:`lynxplan.planning.PlannedTrajectory`.
        clearances: Exact smallest distance per sample, shape (N,), in [m].
        out_path: PNG file to write.
        length_unit: Unit of the vertical axis (``m``, ``mm``, ``in``).
        closest: (link, obstacle) of the worst sample, for the title (default: the
            verification's closest pair).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    scale = length_factor(length_unit)
    t = np.asarray(trajectory.t)
    values = np.asarray(clearances) / scale
    required = trajectory.options.clearance / scale
    worst = int(np.argmin(values))
    fig, ax = plt.subplots(figsize=(8, 4))
    ax.plot(t, values, color="tab:blue", lw=1.5, label="exact min distance per sample (coal)")
    ax.axhline(
        required, color="k", ls="--", lw=1, label=f"required clearance {required:.4g} {length_unit}"
    )
    ax.plot(
        t[worst],
        values[worst],
        "o",
        color="tab:red",
        label=f"worst sample: {values[worst]:.4g} {length_unit} at {t[worst]:.3f} s",
    )
    if closest is None:
        record = trajectory.verification.min_clearance
        closest = (record.link, record.obstacle)
    ax.set_title(f"clearance along the planned path (closest: {closest[0]} to {closest[1]})")
    ax.set_xlabel("time [s]")
    ax.set_ylabel(f"clearance [{length_unit}]")
    ax.set_ylim(bottom=0.0)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    fig.tight_layout()
    fig.savefig(out_path, dpi=110)
    plt.close(fig)
    return out_path
