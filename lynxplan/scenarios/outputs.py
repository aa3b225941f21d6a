"""A run's output folder and the trajectory CSV.

The folder (written all together or not at all, never losing a file lynxplan did not write) is
:mod:`lynxplan.scenarios.folders`; its names are re-exported here.
"""

from __future__ import annotations

import contextlib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.exceptions import ShapeError
from lynxplan.scenarios.folders import MARKER, OutputFolderError, clean_stale, staged_outputs

__all__ = [
    "MARKER",
    "OutputFolderError",
    "artifact_names",
    "clean_stale",
    "csv_rows",
    "staged_outputs",
    "write_samples_csv",
    "write_trajectory_csv",
]


def write_trajectory_csv(
    path: Path,
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    qdd: np.ndarray,
    tool_xyz: np.ndarray | None = None,
) -> None:
    """Write a sampled trajectory as CSV, one row per sample, SI units.

    Header ``t,q1..qn,qd1..qdn,qdd1..qddn`` and, for Cartesian tasks, ``x,y,z`` (tool point);
    readable by ``numpy.loadtxt(path, delimiter=",", skiprows=1)`` and pandas.

    Args:
        path: Output file.
        t: Sample times, shape (N,), in [s].
        q: Joint positions, shape (N, n), in [rad].
        qd: Joint velocities, shape (N, n), in [rad/s].
        qdd: Joint accelerations, shape (N, n), in [rad/s^2].
        tool_xyz: Tool point, shape (N, 3), in [m], or None.
    """
    n = q.shape[1]
    names: list[str] = ["t"]
    columns: list[np.ndarray] = [np.asarray(t, dtype=float)[:, None], q, qd, qdd]
    for prefix in ("q", "qd", "qdd"):
        names += [f"{prefix}{j + 1}" for j in range(n)]
    if tool_xyz is not None:
        names += ["x", "y", "z"]
        columns.append(tool_xyz)
    table = np.hstack(columns)
    with open(path, "w", encoding="ascii", newline="\n") as file:
        file.write(",".join(names) + "\n")
        file.write(csv_rows(table))


def csv_rows(table: np.ndarray) -> str:
    """The rows of ``table`` (N, m) as CSV lines, each value in its shortest exact decimal form.

    Every number reads back to the same float (``float(text) == value``, the repr rule), so a
    reloaded trajectory equals the in-memory one bit for bit. orjson formats the numbers (26,001
    rows of 19 values in ~35 ms; ``numpy.savetxt`` took ~220 ms for a 15-digit format that does
    not round-trip); it writes ``1e-5``, ``1e+20``, ``0.0``. A table holding NaN or infinity,
    which JSON cannot carry, is written with ``repr`` (``nan``, ``inf``).
    """
    values = np.ascontiguousarray(table, dtype=np.float64)
    if values.ndim != 2:
        raise ShapeError("table", "(N, m)", values.shape)
    if values.size == 0:
        return "\n" * int(values.shape[0])
    if not np.isfinite(values).all():
        return "".join(",".join(map(repr, row)) + "\n" for row in values.tolist())
    import orjson

    text: str = orjson.dumps(values, option=orjson.OPT_SERIALIZE_NUMPY).decode("ascii")
    return text[2:-2].replace("],[", "\n") + "\n"


def write_samples_csv(path: Path, samples: Any) -> None:
    """:func:`write_trajectory_csv` of plan samples (``lynxplan.trajectory.PlanSamples``: ``t``,
    ``q``, ``qd``, ``qdd`` and the tool poses ``tool`` (N, 4, 4), whose points are written)."""
    tool = samples.tool[:, :3, 3]
    write_trajectory_csv(path, samples.t, samples.q, samples.qd, samples.qdd, tool)


def artifact_names(out_dir: Path, paths: Sequence[Path | str]) -> list[str]:
    """Paths relative to ``out_dir``, sorted, without duplicates."""
    names = set()
    for p in paths:
        with contextlib.suppress(ValueError):
            names.add(str(Path(p).relative_to(out_dir)) if Path(p).is_absolute() else str(p))
    return sorted(names)
