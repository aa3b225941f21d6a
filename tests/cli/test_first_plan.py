"""A first plan from the command line runs as Python while the planner's kernels are cold
(``lynxplan._jit.plan_as_python_if_cold``): the same path to the bit, no compile, and a plan
that reaches its time limit as Python is planned again compiled. The shipped plan scenarios take
1-6 s this way on the 2-core machine (compiling first: ~1.5 min)."""

from __future__ import annotations

import importlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from lynxplan import _jit, _numba_cache
from lynxplan.constants import COAL_GJK_TOLERANCE

REPO = Path(__file__).resolve().parents[2]
CLI = "import sys; from lynxplan.cli import main; sys.exit(main())"


def _cli(args: list[str], env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess[str]:
    environment = {k: v for k, v in os.environ.items() if k != "NUMBA_DISABLE_JIT"}
    environment.update(env)
    return subprocess.run(
        [sys.executable, "-c", CLI, *args], capture_output=True, text=True, env=environment, cwd=cwd
    )


def _loaded_by_numba(kernel: str) -> bool:
    """numba's own answer: the dispatcher's cache loads a non-empty index (imports the module)."""
    module, name = kernel.split(":")
    dispatcher = getattr(importlib.import_module(module), name)
    return bool(dispatcher._cache._cache_file._load_index())


def test_cached_answers_as_numba_loads_the_index() -> None:
    answers = {kernel: _numba_cache.cached(kernel) for kernel in _jit.ENTRY_KERNELS}
    for kernel, answer in answers.items():
        assert answer == _loaded_by_numba(kernel), kernel
    assert any(answers.values())  # the session compiled them first (conftest): a real check


def test_a_version_for_another_cpu_is_not_cached() -> None:
    """numba keys each compiled version by the CPU's name and features: with another CPU named
    (numba's NUMBA_CPU_NAME) the same warm cache holds nothing to load."""
    code = (
        "from lynxplan import _jit, _numba_cache\n"
        "print(sum(_numba_cache.cached(k) for k in _jit.ENTRY_KERNELS))"
    )
    assert any(_numba_cache.cached(k) for k in _jit.ENTRY_KERNELS)
    env = {**os.environ, "NUMBA_CPU_NAME": "generic", "NUMBA_CPU_FEATURES": ""}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == "0"


def test_cached_on_an_empty_cache_imports_no_kernel_module(tmp_path: Path) -> None:
    code = (
        "import sys; from lynxplan import _jit, _numba_cache\n"
        "print([_numba_cache.cached(k) for k in _jit.ENTRY_KERNELS])\n"
        "print(sorted(m for m in sys.modules if m.startswith(('lynxplan.planning', "
        "'lynxplan.robots', 'lynxplan.arm', 'lynxplan.collision'))))"
    )
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr[-2000:]
    answers, modules = done.stdout.splitlines()
    assert answers == str([False] * len(_jit.ENTRY_KERNELS))
    assert modules == "[]"


@pytest.mark.parametrize("name", ["p02_box_between", "s01_so101_over_the_wall"])
def test_a_first_plan_runs_as_python_and_plans_the_same_path(tmp_path: Path, name: str) -> None:
    scenario = REPO / "scenarios" / "planning" / f"{name}.yaml"
    cache = tmp_path / "numba"
    cache.mkdir()
    out = str(tmp_path / "first")
    first = _cli(["run", str(scenario), "--out", out], {"NUMBA_CACHE_DIR": str(cache)}, tmp_path)
    assert first.returncode == 0, first.stderr[-2000:]
    assert not list(cache.rglob("*.nb*"))  # nothing compiled
    from lynxplan.scenarios.runner import execute, load_scenario

    execute(load_scenario(scenario), tmp_path / "compiled", quick=False, force=False)
    assert not _jit.cold_kernels(_jit.PLANNER_KERNELS)  # the reference ran compiled
    python_csv = (tmp_path / "first" / "trajectory.csv").read_bytes()
    assert python_csv == (tmp_path / "compiled" / "trajectory.csv").read_bytes()
    reports = [
        json.loads((tmp_path / d / "report.json").read_text()) for d in ("first", "compiled")
    ]
    assert [r["details"]["kernels"] for r in reports] == ["python", "compiled"]
    python, compiled = ({**r["metrics"]} for r in reports)
    del python["planning_time"], compiled["planning_time"]  # seconds
    # coal's distances of the same samples, to its GJK tolerance (its answer depends on where
    # the previous queries of the process left GJK's start: here, another process)
    tolerance = COAL_GJK_TOLERANCE
    assert python.pop("min_clearance") == pytest.approx(
        compiled.pop("min_clearance"), abs=tolerance
    )
    assert python == compiled


def test_a_plan_that_reaches_its_time_limit_as_python_is_planned_again_compiled(
    tmp_path: Path,
) -> None:
    """A copy of the package with its warm cache, less the RRT-Connect loop's: the first try runs
    as Python, reaches the 0.3 s limit of u01, and the CLI plans again compiled (compiling that
    one kernel); the verdict is the compiled planner's."""
    if _jit.cold_kernels(_jit.PLANNER_KERNELS):
        from lynxplan.scenarios.runner import execute, load_scenario

        scenario = REPO / "scenarios" / "planning" / "p02_box_between.yaml"
        execute(load_scenario(scenario), tmp_path / "warm", quick=True, force=False)
    copy = tmp_path / "checkout"  # the package, its shipped data (URDF meshes) beside it
    shutil.copytree(REPO / "lynxplan", copy / "lynxplan")  # copy2: the sources' stamps kept
    shutil.copy(REPO / "pyproject.toml", copy)
    (copy / "urdf").symlink_to(REPO / "urdf")
    for index in (copy / "lynxplan" / "planning" / "__pycache__").glob(
        "rrt_connect.rrt_connect_kernel-*.nbi"
    ):
        index.unlink()
    scenario = REPO / "scenarios" / "planning" / "u01_goal_in_jar.yaml"
    env = {"PYTHONPATH": str(copy)}
    done = _cli(["run", str(scenario), "--out", str(tmp_path / "out")], env, tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "planning again compiled" in done.stderr
    assert done.stderr.count(_jit.PYTHON_PLAN_NOTE) == 1  # said on stderr, terminal or not
    assert "time limit 0.3 s reached" in done.stdout
    assert list((copy / "lynxplan" / "planning" / "__pycache__").glob(
        "rrt_connect.rrt_connect_kernel-*.nbi"
    ))  # fmt: skip
    written = sorted(p.name for p in (tmp_path / "out").iterdir())
    assert written == [".lynxplan-output", "report.json"]  # as after any run


def test_a_plan_whose_verdict_depends_on_speed_compiles(tmp_path: Path) -> None:
    """An expectation on planning_time, or samples beyond 1 kHz: no Python run (the scenario's
    raw data decide, before any kernel module is imported)."""
    from lynxplan.commands.run import _may_run_as_python
    from lynxplan.scenarios.source import read_source

    data = read_source(REPO / "scenarios" / "planning" / "p02_box_between.yaml").data
    assert _may_run_as_python(data)
    assert not _may_run_as_python({**data, "expect": {"planning_time": "<= 50 ms"}})
    assert not _may_run_as_python({**data, "planner": {"sample_rate": 2000}})
    assert _may_run_as_python({**data, "planner": {"sample_rate": 1000}})
    assert not _may_run_as_python({**data, "kind": "task"})
    assert not _may_run_as_python({**data, "planner": "fast"})  # malformed: the checks say so


def test_a_python_plan_stops_at_its_time_limit_or_the_cap(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(_jit._state, "python_plan", True)
    _jit.check_python_plan(0.2, 0.3)
    with pytest.raises(_jit.PythonPlanTooSlowError):
        _jit.check_python_plan(0.3, 0.3)
    _jit.check_python_plan(_jit.PYTHON_PLAN_SECONDS - 1.0, 3600.0)
    with pytest.raises(_jit.PythonPlanTooSlowError):
        _jit.check_python_plan(_jit.PYTHON_PLAN_SECONDS, 3600.0)
    monkeypatch.setitem(_jit._state, "python_plan", False)  # compiled: the time limit only
    _jit.check_python_plan(1e9, 0.3)
