"""The one hardened YAML reader: a scenario file -> a plain ``dict``, or one clear error.

:func:`read_yaml_mapping` refuses, with a :class:`~lynxplan.exceptions.ScenarioError` naming the
file (and the line where the parser knows it):

- a missing file, a directory, a device or FIFO, a file it may not read;
- a file larger than :data:`MAX_FILE_BYTES`, a binary file (NUL bytes), text that is not UTF-8;
- an empty file (or one with only comments), a top level that is not a mapping, top-level keys
  that are not strings;
- invalid YAML, unhashable keys (``? [a, b]``), a key given twice in one mapping, tags that are
  not plain data (``!!python/object``);
- nesting deeper than :data:`MAX_DEPTH`, more than :data:`MAX_EVENTS` parser events, and
  anchors/aliases that expand to more than :data:`MAX_NODES` nodes ("billion laughs": the size is
  computed on the composed graph, shared nodes counted once per use, before anything is built).

Only the safe loader is used; the text is parsed in bounded steps, so no input can exhaust memory
or the recursion limit.
"""

from __future__ import annotations

import stat
from pathlib import Path
from typing import Any

import yaml

from lynxplan.exceptions import ScenarioError

#: Largest scenario file read, in [bytes] (shipped scenarios are a few kB).
MAX_FILE_BYTES = 4 * 1024 * 1024
#: Deepest nesting of mappings and sequences.
MAX_DEPTH = 64
#: Most parser events (scalars, mapping and sequence starts/ends, aliases) in one file.
MAX_EVENTS = 1_000_000
#: Most nodes of the document once every alias is expanded.
MAX_NODES = 1_000_000


#: libyaml's parser when PyYAML was built with it (about 10x faster), else the pure-Python one.
_BaseLoader: Any = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


class _UniqueKeyLoader(_BaseLoader):  # type: ignore[misc]
    """Safe loader that rejects a key given twice in one mapping (YAML would keep the last) and
    unhashable keys, each with the key's position."""

    def construct_mapping(self, node: yaml.MappingNode, deep: bool = False) -> dict[Any, Any]:
        seen: set[Any] = set()
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=True)
            try:
                duplicate = key in seen
            except TypeError:
                raise yaml.constructor.ConstructorError(
                    None, None, f"unhashable key ({type(key).__name__})", key_node.start_mark
                ) from None
            if duplicate:
                raise yaml.constructor.ConstructorError(
                    None, None, f"duplicate key {key!r}", key_node.start_mark
                )
            seen.add(key)
        mapping: dict[Any, Any] = super().construct_mapping(node, deep=deep)
        return mapping


def _line(node: yaml.Node | yaml.Event) -> int | None:
    """1-based line of a node or event, None if the parser did not record it."""
    mark = node.start_mark
    return None if mark is None else mark.line + 1


def _error(path: Path, reason: str, line: int | None = None) -> ScenarioError:
    return ScenarioError(str(path), "", reason, line)


def _read_text(path: Path, max_bytes: int) -> str:
    """The file's text, after checking what it is, its size and its encoding."""
    try:
        info = path.stat()
    except FileNotFoundError:
        raise _error(path, "file not found") from None
    except OSError as exc:
        raise _error(path, f"cannot read file ({exc.strerror or exc})") from None
    if stat.S_ISDIR(info.st_mode):
        raise _error(path, "is a directory, not a scenario file")
    if not stat.S_ISREG(info.st_mode):
        raise _error(path, "is not a regular file (a device, FIFO or socket)")
    if info.st_size > max_bytes:
        raise _error(
            path, f"file is {info.st_size} bytes, more than the limit of {max_bytes} bytes"
        )
    try:
        with path.open("rb") as stream:
            raw = stream.read(max_bytes + 1)
    except OSError as exc:
        raise _error(path, f"cannot read file ({exc.strerror or exc})") from None
    if len(raw) > max_bytes:  # grew while we looked
        raise _error(path, f"file is more than the limit of {max_bytes} bytes")
    if b"\x00" in raw:
        line = raw[: raw.index(b"\x00")].count(b"\n") + 1
        raise _error(path, "binary file (NUL byte), not YAML text", line)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise _error(
            path, f"not UTF-8 text (byte 0x{raw[exc.start]:02x} at offset {exc.start})", line
        ) from None
    return text.removeprefix("\ufeff")


def _check_events(path: Path, text: str, max_depth: int, max_events: int) -> None:
    """Walk the parser's events (iterative, no recursion): depth and count limits.

    libyaml (PyYAML >= 6.0.4) has a nesting limit of its own (about 1000 levels), which its
    scanner may reach while it looks ahead, before the events reach ``max_depth``: that error
    is the same "nesting deeper" error."""
    depth = 0
    try:
        for events, event in enumerate(yaml.parse(text, Loader=_BaseLoader), start=1):
            line = _line(event)
            if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
                depth += 1
                if depth > max_depth:
                    raise _error(path, f"nesting deeper than {max_depth} levels", line)
            elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
                depth -= 1
            if events > max_events:
                raise _error(path, f"more than {max_events} YAML elements", line)
    except yaml.YAMLError as exc:
        if "nesting depth" not in str(getattr(exc, "problem", "")):
            raise
        mark = getattr(exc, "problem_mark", None)
        line = None if mark is None else mark.line + 1
        raise _error(path, f"nesting deeper than {max_depth} levels", line) from None


def _expanded_size(path: Path, root: yaml.Node, limit: int) -> int:
    """Nodes of the document with every alias expanded (memoised on the shared graph).

    Raises:
        ScenarioError: an alias refers to a node that contains it (a recursive structure).
    """
    sizes: dict[int, int] = {}
    open_nodes: set[int] = set()
    # Iterative post-order walk (no recursion, whatever the depth).
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]
    while stack:
        node, done = stack.pop()
        if id(node) in sizes:
            continue
        children: list[yaml.Node] = []
        if isinstance(node, yaml.MappingNode):
            children = [n for pair in node.value for n in pair]
        elif isinstance(node, yaml.SequenceNode):
            children = list(node.value)
        if done:
            open_nodes.discard(id(node))
            sizes[id(node)] = min(limit + 1, 1 + sum(sizes[id(c)] for c in children))
            continue
        if id(node) in open_nodes:
            raise _error(path, "an alias refers to a node that contains it", _line(node))
        open_nodes.add(id(node))
        stack.append((node, True))
        for child in children:
            if id(child) in open_nodes:
                raise _error(
                    path,
                    "an alias refers to a node that contains it (recursive structure)",
                    _line(child),
                )
            if id(child) not in sizes:
                stack.append((child, False))
    return sizes[id(root)]


def _yaml_error(path: Path, exc: yaml.YAMLError) -> ScenarioError:
    mark = getattr(exc, "problem_mark", None) or getattr(exc, "context_mark", None)
    problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
    context = getattr(exc, "context", None)
    reason = f"invalid YAML: {problem}" + (f" ({context})" if context else "")
    return _error(path, " ".join(reason.split()), None if mark is None else mark.line + 1)


def read_yaml_mapping(
    path: str | Path,
    *,
    max_bytes: int = MAX_FILE_BYTES,
    max_depth: int = MAX_DEPTH,
    max_nodes: int = MAX_NODES,
) -> dict[str, Any]:
    """Read a YAML file whose top level is a mapping with string keys.

    Args:
        path: The file.
        max_bytes: Largest file size accepted, in [bytes].
        max_depth: Deepest nesting of mappings/sequences accepted.
        max_nodes: Most nodes accepted once aliases are expanded.

    Returns:
        The mapping, as plain Python data (dict, list, str, int, float, bool, None, date).

    Raises:
        ScenarioError: naming the file (and the line where known) and what is wrong.
    """
    data, _ = read_yaml_document(
        path, max_bytes=max_bytes, max_depth=max_depth, max_nodes=max_nodes
    )
    return data


def read_yaml_document(
    path: str | Path,
    *,
    max_bytes: int = MAX_FILE_BYTES,
    max_depth: int = MAX_DEPTH,
    max_nodes: int = MAX_NODES,
) -> tuple[dict[str, Any], yaml.MappingNode]:
    """As :func:`read_yaml_mapping`, and the composed node tree (for key-path line numbers)."""
    path = Path(path)
    text = _read_text(path, max_bytes)
    try:
        _check_events(path, text, max_depth, max(MAX_EVENTS, max_nodes))
        loader = _UniqueKeyLoader(text)
        try:
            node = loader.get_single_node()
            if node is None:
                raise _error(path, "empty file: expected a YAML mapping such as 'kind: ...'")
            size = _expanded_size(path, node, max_nodes)
            if size > max_nodes:
                raise _error(
                    path,
                    f"anchors/aliases expand to more than {max_nodes} YAML nodes "
                    "(an alias bomb?); write the values out or use fewer aliases",
                    _line(node),
                )
            if not isinstance(node, yaml.MappingNode):
                kind = "a list" if isinstance(node, yaml.SequenceNode) else "a single value"
                raise _error(path, f"the top level must be a mapping (key: value), not {kind}", 1)
            data = loader.construct_document(node)
        finally:
            loader.dispose()
    except yaml.YAMLError as exc:
        raise _yaml_error(path, exc) from None
    except RecursionError:  # unreachable after the depth check; kept as a last guard
        raise _error(path, f"nesting deeper than {max_depth} levels") from None
    for key in data:
        if not isinstance(key, str):
            raise _error(path, f"top-level key {key!r} is not a string")
    return data, node
