"""Peer planners for ``lynxplan bench plan``, each a script run by its own virtual environment.

The peers (OMPL 2.x's Python bindings, pyroboplan) are never installed into lynxplan's own
environment: ``pip install 'lynxplan[peers]'`` in a separate venv, and point
``LYNXPLAN_PEERS`` at a folder holding ``ompl/bin/python`` and ``pyroboplan/bin/python``
(default ``/work/peers``). The scripts read one JSON problem set on stdin and write JSON results
to the file named by their argument; they depend on pinocchio, numpy and the peer only (not on
lynxplan).
"""
