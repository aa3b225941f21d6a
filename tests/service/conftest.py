"""Fixtures of the service tests: one real ``lynxplan serve`` process for the session."""

from __future__ import annotations

import os
from collections.abc import Iterator

import httpx
import pytest
from service_server import Server


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line("markers", "slow: long service tests (run with LYNXPLAN_SLOW=1)")


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if os.environ.get("LYNXPLAN_SLOW") == "1":
        return
    skip = pytest.mark.skip(reason="slow: set LYNXPLAN_SLOW=1")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


@pytest.fixture(scope="session")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    """One server for the session: 1 run worker, 1 MiB bodies, JSON batches up to 20,000."""
    process = Server(tmp_path_factory.mktemp("service") / "data", "--workers", "1",
                     "--max-body", "1")  # fmt: skip
    yield process
    process.stop()


@pytest.fixture(scope="session")
def http(server: Server) -> Iterator[httpx.Client]:
    """An HTTP client of the session server."""
    with httpx.Client(base_url=server.url, timeout=120.0) as client:
        yield client
