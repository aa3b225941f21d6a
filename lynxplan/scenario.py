"""Scenario files: YAML -> validated, frozen scenario objects. No computation here.

A scenario file is a YAML mapping with a ``kind`` key that selects its schema (a pydantic model)
and the function that runs it. Kinds are registered in :data:`KIND_MODULES` and imported lazily,
so reading one kind of scenario does not import the others' dependencies.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, Protocol

import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from lynxplan.exceptions import ScenarioError

#: Scenario kind -> module that defines ``Scenario`` (pydantic model) and ``run``.
KIND_MODULES: dict[str, str] = {
    "workspace": "lynxplan.arm.workspace_scenario",
    "singularity": "lynxplan.singularity.scenario",
    "parallel_ik": "lynxplan.parallel.ik_scenario",
    "parallel_workspace": "lynxplan.parallel.workspace_scenario",
    "trajectory": "lynxplan.trajectory.scenario",
    "task": "lynxplan.task.run",
}


class StrictModel(BaseModel):
    """Base of every scenario schema: unknown keys are errors, values are frozen."""

    model_config = ConfigDict(extra="forbid", frozen=True)


class Units(StrictModel):
    """Units in which a scenario states lengths and angles (converted to SI on load)."""

    length: Literal["m", "mm", "in"] = Field("m", description="Length unit of the file.")
    angle: Literal["rad", "deg"] = Field("rad", description="Angle unit of the file.")


@dataclass(frozen=True)
class Outcome:
    """What running a scenario produced.

    Attributes:
        summary: One paragraph for stdout.
        failed_expectations: Human-readable ``expect:`` entries that did not hold (empty = ok).
    """

    summary: str
    failed_expectations: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        """True when every expectation held."""
        return not self.failed_expectations


class ScenarioKind(Protocol):
    """Interface of a scenario-kind module."""

    Scenario: type[StrictModel]

    def run(self, scenario: Any, out_dir: Path | None, *, quick: bool = False) -> Outcome: ...


def kind_module(kind: str, file: str = "<scenario>") -> ScenarioKind:
    """The module implementing scenario ``kind``; ScenarioError naming valid kinds if unknown."""
    if kind not in KIND_MODULES:
        valid = ", ".join(sorted(KIND_MODULES))
        raise ScenarioError(file, "kind", f"unknown kind {kind!r}; valid kinds: {valid}")
    module: Any = importlib.import_module(KIND_MODULES[kind])
    return module  # type: ignore[no-any-return]


def format_location(loc: tuple[int | str, ...]) -> str:
    """Pydantic error location -> key path such as ``segments[3].ta``."""
    path = ""
    for part in loc:
        if isinstance(part, int):
            path += f"[{part}]"
        else:
            path += f".{part}" if path else str(part)
    return path


class _UniqueKeyLoader(yaml.SafeLoader):
    """Safe loader that rejects a key given twice in one mapping (YAML would keep the last)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)  # type: ignore[no-untyped-call]
            if key in seen:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r}", key_node.start_mark
                )
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


def read_yaml(path: Path) -> dict[str, Any]:
    """Read a YAML mapping with the safe loader; ScenarioError on any problem."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise ScenarioError(str(path), "", f"cannot read file ({exc.strerror})") from exc
    try:
        data = yaml.load(text, Loader=_UniqueKeyLoader)  # noqa: S506 (a SafeLoader subclass)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}" if mark is not None else ""
        raise ScenarioError(str(path), where, f"invalid YAML: {exc}".splitlines()[0]) from exc
    if not isinstance(data, dict):
        raise ScenarioError(str(path), "", "the file must contain a YAML mapping")
    return data


def load_scenario(path: str | Path) -> tuple[ScenarioKind, StrictModel]:
    """Load and validate a scenario file.

    Returns:
        The kind module and the validated, frozen scenario object.

    Raises:
        ScenarioError: naming the file, the key path and the reason.
    """
    path = Path(path)
    data = read_yaml(path)
    kind = data.get("kind")
    if not isinstance(kind, str):
        raise ScenarioError(str(path), "kind", "missing or not a string")
    module = kind_module(kind, str(path))
    try:
        scenario = module.Scenario.model_validate(data)
    except ValidationError as exc:
        first = exc.errors()[0]
        raise ScenarioError(str(path), format_location(first["loc"]), first["msg"]) from exc
    return module, scenario
