"""Shared fixtures: models are loaded once per session.

On a cold numba cache (a clean clone: CI), a background process compiles the heaviest kernels
(the SO-101's IK and the planner, through ``lynxplan compile``'s own workloads) on the second
core while the first tests run, so that the tests which need them later load them from numba's
cache instead of compiling them one after the other on one core. It changes no result (the
same kernels, the same single signature each; ``tests/test_kernel_signatures.py`` checks it).
``LYNXPLAN_TEST_PRECOMPILE=0`` turns it off; the tests that measure a first run use caches of
their own (``NUMBA_CACHE_DIR``).
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest
from hypothesis import settings

from lynxplan.arm import Arm, load_arm

# Property tests draw the same examples on every run (no flaky CI); deadlines off because the
# first call of a numba kernel compiles or loads it.
settings.register_profile("lynxplan", derandomize=True, deadline=None)
settings.load_profile("lynxplan")

#: ``lynxplan compile`` stages compiled in the background on a cold cache, in this order (the
#: SO-101's IK is first needed by the benchmark-suite and fan-out tests, the planner next).
PRECOMPILE = ("IK (SO-101)", "plan (AL5)", "plan (SO-101)")
_PRECOMPILE_CODE = (
    "import sys\n"
    "from lynxplan.commands.compile import STAGES\n"
    "stages = dict(STAGES)\n"
    "for name in sys.argv[1:]:\n"
    "    stages[name]()\n"
)
_background: list[subprocess.Popen[bytes]] = []


def pytest_sessionstart(session: pytest.Session) -> None:
    if os.environ.get("LYNXPLAN_TEST_PRECOMPILE", "1") == "0":
        return
    from lynxplan import _jit

    if not _jit.cold_kernels():
        return
    _background.append(
        subprocess.Popen(
            [sys.executable, "-c", _PRECOMPILE_CODE, *PRECOMPILE],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
            start_new_session=True,
        )
    )


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    for process in _background:
        if process.poll() is None:
            process.kill()
        process.wait()


@pytest.fixture(scope="session")
def arm() -> Arm:
    """The shipped AL5 arm."""
    return load_arm()
