"""Shared fixtures: models are loaded once per session.

On a cold numba cache (a clean clone: CI), the kernels are compiled before the tests run, by
``lynxplan compile``: under ``pytest -n`` (the README's test command) with two jobs, while the
test session waits; otherwise in one background process on the second core while the first
tests run. Either way the tests load the kernels
from numba's cache instead of compiling them each in its own process, the same kernel in two
workers at once (measured on the 2-core machine: five Dask tests took 2-4 min each, compiling
what the other worker was compiling too). It changes no result (the same kernels, the same
single signature each; ``tests/test_kernel_signatures.py`` checks it).
``LYNXPLAN_TEST_PRECOMPILE=0`` turns it off; the tests that measure a first run use caches of
their own (``NUMBA_CACHE_DIR``).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import settings

from lynxplan.arm import Arm, load_arm

REPO = Path(__file__).resolve().parents[1]
# The commands the tests start (``lynxplan ...``, ``python -c``) import this checkout, the code
# under test, as pytest does (``pythonpath``), not a copy installed into the venv by ``pip
# install .``: the same code, and the same numba cache (an installed copy compiles every kernel
# again, measured in CI: 2-3 min of two tests). The tests of the installed wheel
# (``wheel_venv.py``) clear PYTHONPATH for theirs.
os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [str(REPO), os.environ.get("PYTHONPATH")]))

# Property tests draw the same examples on every run (no flaky CI); deadlines off because the
# first call of a numba kernel compiles or loads it.
settings.register_profile("lynxplan", derandomize=True, deadline=None)
settings.load_profile("lynxplan")

_CLI = "import sys; from lynxplan.cli import main; sys.exit(main())"
_background: list[subprocess.Popen[bytes]] = []


def _compile(jobs: int) -> subprocess.Popen[bytes]:
    """``lynxplan compile --jobs JOBS`` in a process of its own (no output)."""
    return subprocess.Popen(
        [sys.executable, "-c", _CLI, "compile", "--jobs", str(jobs)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )


#: Test files whose tests build on each other's files (the README's blocks run in order in one
#: folder): under ``pytest -n`` each runs whole, in order, on one worker.
IN_ORDER_FILES = ("tests/test_readme.py",)


def pytest_xdist_make_scheduler(config: pytest.Config, log: object) -> object:
    """Under ``pytest -n``: spread tests one by one (balance on 2 cores), except the files of
    :data:`IN_ORDER_FILES`, each kept whole on one worker (xdist's ``loadgroup`` marker is
    ignored under pytest 9.2, so the grouping is this scheduler's scope)."""
    from xdist.scheduler import LoadScopeScheduling

    class InOrderFilesScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            path = nodeid.split("::", 1)[0]
            return path if path in IN_ORDER_FILES else nodeid

    return InOrderFilesScheduling(config, log)


def pytest_sessionstart(session: pytest.Session) -> None:
    off = os.environ.get("LYNXPLAN_TEST_PRECOMPILE", "1") == "0"
    if off or "PYTEST_XDIST_WORKER" in os.environ:
        return
    from lynxplan import _jit

    if not _jit.cold_kernels():
        return
    if not getattr(session.config.option, "numprocesses", None):
        _background.append(_compile(1))
        return
    began = time.perf_counter()
    code = _compile(2).wait()
    print(f"\nlynxplan: compiled the numba kernels first ({time.perf_counter() - began:.0f} s, "
          f"`lynxplan compile --jobs 2`: exit code {code})", flush=True)  # fmt: skip


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    for process in _background:
        if process.poll() is None:
            process.kill()
        process.wait()


@pytest.fixture(scope="session")
def arm() -> Arm:
    """The shipped AL5 arm."""
    return load_arm()
