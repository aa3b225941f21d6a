"""Arm task scenarios (kind ``task``): schema, resolution, run, report, plots and HTML."""

from lynxplan.task.expect import Comparison, parse_comparison

__all__ = ["Comparison", "parse_comparison"]
