"""Tasks: selections of rows of the extended tool Jacobian (see
:mod:`lynxplan.singularity.measures`)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from lynxplan.exceptions import TaskError

#: Names of the rows of the extended Jacobian, in order.
ROW_NAMES = ("vx", "vy", "vz", "wx", "wy", "wz", "pitch", "roll")

#: Named tasks -> row indices into :data:`ROW_NAMES`.
NAMED_TASKS: dict[str, tuple[int, ...]] = {
    "position": (0, 1, 2),
    "position_pitch": (0, 1, 2, 6),
    "position_pitch_roll": (0, 1, 2, 6, 7),
}


@dataclass(frozen=True)
class Task:
    """A selection of rows of the extended tool Jacobian.

    Attributes:
        name: Task name (a key of :data:`NAMED_TASKS`, or the row names joined by ``+``).
        rows: Row indices into :data:`ROW_NAMES`, distinct, 1 to 5 of them.
    """

    name: str
    rows: tuple[int, ...]

    @property
    def size(self) -> int:
        """Number of task rows."""
        return len(self.rows)

    @property
    def row_names(self) -> tuple[str, ...]:
        """Names of the selected rows."""
        return tuple(ROW_NAMES[i] for i in self.rows)

    @property
    def rows_array(self) -> np.ndarray:
        """Row indices as an int64 array (for the kernels)."""
        return np.array(self.rows, dtype=np.int64)


def make_task(spec: str | Task | Sequence[str | int]) -> Task:
    """A task from a name (``"position"``, ``"position_pitch"``, ...) or a row selection.

    Args:
        spec: A task name, a Task, or a sequence of row names/indices (see :data:`ROW_NAMES`).

    Raises:
        TaskError: unknown name or row, repeated rows, or more than 5 or no rows.
    """
    if isinstance(spec, Task):
        return spec
    if isinstance(spec, str):
        if spec not in NAMED_TASKS:
            raise TaskError(spec, f"valid names: {', '.join(NAMED_TASKS)}, or a list of rows")
        return Task(spec, NAMED_TASKS[spec])
    rows: list[int] = []
    for item in spec:
        if isinstance(item, str) and item in ROW_NAMES:
            rows.append(ROW_NAMES.index(item))
        elif isinstance(item, (int, np.integer)) and not isinstance(item, bool) and 0 <= item < 8:
            rows.append(int(item))
        else:
            raise TaskError(str(item), f"unknown task row; valid rows: {', '.join(ROW_NAMES)}")
    if not rows or len(rows) > 5 or len(set(rows)) != len(rows):
        raise TaskError(str(list(spec)), "a task needs 1 to 5 distinct rows (the arm has 5 joints)")
    for name, named_rows in NAMED_TASKS.items():
        if tuple(rows) == named_rows:
            return Task(name, named_rows)
    return Task("+".join(ROW_NAMES[i] for i in rows), tuple(rows))
