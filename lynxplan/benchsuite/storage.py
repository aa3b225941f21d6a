"""Storing SmallArmBench: one compressed ``.npz`` per robot, and any problem as a ``plan`` file.

A suite file holds flat arrays (no pickled objects): per problem its family index, index,
attempt, start and goal, and the slice of the box arrays that is its scene; a JSON header names
the robot, the seed, the families and the generator's settings. The shipped files live in
``scenarios/benchsuite/<robot>.npz`` (package data, see :mod:`lynxplan.shipped`).
"""

from __future__ import annotations

import io
import json
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.benchsuite.families import FAMILIES
from lynxplan.benchsuite.problem import Problem, yaw_rotation
from lynxplan.exceptions import InputError

#: Version of the file layout.
FORMAT = 1
#: Folder of the shipped suite files, below ``scenarios/``.
SHIPPED_FOLDER = "benchsuite"


def suite_bytes(problems: Sequence[Problem], header: dict[str, Any]) -> bytes:
    """The ``.npz`` bytes of one robot's problems (same problems, same bytes)."""
    if not problems:
        raise InputError("a suite file needs at least one problem")
    counts = [len(p.names) for p in problems]
    arrays = {
        "family": np.array([FAMILIES.index(p.family) for p in problems], dtype=np.int8),
        "index": np.array([p.index for p in problems], dtype=np.int32),
        "attempt": np.array([p.attempt for p in problems], dtype=np.int32),
        "start": np.stack([p.start for p in problems]),
        "goal": np.stack([p.goal for p in problems]),
        "box_offset": np.concatenate(([0], np.cumsum(counts))).astype(np.int32),
        "box_name": np.array([n for p in problems for n in p.names], dtype="U24"),
        "box_centre": np.concatenate([p.centres for p in problems]),
        "box_size": np.concatenate([p.sizes for p in problems]),
        "box_yaw": np.concatenate([p.yaws for p in problems]),
        "header": np.array(json.dumps({**header, "format": FORMAT, "families": FAMILIES,
                                       "robot": problems[0].robot}, sort_keys=True)),
    }  # fmt: skip
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)  # type: ignore[arg-type]
    return buffer.getvalue()


def save_suite(path: Path, problems: Sequence[Problem], header: dict[str, Any]) -> None:
    """Write a suite file atomically (a temporary file renamed over ``path``)."""
    data = suite_bytes(problems, header)
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.NamedTemporaryFile(dir=path.parent, suffix=".tmp", delete=False) as out:
        out.write(data)
    os.chmod(out.name, 0o644)  # a shipped file: readable by all (the temporary file is 0600)
    os.replace(out.name, path)


def load_suite(path: Path) -> tuple[list[Problem], dict[str, Any]]:
    """The problems and the header of a suite file.

    Raises:
        InputError: not a suite file (the path and what is wrong).
    """
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: data[k] for k in data.files}
        header: dict[str, Any] = json.loads(str(arrays["header"]))
    except (OSError, ValueError, KeyError) as error:
        raise InputError(f"{path}: not a SmallArmBench suite file ({error})") from error
    if header.get("format") != FORMAT:
        found = header.get("format")
        raise InputError(f"{path}: suite format {found!r}; this lynxplan reads format {FORMAT}")
    families, robot, offsets = header["families"], header["robot"], arrays["box_offset"]
    problems = []
    for k in range(len(arrays["family"])):
        boxes = slice(int(offsets[k]), int(offsets[k + 1]))
        problems.append(
            Problem(
                robot,
                families[int(arrays["family"][k])],
                int(arrays["index"][k]),
                int(arrays["attempt"][k]),
                tuple(str(n) for n in arrays["box_name"][boxes]),
                arrays["box_centre"][boxes],
                arrays["box_size"][boxes],
                arrays["box_yaw"][boxes],
                arrays["start"][k],
                arrays["goal"][k],
            )
        )
    return problems, header


def shipped_suite_path(robot: str) -> Path:
    """The shipped suite file of ``robot`` (InputError naming the shipped ones if none)."""
    from lynxplan.shipped import scenario_path

    return scenario_path(f"{SHIPPED_FOLDER}/{robot}.npz")


def load_shipped(robot: str) -> list[Problem]:
    """The shipped problems of ``robot``."""
    return load_suite(shipped_suite_path(robot))[0]


def _floats(values: np.ndarray) -> str:
    """A YAML flow list of floats that read back bit for bit (``repr``)."""
    return "[" + ", ".join(repr(float(v)) for v in np.ravel(values)) + "]"


def scenario_yaml(problem: Problem, *, time_limit: float = 1.0, seed: int = 0) -> str:
    """``problem`` as a ``plan`` scenario (metres, radians, every float written exactly)."""
    lines = [
        f"# SmallArmBench {problem.name}: family {problem.family}, generator attempt "
        f"{problem.attempt}",
        "kind: plan",
        f"name: {problem.name}",
        "units: {length: m, angle: rad}",
        f"robot: {{name: {problem.robot}}}",
        "obstacles:",
    ]
    for name, centre, size, yaw in zip(
        problem.names, problem.centres, problem.sizes, problem.yaws, strict=True
    ):
        rotation = yaw_rotation(float(yaw))
        rows = ", ".join(_floats(row) for row in rotation)
        lines.append(
            f"  - {{name: {name}, type: box, centre: {_floats(centre)}, size: {_floats(size)}, "
            f"rotation: [{rows}]}}"
        )
    lines += [
        f"start: {_floats(problem.start)}",
        f"goal: {{q: {_floats(problem.goal)}}}",
        f"planner: {{seed: {seed}, time_limit: {time_limit!r}}}",
        "expect:",
        "  within_limits: true",
        "",
    ]
    return "\n".join(lines)
