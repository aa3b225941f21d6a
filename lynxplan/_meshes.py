"""Triangle meshes of visual geometry for the HTML export: read from the loaded model, decimated.

A URDF's visual meshes are made for CAD rendering (the SO-101's thirteen STL files hold 320,000
triangles, 16 MB); a browser page that animates them needs a few thousand triangles a part.
:func:`decimate` clusters vertices on a uniform grid (Rossignac and Borrel, "Multi-resolution 3D
approximations for rendering complex scenes", 1993): each grid cell's vertices merge into their
mean, and triangles that collapse are dropped. It keeps the silhouette within one cell, needs
numpy only, and is deterministic. The cell grows until the mesh has at most ``max_faces``
triangles.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

#: Triangles kept per visual mesh in the HTML export.
MAX_FACES = 5_000
#: First clustering cell, as a fraction of the mesh's bounding-box diagonal, and its growth.
_FIRST_CELL = 0.006
_GROWTH = 1.2


def mesh_arrays(geometry_object: Any) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (N, 3) [m] and triangles (M, 3) (vertex indices) of a visual mesh: read from a
    binary STL file (scaled by the URDF's mesh scale), else from the coal ``BVHModel`` Pinocchio
    loaded (its scale applied)."""
    path = Path(str(getattr(geometry_object, "meshPath", "") or ""))
    scale = np.asarray(geometry_object.meshScale, dtype=float)
    if path.suffix.lower() == ".stl" and path.is_file():
        stl = _binary_stl(path)
        if stl is not None:
            return stl[0] * scale, stl[1]
    shape = geometry_object.geometry
    vertices = np.asarray(shape.vertices(), dtype=float).reshape(-1, 3)
    faces = np.empty((int(shape.num_tris), 3), dtype=np.int64)
    for i in range(len(faces)):
        triangle = shape.tri_indices(i)
        faces[i] = triangle[0], triangle[1], triangle[2]
    return vertices, faces


def _binary_stl(path: Path) -> tuple[np.ndarray, np.ndarray] | None:
    """Vertices and triangles of a binary STL file (None for an ASCII one); equal corners of
    adjacent triangles merged."""
    data = path.read_bytes()
    if len(data) < 84:
        return None
    count = int(np.frombuffer(data, dtype="<u4", count=1, offset=80)[0])
    if len(data) != 84 + 50 * count:
        return None
    record = np.dtype([("normal", "<f4", 3), ("corners", "<f4", (3, 3)), ("flags", "<u2")])
    corners = np.frombuffer(data, dtype=record, count=count, offset=84)["corners"]
    vertices, faces = np.unique(corners.reshape(-1, 3), axis=0, return_inverse=True)
    return vertices.astype(float), faces.reshape(-1, 3).astype(np.int64)


def decimate(
    vertices: np.ndarray, faces: np.ndarray, max_faces: int = MAX_FACES
) -> tuple[np.ndarray, np.ndarray]:
    """The mesh with at most ``max_faces`` triangles, by vertex clustering (module docstring).

    Args:
        vertices: Vertex positions, shape (N, 3).
        faces: Triangles as vertex indices, shape (M, 3).
        max_faces: Largest number of triangles to keep.

    Returns:
        (vertices (n, 3), faces (m, 3)) with m <= max_faces; the mesh unchanged if it has no
        more than ``max_faces`` triangles already. Triangles keep their orientation.
    """
    vertices = np.asarray(vertices, dtype=float)
    faces = np.asarray(faces, dtype=np.int64)
    faces = faces[_proper(faces)]
    if len(faces) <= max_faces:
        return vertices, faces
    low = vertices.min(axis=0)
    cell = max(float(np.linalg.norm(vertices.max(axis=0) - low)), 1e-12) * _FIRST_CELL
    while True:
        merged, kept = _cluster(vertices, faces, low, cell)
        if len(kept) <= max_faces:
            return merged, kept
        cell *= _GROWTH


def _cluster(
    vertices: np.ndarray, faces: np.ndarray, low: np.ndarray, cell: float
) -> tuple[np.ndarray, np.ndarray]:
    """Merge the vertices of each grid cell of edge ``cell`` into their mean; drop collapsed and
    repeated triangles and unused vertices."""
    keys = np.floor((vertices - low) / cell).astype(np.int64)  # < 2^20 a side: one int64
    _, cluster = np.unique(
        (keys[:, 0] << 42) | (keys[:, 1] << 21) | keys[:, 2], return_inverse=True
    )
    cluster = cluster.reshape(-1)
    count = np.bincount(cluster).astype(float)
    centre = np.stack(
        [np.bincount(cluster, weights=vertices[:, k]) / count for k in range(3)], axis=1
    )
    mapped = cluster[faces]
    mapped = mapped[_proper(mapped)]
    ordered = np.sort(mapped, axis=1)
    n = np.int64(len(centre))
    _, first = np.unique((ordered[:, 0] * n + ordered[:, 1]) * n + ordered[:, 2], return_index=True)
    mapped = mapped[np.sort(first)]
    used, compact = np.unique(mapped, return_inverse=True)
    return centre[used], compact.reshape(-1, 3)


def _proper(faces: np.ndarray) -> np.ndarray:
    """Mask of the triangles with three distinct vertices."""
    mask: np.ndarray = (
        (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2]) & (faces[:, 0] != faces[:, 2])
    )
    return mask
