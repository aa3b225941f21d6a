"""Arm tasks (the scenario kind ``task``): resolution into a plan, the run, report, plots, HTML.

The input model and the kind's entry points are in :mod:`lynxplan.scenarios.task`.
"""
