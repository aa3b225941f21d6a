"""Scenario sources: a YAML file or a mapping -> (data, origin, key-path line numbers).

Validation errors are reported as ``file, key path (line N): reason``; the line numbers come
from the YAML node tree, so an error deep in ``segments[3].ta`` points at the line a user edits.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from lynxplan.exceptions import ScenarioError

Location = tuple[int | str, ...]


@dataclass(frozen=True)
class ScenarioSource:
    """A scenario's raw data and where it came from.

    Attributes:
        data: The top-level mapping.
        origin: File path, or ``<mapping>`` for data given in memory.
        lines: Key path -> 1-based line of that key in the file (empty for a mapping).
    """

    data: dict[str, Any]
    origin: str
    lines: dict[Location, int] = field(default_factory=dict)

    def line(self, loc: Location) -> int | None:
        """1-based line of the key path ``loc`` (or of its nearest known parent), or None."""
        for end in range(len(loc), 0, -1):
            line = self.lines.get(tuple(loc[:end]))
            if line is not None:
                return line
        return None

    def error(self, loc: Location, reason: str) -> ScenarioError:
        """A ScenarioError naming this source, the key path ``loc``, its line and ``reason``."""
        return ScenarioError(self.origin, format_location(loc), reason, self.line(loc))


def format_location(loc: Location) -> str:
    """Location tuple -> key path such as ``segments[3].ta``."""
    path = ""
    for part in loc:
        if isinstance(part, int):
            path += f"[{part}]"
        else:
            path += f".{part}" if path else str(part)
    return path


def _line_map(node: yaml.Node, path: Location, lines: dict[Location, int], seen: set[int]) -> None:
    if id(node) in seen:  # an alias: its lines are those of the anchor
        return
    seen.add(id(node))
    if isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            child = (*path, str(key_node.value))
            lines.setdefault(child, key_node.start_mark.line + 1)
            _line_map(value_node, child, lines, seen)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            lines.setdefault((*path, i), item.start_mark.line + 1)
            _line_map(item, (*path, i), lines, seen)


def read_yaml_file(path: Path) -> ScenarioSource:
    """Read a YAML scenario file (safe loader, unique keys) with its key-path line numbers.

    Raises:
        ScenarioError: naming the file (and line) on any problem.
    """
    from lynxplan.yamlio import read_yaml_document  # the one hardened reader (issue 12)

    data, node = read_yaml_document(path)
    lines: dict[Location, int] = {}
    _line_map(node, (), lines, set())
    return ScenarioSource(data, str(path), lines)


def read_source(source: str | Path | Mapping[str, Any]) -> ScenarioSource:
    """A scenario given as a file path or as an in-memory mapping."""
    if isinstance(source, Mapping):
        return ScenarioSource(dict(source), "<mapping>")
    return read_yaml_file(Path(source))
