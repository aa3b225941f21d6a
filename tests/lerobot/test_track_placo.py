"""lynxplan's continuous IK against placo driven as LeRobot drives it, on the same streams.

placo (LeRobot's IK, ``lerobot.model.kinematics``) cannot share lynxplan's venv (its ``pin``
wheel brings another Pinocchio): it runs in ``<peers dir>/placo`` (``LYNXPLAN_PEERS_DIR``,
default ``/work/peers``; :mod:`lynxplan.bench.peers`), and this test is skipped, with this
reason, when that venv is not there::

    python3 -m venv /work/peers/placo
    /work/peers/placo/bin/pip install "placo>=0.9.6,<0.10"   # lerobot 0.4.4's placo-dep pin

The figures over 20 streams: ``python -m lynxplan.bench.lerobot_track`` (docs/lerobot.md).
"""

from __future__ import annotations

import numpy as np
import pytest

from lynxplan.bench.lerobot_track import figures, run_lynxplan, run_placo
from lynxplan.bench.peers import peer_python
from lynxplan.lerobot.servo import DEFAULT_FPS, DEFAULT_MAX_VELOCITY
from lynxplan.lerobot.streams import target_stream

PLACO = peer_python("placo")
pytestmark = pytest.mark.skipif(
    not PLACO.is_file(),
    reason=f"placo (LeRobot's IK) is not installed in its own venv: no {PLACO} "
    "(see this module's docstring)",
)
#: placo's FK and lynxplan's of the same joint angles, same URDF, in [m] (both Pinocchio).
FK_ATOL = 1e-12
#: A one-solve-per-frame tracker lags a moving target by about one frame's motion, in [m].
LAG_ATOL = 2e-3


def test_same_streams_lynxplan_bounded_placo_measured(so101):
    streams = [target_stream(so101, 0), target_stream(so101, 1, out_of_reach=True)]
    bound = DEFAULT_MAX_VELOCITY / DEFAULT_FPS
    for update in (False, True):
        placo = run_placo(so101, streams, PLACO, update_before_solve=update)
        for stream, result in zip(streams, placo["streams"], strict=True):
            q = np.asarray(result["q"])
            assert q.shape == stream.q.shape
            # the peer read the same model: its FK of its answers is lynxplan's
            np.testing.assert_allclose(so101.fk(q), result["fk"], atol=FK_ATOL)
            theirs = figures(so101, stream, q, DEFAULT_FPS)
            if update and not stream.pushed.any():
                # placo driven right tracks a reachable stream as closely as a one-step QP can
                assert theirs.error_end <= LAG_ATOL and theirs.over_bound == 0
    for stream in streams:
        ours = figures(so101, stream, run_lynxplan(so101, stream, DEFAULT_FPS), DEFAULT_FPS)
        assert ours.max_step <= bound * (1 + 1e-12) and ours.over_bound == 0
        assert ours.error_end <= 1e-6  # back on the targets after the push
    # the pushed stream: placo (LeRobot's way) steps far beyond the servo bound
    assert figures(so101, streams[1], np.asarray(placo["streams"][1]["q"]), 30).max_step > bound
