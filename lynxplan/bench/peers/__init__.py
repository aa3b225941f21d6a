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
