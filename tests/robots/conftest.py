"""Robot fixtures (loaded once) and the ``slow`` marker (full counts with LYNXPLAN_SLOW=1)."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from lynxplan.robots import Robot, load_robot

#: Full-count runs (1e6 round trips, 100 random URDFs) only when LYNXPLAN_SLOW=1.
SLOW = os.environ.get("LYNXPLAN_SLOW", "") == "1"


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "slow: full-count checks, run with LYNXPLAN_SLOW=1")


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    skip = pytest.mark.skip(reason="full count: set LYNXPLAN_SLOW=1")
    here = Path(__file__).parent
    for item in items:
        if "slow" in item.keywords and not SLOW and here in Path(str(item.fspath)).parents:
            item.add_marker(skip)


@pytest.fixture(scope="session", params=["al5", "so100", "so101"])
def builtin(request: pytest.FixtureRequest) -> Robot:
    return load_robot(request.param)


@pytest.fixture(scope="session")
def so101() -> Robot:
    return load_robot("so101")
