"""Bench section ``arm``: batch FK/IK throughput, single-pose IK latency, CLIK baseline."""

from __future__ import annotations

from lynxplan.bench import Figure


def run(quick: bool) -> list[Figure]:
    """Measure the arm figures."""
    return []
