"""The typed methods of :class:`Client`: each request's answer rebuilt as the library's own type."""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import orjson

from lynxplan.client import results
from lynxplan.client.results import RunResult
from lynxplan.client.transport import ServiceError, Transport
from lynxplan.exceptions import LynxplanError

#: Batches at least this large travel as binary arrays instead of JSON.
BINARY_BATCH = 1_000
_FINAL = ("succeeded", "failed", "cancelled", "interrupted")


class Client(Transport):
    """HTTP client of a lynxplan server.

    Args:
        url: Base URL, e.g. ``"http://127.0.0.1:8000"``.
        token: Bearer token, if the server requires one.
        timeout: Per-request timeout, in [s].
    """

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

    # -- meta ----------------------------------------
    def health(self) -> dict[str, Any]:
        """``GET /health``."""
        return dict(self._json("GET", "/health"))

    def robots(self) -> list[dict[str, Any]]:
        """Descriptions of the server's robots (joints, limits, family, tool)."""
        return list(self._json("GET", "/robots")["robots"])

    # -- kinematics ----------------------------------------
    def fk(self, q: Any, robot: str = "al5") -> np.ndarray:
        """Tool pose(s), as :meth:`lynxplan.arm.Arm.fk`: (5,) -> (4, 4), (N, 5) -> (N, 4, 4)."""
        q = np.asarray(q, dtype=float)
        if q.ndim == 2 and len(q) >= BINARY_BATCH:
            return np.asarray(self._binary("/fk", q, {"robot": robot})["T"])
        return np.array(self._json("POST", "/fk", {"robot": robot, "q": q})["T"], dtype=float)

    def ik(
        self,
        T: Any,
        *,
        q_reference: Any = None,
        select: str = "nearest",
        approach_only: bool = False,
        robot: str = "al5",
    ) -> Any:
        """IK, as the library: a (4, 4) pose gives :class:`~lynxplan.branches.IkResult`
        (:meth:`Arm.ik`, :meth:`Robot.ik`), (N, 4, 4) poses an :class:`~lynxplan.arm.ik.IkBatch`
        (:meth:`Arm.ik_batch`)."""
        T = np.asarray(T, dtype=float)
        if T.ndim == 3:
            if len(T) >= BINARY_BATCH and q_reference is None:
                fields = self._binary(
                    "/ik", T, {"robot": robot, "approach_only": str(approach_only).lower()}
                )
            else:
                body = {
                    "robot": robot,
                    "T": T,
                    "approach_only": approach_only,
                    "q_reference": None if q_reference is None else np.asarray(q_reference),
                }
                fields = self._json("POST", "/ik", body)
            return results.ik_batch(fields)
        body = {
            "robot": robot,
            "T": T,
            "select": select,
            "approach_only": approach_only,
            "q_reference": None if q_reference is None else np.asarray(q_reference),
        }
        return results.ik_result(self._json("POST", "/ik", body))

    # -- collision and trajectories ----------------------------------------
    def check(
        self,
        q: Any,
        obstacles: Sequence[Any] = (),
        t: Any = None,
        *,
        self_collision: bool = False,
        robot: str = "al5",
    ) -> Any:
        """Collision check against obstacles (library obstacle objects or JSON objects).

        With times ``t`` (N,) [s]: the library's :class:`~lynxplan.collision.CollisionReport`
        (:func:`~lynxplan.collision.check_trajectory`); without: the clearance (N, obstacles),
        in [m], as :func:`~lynxplan.collision.clearance_profile`.
        """
        body = {"robot": robot, "q": np.asarray(q, dtype=float),
                "obstacles": [results.obstacle_json(o) for o in obstacles],
                "t": None if t is None else np.asarray(t, dtype=float),
                "self_collision": self_collision}  # fmt: skip
        answer = self._json("POST", "/check", body)
        if t is None:
            return np.array(answer["clearance"], dtype=float).reshape(-1, len(obstacles))
        return results.collision_report(answer)

    def trajectory(
        self,
        waypoints: Any,
        method: str = "lspb",
        *,
        rate: float = 100.0,
        timing: tuple[float, float] | None = None,
        limits: Mapping[str, Any] | None = None,
        robot: str = "al5",
    ) -> list[Any]:
        """Free motions through ``waypoints`` (M, 5) [rad], one library
        :class:`~lynxplan.trajectory.Profile` per segment (``lspb``, ``ruckig``, ``toppra``)."""
        body = {
            "robot": robot,
            "waypoints": np.asarray(waypoints, dtype=float),
            "method": method,
            "rate": rate,
            "limits": dict(limits) if limits else None,
            "timing": None if timing is None else {"tt": timing[0], "ta": timing[1]},
        }
        return results.profiles(self._json("POST", "/trajectory", body))

    def plan(
        self,
        start: Any,
        goal: Any,
        obstacles: Sequence[Any] = (),
        *,
        seed: int = 0,
        time_limit: float = 1.0,
        options: Mapping[str, Any] | None = None,
        robot: str = "al5",
    ) -> Any:
        """Plan on the server, as :func:`lynxplan.planning.plan`: start (5,) [rad], goal (5,)
        joints or (4, 4) pose [m]; the library's
        :class:`~lynxplan.planning.PlannedTrajectory`."""
        body = {
            "robot": robot,
            "start": np.asarray(start, dtype=float),
            "goal": np.asarray(goal, dtype=float),
            "obstacles": [results.obstacle_json(o) for o in obstacles],
            "seed": seed,
            "time_limit": time_limit,
            "options": dict(options) if options else None,
        }
        return results.planned_trajectory(self._json("POST", "/plan", body))

    # -- runs ----------------------------------------
    def submit(self, scenario: str | Path | Mapping[str, Any], *, quick: bool = False) -> str:
        """Submit a scenario (file path, YAML text or mapping); the run id."""
        if isinstance(scenario, Mapping):
            content, media = orjson.dumps(dict(scenario)), "application/json"
        elif isinstance(scenario, Path) or "\n" not in str(scenario):
            try:
                content, media = Path(scenario).read_bytes(), "application/yaml"
            except OSError as exc:
                raise LynxplanError(f"cannot read scenario {scenario}: {exc.strerror}") from exc
        else:
            content, media = str(scenario).encode(), "application/yaml"
        answer = self._json(
            "POST",
            "/runs",
            content=content,
            params={"quick": str(quick).lower()},
            headers={"Content-Type": media},
        )
        return str(answer["id"])

    def status(self, run_id: str, wait: float = 0.0) -> RunResult:
        """The run's current record; with ``wait`` [s], the server holds the answer until the
        run ends or that time passed (long poll)."""
        fields = self._json("GET", f"/runs/{run_id}", params={"wait": wait} if wait else None)
        return results.run_result(fields)

    def wait(self, run_id: str, timeout: float = 3600.0) -> RunResult:
        """Wait until the run ends (``timeout`` in [s]), by long polls of at most 10 s."""
        deadline = time.monotonic() + timeout
        while (result := self.status(run_id, wait=min(10.0, timeout))).state not in _FINAL:
            if time.monotonic() > deadline:
                raise ServiceError(0, f"run {run_id} did not end within {timeout:g} s")
        return result

    def cancel(self, run_id: str) -> RunResult:
        """Cancel a queued or running run."""
        self._json("DELETE", f"/runs/{run_id}")
        return self.status(run_id)

    def artifact(self, run_id: str, name: str) -> bytes:
        """Content of one artifact."""
        return bytes(self._request("GET", f"/runs/{run_id}/artifacts/{name}").content)

    def download(
        self, result: RunResult, out_dir: str | Path, *, force: bool = False
    ) -> list[Path]:
        """Write every artifact of a run into ``out_dir`` as a local run would (all together,
        never touching a file lynxplan did not write, see :mod:`lynxplan.scenarios.folders`);
        their paths."""
        from lynxplan.scenarios.folders import staged_outputs

        names = [str(name) for name in result.artifacts]
        for name in names:
            if Path(name).is_absolute() or ".." in Path(name).parts:
                raise LynxplanError(f"run {result.id}: artifact name {name!r} leaves the folder")
        with staged_outputs(out_dir, force=force) as staging:
            for name in names:
                (staging / name).parent.mkdir(parents=True, exist_ok=True)
                (staging / name).write_bytes(self.artifact(result.id, name))
        return [Path(out_dir) / name for name in names]

    def run(
        self,
        scenario: str | Path | Mapping[str, Any],
        *,
        wait: bool = True,
        quick: bool = False,
        out_dir: str | Path | None = None,
        force: bool = False,
    ) -> RunResult:
        """Run a scenario on the server; with ``out_dir``, its artifacts are downloaded there
        (``force``: as ``lynxplan run --force``)."""
        run_id = self.submit(scenario, quick=quick)
        if not wait:
            return self.status(run_id)
        result = self.wait(run_id)
        if out_dir is not None and result.state == "succeeded":
            self.download(result, out_dir, force=force)
        return result


def run_remote(
    url: str, scenario: str | Path, out_dir: str | Path, *, quick: bool = False, force: bool = False
) -> int:
    """``lynxplan run --server URL``: run remotely, download the outputs, print the summary.

    The token comes from ``LYNXPLAN_TOKEN``. Returns the exit code (0 ok, 1 expectations failed).
    """
    import os

    with Client(url, token=os.environ.get("LYNXPLAN_TOKEN") or None) as client:
        result = client.run(scenario, quick=quick, out_dir=out_dir, force=force)
    if result.state != "succeeded":
        raise LynxplanError(f"scenario {scenario}: run {result.id} {result.state}: {result.error}")
    print(result.summary)
    library = result.result
    if library is not None and library.expectations:
        held = sum(e.passed for e in library.expectations)
        print(f"expectations: {held} of {len(library.expectations)} hold")
    print(f"outputs in {out_dir}/: {', '.join(result.artifacts)}")
    if not result.ok:
        print("failed expectations:")
        for failure in library.failed_expectations if library is not None else ():
            print(f"  - {failure}")
        return 1
    return 0


__all__ = ["BINARY_BATCH", "Client", "run_remote"]
