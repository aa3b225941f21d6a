"""The task as a self-contained meshcat HTML file (arm, obstacles, writing plane, pen path)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    from lynxplan.task.run import TaskResult
    from lynxplan.task.schema import Scenario

#: The pen path drawn in the HTML is sub-sampled to this rate, in [Hz] (smaller file).
PATH_RATE = 100.0


def write_html(scenario: Scenario, result: TaskResult, out_path: Path) -> Path:
    """Export the animated task (``lynxplan.viz.export_html``) to ``out_path``."""
    from lynxplan.viz import export_html

    samples, setup = result.samples, result.setup
    step = max(1, round(scenario.sample_rate / PATH_RATE))
    index = np.unique(np.append(np.arange(0, len(samples.t), step), len(samples.t) - 1))
    kinds = [segment.kind for segment in setup.plan.segments]
    plane = setup.writing_plane
    return export_html(
        setup.arm,
        samples.q,
        samples.t,
        out_path,
        path=samples.tool[index, :3, 3],
        motion=[kinds[s] for s in samples.segment[index].tolist()],
        obstacles=setup.obstacles,
        plane=plane,
    )
