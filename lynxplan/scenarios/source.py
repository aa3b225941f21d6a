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

#: Largest scenario file read, in bytes (a scenario is a few kB; this bounds memory and time).
MAX_SCENARIO_BYTES = 4 * 1024 * 1024

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


class _UniqueKeyLoader(yaml.SafeLoader):
    """Safe loader that rejects a key given twice in one mapping (YAML would keep the last)."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                duplicate = key in seen
            except TypeError:
                raise yaml.constructor.ConstructorError(
                    None,
                    None,
                    f"a key must be a scalar, not {type(key).__name__}",
                    key_node.start_mark,
                ) from None
            if duplicate:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r}", key_node.start_mark
                )
            seen.add(key)
        return super().construct_mapping(node, deep=deep)


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


#: Largest number of YAML nodes a scenario may expand to (aliases counted each time they are used).
MAX_EXPANDED_NODES = 1_000_000


def _expanded_size(node: yaml.Node, memo: dict[int, int]) -> int:
    """Number of nodes ``node`` stands for once every alias is expanded (memoised: linear time)."""
    known = memo.get(id(node))
    if known is not None:
        return known
    memo[id(node)] = 1  # a cycle counts once (the safe loader builds it as a shared object)
    size = 1
    if isinstance(node, yaml.MappingNode):
        size += sum(_expanded_size(k, memo) + _expanded_size(v, memo) for k, v in node.value)
    elif isinstance(node, yaml.SequenceNode):
        size += sum(_expanded_size(item, memo) for item in node.value)
    memo[id(node)] = size
    return size


def _read_text(path: Path) -> str:
    try:
        if path.is_dir():
            raise ScenarioError(str(path), "", "is a folder, not a scenario file")
        size = path.stat().st_size
        if size > MAX_SCENARIO_BYTES:
            raise ScenarioError(
                str(path), "", f"{size} bytes is larger than the {MAX_SCENARIO_BYTES} bytes allowed"
            )
        raw = path.read_bytes()
    except OSError as exc:
        raise ScenarioError(str(path), "", f"cannot read file ({exc.strerror or exc})") from exc
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ScenarioError(
            str(path), "", f"not UTF-8 text (byte {exc.start}); scenario files are UTF-8 YAML"
        ) from None


def read_yaml_file(path: Path) -> ScenarioSource:
    """Read a YAML scenario file (safe loader, unique keys) with its key-path line numbers.

    Raises:
        ScenarioError: naming the file (and line) on any problem.
    """
    text = _read_text(path)
    try:
        data = yaml.load(text, Loader=_UniqueKeyLoader)  # noqa: S506 (a SafeLoader subclass)
        node = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ScenarioError(str(path), where, f"invalid YAML: {problem}") from None
    except RecursionError:
        raise ScenarioError(str(path), "", "invalid YAML: nested too deeply") from None
    if data is None:
        raise ScenarioError(str(path), "", "the file is empty; a scenario is a YAML mapping")
    if not isinstance(data, dict):
        raise ScenarioError(
            str(path), "", f"the file must contain a YAML mapping, not a {type(data).__name__}"
        )
    lines: dict[Location, int] = {}
    if node is not None:
        expanded = _expanded_size(node, {})
        if expanded > MAX_EXPANDED_NODES:
            raise ScenarioError(
                str(path),
                "",
                f"aliases expand to {expanded:.3g} YAML nodes, more than the "
                f"{MAX_EXPANDED_NODES:,} allowed",
            )
        _line_map(node, (), lines, set())
    return ScenarioSource(data, str(path), lines)


def read_source(source: str | Path | Mapping[str, Any]) -> ScenarioSource:
    """A scenario given as a file path or as an in-memory mapping."""
    if isinstance(source, Mapping):
        return ScenarioSource(dict(source), "<mapping>")
    return read_yaml_file(Path(source))
