"""matplotlib for the figure writers: loaded on first use (the core imports fast), always with
the non-interactive Agg backend, and one way to write a figure out."""

from __future__ import annotations

from pathlib import Path
from typing import Any


def pyplot() -> Any:
    """``matplotlib.pyplot`` on the Agg backend (files only, no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig: Any, path: str | Path, dpi: int = 110) -> Path:
    """Lay ``fig`` out tightly, write it to ``path`` at ``dpi`` [dots/inch] and close it.

    Returns:
        ``path``, as a :class:`~pathlib.Path`.
    """
    path = Path(path)
    fig.tight_layout()
    fig.savefig(path, dpi=dpi)
    pyplot().close(fig)
    return path
