"""Convex hulls of a URDF's collision meshes, cached on disk as small STL files.

The collision world checks every mesh as its convex hull. Loading the original meshes is most of
a run's set-up for a robot with detailed parts (the SO-101's 17 STL files, 330k triangles:
~1.4 s through assimp and coal's BVH build); the hull of each (a few thousand triangles) loads
in a fraction of that. :func:`hull_urdf` rewrites the ``<collision>`` meshes of a URDF to hull
files made once per mesh file (keyed by its path, size and modification time) in
:func:`cache_dir`. A hull's vertices are vertices of the mesh, written in the mesh's own float32
coordinates, so the hull of the hull file is the same polytope; the URDF's ``scale`` is kept.
Where the cache is not writable or a mesh cannot be resolved or read, the original stays.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.mesh_paths import (
    build_geometry_model,
    resolve_mesh,
    resolve_urdf_meshes,
)

#: Bump when the hull files change format or content.
HULL_FORMAT = 1
#: Environment variable naming the cache folder (default: $XDG_CACHE_HOME/lynxplan).
CACHE_ENV = "LYNXPLAN_CACHE_DIR"


def cache_dir() -> Path | None:
    """The folder of the hull files, created if needed; None where it cannot be written."""
    root = os.environ.get(CACHE_ENV) or os.path.join(
        os.environ.get("XDG_CACHE_HOME") or os.path.join(Path.home(), ".cache"), "lynxplan"
    )
    folder = Path(root) / "hulls"
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None
    return folder if os.access(folder, os.W_OK) else None


def _write_stl(path: Path, points: np.ndarray, triangles: np.ndarray) -> None:
    """Binary STL of triangles (K, 3) (indices into points (P, 3)), written atomically."""
    corners = points[triangles].astype(np.float32)
    record = np.zeros(
        len(triangles), dtype=[("normal", "<f4", 3), ("vertices", "<f4", (3, 3)), ("attr", "<u2")]
    )
    record["normal"] = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    record["vertices"] = corners
    handle, temporary = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
    with os.fdopen(handle, "wb") as out:
        out.write(b"lynxplan convex hull".ljust(80, b"\0"))
        out.write(np.uint32(len(triangles)).tobytes())
        out.write(record.tobytes())
    os.replace(temporary, path)


def hull_file(mesh: Path, folder: Path) -> Path | None:
    """The cached hull STL of ``mesh`` (made on first use), or None where it cannot be made."""
    stat = mesh.stat()
    key = f"{mesh.resolve()}|{stat.st_size}|{stat.st_mtime_ns}|{HULL_FORMAT}"
    path = folder / f"{hashlib.sha256(key.encode()).hexdigest()[:32]}.stl"
    if path.is_file():
        return path
    try:
        import coal
        from scipy.spatial import ConvexHull

        points = np.array(coal.MeshLoader().load(str(mesh), np.ones(3)).vertices(), dtype=float)
        hull = ConvexHull(points)
        _write_stl(path, points, hull.simplices)
    except Exception:  # any failure keeps the original mesh
        return None
    return path


def hull_urdf(urdf_xml: str, urdf_dir: Path | None, package_dirs: tuple[str, ...]) -> str:
    """``urdf_xml`` with each ``<collision>`` mesh replaced by its cached hull file (visual
    meshes untouched); unchanged where nothing can be cached."""
    if "<collision" not in urdf_xml or "<mesh" not in urdf_xml:
        return urdf_xml
    folder = cache_dir()
    if folder is None:
        return urdf_xml
    root = ET.fromstring(urdf_xml)
    changed = False
    for collision in root.iter("collision"):
        for mesh in collision.iter("mesh"):
            filename = mesh.get("filename")
            source = resolve_mesh(filename, urdf_dir, package_dirs) if filename else None
            hull = hull_file(source, folder) if source is not None else None
            if hull is not None:
                mesh.set("filename", str(hull))
                changed = True
    return ET.tostring(root, encoding="unicode") if changed else urdf_xml


def geometry_model(robot: Any, kind: str, *, hulls: bool) -> Any:
    """Pinocchio GeometryModel of a Robot's URDF elements of ``kind`` ("collision" or
    "visual"), every mesh found by :func:`lynxplan.mesh_paths.resolve_mesh`; with
    ``hulls``, collision meshes replaced by their cached hull files.

    Raises:
        MeshNotFoundError: a mesh of that kind found nowhere, naming it.
        ModelError: a mesh file that cannot be read.
    """
    xml = resolve_urdf_meshes(robot.urdf_xml, robot.urdf_path, robot.package_dirs, (kind,))
    if hulls:
        xml = hull_urdf(xml, robot.urdf_path.parent, robot.package_dirs)
    return build_geometry_model(robot.model, xml, robot.urdf_path.name, kind)
