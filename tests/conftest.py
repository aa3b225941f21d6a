"""Shared fixtures: models are loaded once per session."""

from __future__ import annotations

import pytest
from hypothesis import settings

from lynxplan.arm import Arm, load_arm

# Property tests draw the same examples on every run (no flaky CI); deadlines off because the
# first call of a numba kernel compiles or loads it.
settings.register_profile("lynxplan", derandomize=True, deadline=None)
settings.load_profile("lynxplan")


@pytest.fixture(scope="session")
def arm() -> Arm:
    """The shipped AL5 arm."""
    return load_arm()
