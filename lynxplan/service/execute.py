"""Executing one scenario run, in a local worker process or on a Dask worker, and validating
scenario text before it is queued."""

from __future__ import annotations

import json
import tempfile
import time
from pathlib import Path
from typing import Any


def execute_run(scenario_path: str, out_dir: str, quick: bool) -> dict[str, Any]:
    """Run a scenario file into ``out_dir``; never raises.

    Returns:
        ``{"ok", "summary", "failures", "report", "artifacts", "seconds"}``, or ``{"error": line}``.
    """
    from lynxplan.exceptions import LynxplanError

    start = time.perf_counter()
    try:
        result = _run_scenario(scenario_path, out_dir, quick)
    except LynxplanError as exc:
        return {"error": str(exc).splitlines()[0] if str(exc) else type(exc).__name__}
    except MemoryError:
        return {"error": "the run exceeded the worker's memory limit"}
    except Exception as exc:
        return {"error": f"internal error: {type(exc).__name__}: {exc}".splitlines()[0]}
    out = Path(out_dir)
    report_path = out / "report.json"
    report = json.loads(report_path.read_text()) if report_path.is_file() else None
    return {
        "ok": bool(result.ok),
        "summary": str(result.summary),
        "failures": list(result.failed_expectations),
        "report": report,
        "artifacts": sorted(result.artifacts),
        "seconds": time.perf_counter() - start,
    }


def _run_scenario(scenario_path: str, out_dir: str, quick: bool) -> Any:
    from lynxplan.scenarios import run_scenario

    return run_scenario(scenario_path, out_dir, quick=quick, force=True)


def execute_run_packed(source: str, quick: bool) -> dict[str, Any]:
    """:func:`execute_run` of scenario text in a temporary folder, artifacts returned as bytes
    (``"files"``: relative path -> content), for workers that do not share the server's disk."""
    with tempfile.TemporaryDirectory(prefix="lynxplan-run-") as folder:
        scenario = Path(folder) / "scenario.yaml"
        scenario.write_text(source, encoding="utf-8")
        out = Path(folder) / "out"
        answer = execute_run(str(scenario), str(out), quick)
        if "error" not in answer:
            answer["files"] = {name: (out / name).read_bytes() for name in answer["artifacts"]}
        return answer


def validate_scenario(source: str, uploaded: bool = False) -> tuple[str, str]:
    """Validate scenario text (YAML or JSON) without running it; its (kind, name).

    A scenario sent over the network may not name files on the server: ``robot.name`` must be
    a built-in robot (never taken for a path), and ``robot.urdf`` is refused unless the URDF was
    uploaded with it (``uploaded``: the server wrote that path into its run's folder).

    Raises:
        lynxplan.exceptions.ScenarioError: naming the key path and the reason.
    """
    from lynxplan.exceptions import ScenarioError
    from lynxplan.scenarios import load_scenario
    from lynxplan.service.robots import robot_names

    with tempfile.TemporaryDirectory(prefix="lynxplan-check-") as folder:
        path = Path(folder) / "scenario.yaml"
        path.write_text(source, encoding="utf-8")
        scenario = load_scenario(path).scenario
    robot = getattr(scenario, "robot", None)
    name = getattr(robot, "name", None)
    if name is not None and name not in robot_names():
        shown = name if len(name) <= 40 else name[:40] + "..."
        raise ScenarioError(
            "<request>",
            "robot.name",
            f"unknown robot {shown!r}; robots: {', '.join(robot_names())} "
            "(or upload a URDF with the run: robot: {urdf: NAME} and files)",
        )
    if getattr(robot, "urdf", None) is not None and not uploaded:
        raise ScenarioError(
            "<request>",
            "robot.urdf",
            "the service reads no URDF paths on its disk: upload the URDF and its meshes with "
            'the run ({"scenario": ..., "files": {NAME: base64}}) or name a built-in robot',
        )
    return str(getattr(scenario, "kind", "")), str(getattr(scenario, "name", "") or "")


__all__ = ["execute_run", "execute_run_packed", "validate_scenario"]
