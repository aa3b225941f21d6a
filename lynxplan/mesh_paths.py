"""Where a URDF's meshes are: the one resolver of every mesh path lynxplan reads.

A ``<mesh filename=...>`` is found the way a Pinocchio or ROS user expects:

- ``package://PKG/REST``: ``ROOT/PKG/REST`` (or ``ROOT/REST`` where ``ROOT`` is the package
  folder ``PKG`` itself) for each search root, in this order: the ``package_dirs`` given (a
  built-in robot's own), each folder of ``ROS_PACKAGE_PATH``, ``PREFIX/share`` for each prefix of
  ``AMENT_PREFIX_PATH`` (ROS 2), the URDF's folder and each of its parents, then the installed
  example-robot-data (its ``share`` folder, for ``package://example-robot-data/robots/...``, and
  its ``robots`` folder, for ``package://ur_description/...``). The URDF's own tree comes before
  example-robot-data, so a user's copy of a package wins over the installed one of the same name.
- ``file:///abs/path`` or an absolute path: that file.
- A relative path (or ``file://`` with one): against the URDF's folder, then each of
  ``package_dirs``, then the URDF folder's parents.

:func:`resolve_urdf_meshes` writes every mesh of a kind as the absolute path found, so Pinocchio
and coal read files that exist; a mesh found nowhere is a :class:`MeshNotFoundError` naming it.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from collections.abc import Iterator, Sequence
from functools import lru_cache
from pathlib import Path
from typing import Any

from lynxplan.exceptions import MeshNotFoundError, ModelError

#: The URDF elements holding geometry, by geometry kind.
GEOMETRY_KINDS = ("collision", "visual")


@lru_cache(maxsize=1)
def example_robot_data_robots() -> Path | None:
    """The installed example-robot-data ``robots`` folder, or None where it is not installed."""
    try:
        from example_robot_data.robots_loader import getModelPath
    except ImportError:  # pragma: no cover - a dependency
        return None
    try:
        return Path(getModelPath("so_arm_description")).resolve()
    except OSError:  # pragma: no cover - a broken install
        return None


def _environment_dirs(variable: str, suffix: str = "") -> list[Path]:
    return [
        Path(entry) / suffix if suffix else Path(entry)
        for entry in os.environ.get(variable, "").split(os.pathsep)
        if entry
    ]


def _ancestors(folder: Path | None) -> list[Path]:
    if folder is None:
        return []
    folder = folder.resolve()
    return [folder, *folder.parents]


def package_roots(urdf_dir: Path | None, package_dirs: Sequence[str]) -> list[Path]:
    """The folders ``package://`` URIs are looked up in, in order (see the module docstring)."""
    roots = [Path(d) for d in package_dirs]
    roots += _environment_dirs("ROS_PACKAGE_PATH")
    roots += _environment_dirs("AMENT_PREFIX_PATH", "share")
    roots += _ancestors(urdf_dir)
    robots = example_robot_data_robots()
    if robots is not None:
        roots += [robots.parent.parent, robots]
    return roots


def _candidates(
    filename: str, urdf_dir: Path | None, package_dirs: Sequence[str]
) -> Iterator[Path]:
    if filename.startswith("package://"):
        package, _, rest = filename[len("package://") :].partition("/")
        if not package or not rest:
            return
        for root in package_roots(urdf_dir, package_dirs):
            yield root / package / rest
            if root.name == package:
                yield root / rest
        return
    if filename.startswith("file://"):
        filename = filename[len("file://") :]
    if "://" in filename:  # another scheme (http://, model://): not a file lynxplan reads
        return
    if os.path.isabs(filename):
        yield Path(filename)
        return
    if urdf_dir is not None:
        yield urdf_dir / filename
    yield from (Path(d) / filename for d in package_dirs)
    yield from (parent / filename for parent in _ancestors(urdf_dir)[1:])


def resolve_mesh(filename: str, urdf_dir: Path | None, package_dirs: Sequence[str]) -> Path | None:
    """The file a URDF mesh ``filename`` names (see the module docstring), or None.

    Args:
        filename: The ``filename`` attribute of a URDF ``<mesh>``.
        urdf_dir: Folder of the URDF (None: a URDF without a file).
        package_dirs: Folders searched first for ``package://`` URIs and relative paths.
    """
    return next((c for c in _candidates(filename, urdf_dir, package_dirs) if c.is_file()), None)


def _not_found(filename: str, urdf_name: str, package_dirs: Sequence[str]) -> MeshNotFoundError:
    searched = ["package_dirs"] if package_dirs else []
    if filename.startswith("package://") or "://" not in filename:
        searched += ["the URDF's folder and its parents"]
    if filename.startswith("package://"):
        searched += ["ROS_PACKAGE_PATH", "AMENT_PREFIX_PATH", "example-robot-data"]
        package = filename[len("package://") :].partition("/")[0]
        hint = f"give the folder holding package {package!r} in package_dirs"
    elif "://" in filename and not filename.startswith("file://"):
        return MeshNotFoundError(
            filename, urdf_name, (), "only package://, file:// and file paths are read"
        )
    else:
        hint = "check the path"
    roots = tuple(searched)
    return MeshNotFoundError(filename, urdf_name, roots, f"searched {', '.join(roots)}; {hint}")


def resolve_urdf_meshes(
    urdf_xml: str,
    urdf_path: Path | None,
    package_dirs: Sequence[str],
    kinds: Sequence[str] = GEOMETRY_KINDS,
) -> str:
    """``urdf_xml`` with the mesh of every ``<collision>``/``<visual>`` element of ``kinds``
    written as the absolute path of its file.

    Args:
        urdf_xml: The URDF text.
        urdf_path: The URDF file (its folder anchors relative paths), or None.
        package_dirs: Folders searched first (see the module docstring).
        kinds: Which elements: ``"collision"``, ``"visual"`` or both.

    Raises:
        MeshNotFoundError: a mesh found in no search folder, naming it.
    """
    if "<mesh" not in urdf_xml:
        return urdf_xml
    urdf_dir = urdf_path.parent if urdf_path is not None else None
    urdf_name = urdf_path.name if urdf_path is not None else "(text)"
    root = ET.fromstring(urdf_xml)
    changed = False
    for link in root.iter("link"):
        for kind in kinds:
            for element in link.iter(kind):
                for mesh in element.iter("mesh"):
                    filename = (mesh.get("filename") or "").strip()
                    found = resolve_mesh(filename, urdf_dir, package_dirs)
                    if found is None:
                        raise _not_found(filename, urdf_name, package_dirs)
                    mesh.set("filename", str(found.resolve()))
                    changed = True
    return ET.tostring(root, encoding="unicode") if changed else urdf_xml


def build_geometry_model(model: Any, urdf_xml: str, urdf_name: str, kind: str) -> Any:
    """Pinocchio GeometryModel of the ``kind`` elements (``"collision"`` or ``"visual"``) of a
    URDF whose meshes are absolute paths (:func:`resolve_urdf_meshes`).

    Raises:
        ModelError: a mesh file Pinocchio or coal cannot read, naming the URDF and the reason.
    """
    import pinocchio as pin

    geometry_type = pin.GeometryType.COLLISION if kind == "collision" else pin.GeometryType.VISUAL
    try:
        return pin.buildGeomFromUrdfString(model, urdf_xml, geometry_type, package_dirs=[])
    except (RuntimeError, ValueError, OSError) as exc:
        reason = " ".join(str(exc).split())[:300]
        raise ModelError(f"URDF {urdf_name}: cannot read its {kind} geometry: {reason}") from exc


def urdf_geometry_model(model: Any, urdf_path: Path, package_dirs: Sequence[str], kind: str) -> Any:
    """Pinocchio GeometryModel of the ``kind`` elements of the URDF file ``urdf_path``, every
    mesh found by :func:`resolve_mesh`.

    Raises:
        MeshNotFoundError: a mesh found nowhere, naming it.
        ModelError: a mesh file that cannot be read.
    """
    xml = resolve_urdf_meshes(urdf_path.read_text(), urdf_path, package_dirs, (kind,))
    return build_geometry_model(model, xml, urdf_path.name, kind)
