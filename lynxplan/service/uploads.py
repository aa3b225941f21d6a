"""A run's own robot: a URDF and its meshes uploaded with the scenario, into the run's folder.

``POST /runs`` takes, besides a plain scenario, a JSON bundle::

    {"scenario": {...} or "YAML text",
     "files": {"arm.urdf": "<base64>", "meshes/base.stl": "<base64>", ...}}

where the scenario's ``robot: {urdf: arm.urdf, tool: ...}`` names one of ``files``. The files
go to ``runs/<id>/files/`` and nowhere else: names are relative (letters, digits, ``._-``, at
most :data:`MAX_DEPTH` folders, no ``..``), their decoded sizes are bounded, and every
``filename=`` of the URDF (meshes, textures) must name an uploaded file (``package://PKG/REST``
matches ``REST`` or ``PKG/REST``; a relative path, the URDF's folder); the stored URDF names
them by their sandbox paths, so nothing outside the run's folder is ever opened for it.
"""

from __future__ import annotations

import base64
import binascii
import posixpath
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lynxplan.service.problems import Problem

#: Most files in one bundle; deepest folder nesting of a file name.
MAX_FILES = 64
MAX_DEPTH = 4
_NAME_PART = re.compile(r"[A-Za-z0-9_][A-Za-z0-9._-]{0,99}")


@dataclass(frozen=True)
class Bundle:
    """A decoded bundle: the scenario object and the files (relative name -> bytes)."""

    scenario: dict[str, Any]
    files: dict[str, bytes]


def is_bundle(value: Any) -> bool:
    """Whether a JSON body is a bundle (``scenario`` and ``files`` keys only)."""
    return isinstance(value, dict) and set(value) == {"scenario", "files"}


def decode_bundle(value: dict[str, Any], max_bytes: int) -> Bundle:
    """Check and decode a bundle: file names, base64, sizes (Problem 413/422 naming the key)."""
    import yaml

    scenario = value["scenario"]
    if isinstance(scenario, str):
        try:
            scenario = yaml.safe_load(scenario)
        except yaml.YAMLError:
            raise Problem(422, "scenario: malformed YAML", "scenario") from None
    if not isinstance(scenario, dict):
        raise Problem(422, "scenario must be an object (or YAML text of one)", "scenario")
    files = value["files"]
    if not isinstance(files, dict) or not files:
        raise Problem(422, "files must be an object {name: base64 content}", "files")
    if len(files) > MAX_FILES:
        raise Problem(413, f"files: {len(files)} files exceed the limit of {MAX_FILES}", "files")
    decoded: dict[str, bytes] = {}
    total = 0
    for name, content in files.items():
        key = f"files.{name}"[:120]
        check_name(name, key)
        if not isinstance(content, str):
            raise Problem(422, f"{key} must be base64 text", key)
        try:
            data = base64.b64decode(content, validate=True)
        except (binascii.Error, ValueError):
            raise Problem(422, f"{key} is not valid base64", key) from None
        total += len(data)
        if total > max_bytes:
            raise Problem(
                413, f"files: the uploaded files exceed the limit of {max_bytes} bytes", "files"
            )
        decoded[name] = data
    return Bundle(scenario, decoded)


def check_name(name: str, key: str) -> None:
    """A safe relative file name, else Problem 422 naming ``key``."""
    parts = name.split("/")
    if len(parts) > MAX_DEPTH + 1 or not all(_NAME_PART.fullmatch(p) for p in parts):
        raise Problem(
            422,
            f"{key}: a file name must be a relative path of at most {MAX_DEPTH + 1} parts of "
            "letters, digits, '.', '_', '-' (no '..', no leading '/' or '.')",
            key,
        )


def install(bundle: Bundle, folder: Path) -> dict[str, Any]:
    """Write the bundle's files under ``folder`` (the run's ``files/``) and the scenario whose
    ``robot.urdf`` names the stored URDF, with its file references made sandbox paths.

    Returns:
        The scenario object to store and run.

    Raises:
        Problem: 422 naming ``robot.urdf`` or the offending ``files.NAME``.
    """
    scenario = dict(bundle.scenario)
    robot = scenario.get("robot")
    robot = robot if isinstance(robot, dict) else {}
    urdf = robot.get("urdf")
    if not isinstance(urdf, str) or urdf not in bundle.files:
        raise Problem(
            422,
            "robot.urdf must name one of the uploaded files: " + ", ".join(sorted(bundle.files)),
            "robot.urdf",
        )
    folder.mkdir(parents=True)
    for name, data in bundle.files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    text = _sandboxed_urdf(bundle.files[urdf], urdf, set(bundle.files), folder)
    (folder / urdf).write_text(text, encoding="utf-8")
    scenario["robot"] = {**robot, "urdf": str(folder / urdf)}
    return scenario


def _sandboxed_urdf(data: bytes, urdf: str, names: set[str], folder: Path) -> str:
    key = f"files.{urdf}"
    try:
        root = ET.fromstring(data.decode("utf-8"))
    except (UnicodeDecodeError, ET.ParseError) as exc:
        raise Problem(422, f"{key}: not a URDF (XML): {exc}".splitlines()[0], key) from None
    if root.tag != "robot":
        raise Problem(422, f"{key}: not a URDF: the root element is <{root.tag}>", key)
    base = posixpath.dirname(urdf)
    for element in root.iter():
        reference = element.get("filename")
        if reference is None:
            continue
        name = _uploaded(reference, base, names)
        if name is None:
            raise Problem(
                422,
                f"{key}: {element.tag} file {reference[:80]!r} is not among the uploaded files "
                "(upload it with the URDF; meshes: relative paths or package://PKG/PATH)",
                key,
            )
        element.set("filename", str(folder / name))
    return ET.tostring(root, encoding="unicode")


def _uploaded(reference: str, base: str, names: set[str]) -> str | None:
    """The uploaded file a URDF reference names, or None."""
    if reference.startswith("package://"):
        rest = reference[len("package://") :]
        _, _, inside = rest.partition("/")
        candidates = [rest, inside, posixpath.join(base, inside), posixpath.join(base, rest)]
    elif "://" in reference or reference.startswith("/"):
        return None
    else:
        candidates = [posixpath.join(base, reference)]
    for candidate in candidates:
        normal = posixpath.normpath(candidate)
        if normal in names:
            return normal
    return None
