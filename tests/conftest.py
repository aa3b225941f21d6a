"""Shared fixtures: models are loaded once per session."""

from __future__ import annotations

import pytest

from lynxplan.arm import Arm, load_arm


@pytest.fixture(scope="session")
def arm() -> Arm:
    """The shipped AL5 arm."""
    return load_arm()
