"""Peer planners for ``lynxplan bench plan``, each a script run by its own virtual environment.

The peers (OMPL 2.x's Python bindings, pyroboplan) are never installed into lynxplan's own
environment: ``pip install 'lynxplan[peers]'`` in a separate venv, and point
``LYNXPLAN_PEERS_DIR`` at a folder holding ``ompl/bin/python`` and ``pyroboplan/bin/python``
(default ``/work/peers``; the IK peers of ``bench robots`` live there too). A peer that is not
there is reported as "peer not installed": the peers are optional. The scripts read one JSON
problem set on stdin and write JSON results to the file named by their argument; they depend on
pinocchio, numpy and the peer only (not on lynxplan).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

#: Environment variable naming the folder of the peers' virtual environments (``LYNXPLAN_PEERS``,
#: the older name, is read too).
PEERS_DIR_VARIABLE = "LYNXPLAN_PEERS_DIR"
DEFAULT_PEERS_DIR = "/work/peers"


def peers_dir() -> Path:
    """The folder of the peers' virtual environments (:data:`PEERS_DIR_VARIABLE`)."""
    root = os.environ.get(PEERS_DIR_VARIABLE) or os.environ.get("LYNXPLAN_PEERS")
    return Path(root or DEFAULT_PEERS_DIR)


def peer_python(name: str) -> Path:
    """The Python of peer ``name``'s virtual environment: ``<peers dir>/<name>/bin/python`` (it
    may not exist: the peer is not installed)."""
    return peers_dir() / name / "bin" / "python"


def peer_urdf(robot: Any, folder: Path) -> Path:
    """Write, in ``folder``, the URDF a peer loads for ``robot``, and return its path.

    Its collision meshes are those of lynxplan's own collision model: each found by lynxplan's
    one mesh resolver (:func:`lynxplan.mesh_paths.resolve_urdf_meshes`: ``package://`` URIs
    included, e.g. example-robot-data's UR5) and replaced by its cached convex hull
    (:func:`lynxplan.robots.hull_cache.hull_urdf`), as absolute paths: a peer's Pinocchio
    reads them without a package path of its own. Visual elements are left as written.
    """
    from lynxplan.mesh_paths import resolve_urdf_meshes
    from lynxplan.robots.hull_cache import hull_urdf

    xml = robot.urdf_xml  # the robot's URDF as loaded (a built-in may differ from its file)
    xml = resolve_urdf_meshes(xml, robot.urdf_path, robot.package_dirs, ("collision",))
    xml = hull_urdf(xml, robot.urdf_path.parent, tuple(robot.package_dirs))
    path = Path(folder) / f"{robot.urdf_path.stem}.peer.urdf"
    path.write_text(xml, encoding="utf-8")
    return path


def self_pair_names(robot: Any) -> list[list[str]]:
    """The self-collision pairs lynxplan checks for ``robot`` (non-adjacent bodies, less its
    SRDF's disabled pairs), as pairs of collision geometry names: the peers check the same."""
    from lynxplan.collision import CollisionWorld

    names = [g.name for g in robot.collision_model.geometryObjects]
    pairs = CollisionWorld(robot, (), self_collision=True).self_pairs
    return [[names[int(a)], names[int(b)]] for a, b in pairs]
