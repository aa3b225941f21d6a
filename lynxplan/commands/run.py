"""``lynxplan run SCENARIO.yaml``: run a scenario file and write its outputs."""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

from lynxplan import _jit


def register(subparsers: Any) -> None:
    """Add the ``run`` sub-command."""
    parser = subparsers.add_parser(
        "run",
        help="run a scenario YAML file",
        description="Run a scenario and write report.json and its artifacts into --out "
        "(default: out/<scenario name>). lynxplan's previous outputs there are replaced as a "
        "whole when the run completes (an interrupted, killed or failed run leaves them intact); "
        "files lynxplan did not write are never deleted or overwritten: a folder holding some is "
        "refused unless --force, which keeps them. Exit 0: every expectation holds; 1: an "
        "expectation failed (the report is still written); 2: bad input.",
    )
    parser.add_argument("scenario", help="scenario YAML file")
    parser.add_argument(
        "--out", help="output folder (default: out/<scenario name>, e.g. out/ok_task)"
    )
    parser.add_argument(
        "--quick", action="store_true", help="skip plots, HTML and the ruckig/toppra comparisons"
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="use --out even if it holds files lynxplan did not write (they stay untouched; "
        "only lynxplan's own outputs are replaced)",
    )
    parser.add_argument("--server", help="run on a lynxplan server (URL) instead of locally")
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    """Run the scenario; exit 0 when every expectation holds, 1 otherwise."""
    from lynxplan.scenarios.folders import folder_name
    from lynxplan.scenarios.source import read_source

    if args.server:
        from lynxplan.client import run_remote

        out = (
            args.out
            or f"out/{folder_name(read_source(args.scenario).data.get('name'), args.scenario)}"
        )
        return run_remote(args.server, args.scenario, out, quick=args.quick, force=args.force)
    source = read_source(args.scenario)
    if _may_run_as_python(source.data):
        _jit.plan_as_python_if_cold()  # a first plan: seconds as Python, not minutes compiling
    from lynxplan.scenarios.runner import execute, validate

    loaded = validate(source)
    out = args.out or f"out/{folder_name(loaded.scenario.name, args.scenario)}"
    try:
        result = execute(loaded, out, quick=args.quick, force=args.force)
    except _jit.PythonPlanTooSlowError:  # nothing written: the compiled planner's verdict instead
        return _rerun_compiled(sys.argv[1:])
    print(result.summary)
    held = sum(e.passed for e in result.expectations)
    if result.expectations:
        print(f"expectations: {held} of {len(result.expectations)} hold")
    print(f"outputs in {out}/: {', '.join(result.artifacts)}")
    if not result.ok:
        print("failed expectations:")
        for failure in result.failed_expectations:
            print(f"  - {failure}")
        return 1
    return 0


#: Samples per second up to which a plan scenario may run as Python on a cold cache (the
#: trajectory's exact clearance is computed at every sample: 10x the default 100 Hz).
PYTHON_SAMPLE_RATE = 1000.0


def _may_run_as_python(data: dict[str, Any]) -> bool:
    """Whether a scenario (its raw data) may run as Python while the planner is cold
    (``_jit.plan_as_python_if_cold``): a plan whose verdict cannot depend on the kernels' speed
    (no expectation on ``planning_time``) and whose samples stay few (``planner.sample_rate`` up
    to :data:`PYTHON_SAMPLE_RATE`). Anything malformed: no (the scenario's checks report it)."""
    planner, expect = data.get("planner") or {}, data.get("expect") or {}
    if data.get("kind") != "plan" or not isinstance(planner, dict) or not isinstance(expect, dict):
        return False
    rate = planner.get("sample_rate", 100.0)
    few = isinstance(rate, int | float) and not isinstance(rate, bool)
    return "planning_time" not in expect and few and rate <= PYTHON_SAMPLE_RATE


def _rerun_compiled(argv: list[str]) -> int:
    """Run this command again with ``argv`` in a new process with numba's compiler on (it
    compiles the planner, once), importing the same lynxplan as this one; returns its exit code
    (128 + the signal that ended it, if one did)."""
    sys.stderr.write("lynxplan: the plan took too long as Python code: planning again compiled\n")
    sys.stderr.flush()
    root = str(Path(_jit.__file__).resolve().parent.parent)
    paths = [root, *filter(None, [os.environ.get("PYTHONPATH")])]
    environment = {**os.environ, "NUMBA_DISABLE_JIT": "0", "PYTHONPATH": os.pathsep.join(paths)}
    # without the working folder python -c puts first: the lynxplan of PYTHONPATH, this one
    program = (
        "import sys; sys.path[:] = [p for p in sys.path if p]; "
        "from lynxplan.cli import main; sys.exit(main())"
    )
    done = subprocess.run([sys.executable, "-c", program, *argv], env=environment, check=False)
    return done.returncode if done.returncode >= 0 else 128 - done.returncode
