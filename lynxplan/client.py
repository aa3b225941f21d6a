"""A Python client of ``lynxplan serve`` that returns the library's own types.

Example::

    from lynxplan.client import Client

    with Client("http://127.0.0.1:8000") as client:
        T = client.fk([0.1, 0.5, -0.5, 0.3, 0.2])       # (4, 4) ndarray, as Arm.fk
        result = client.ik(T)                            # IkResult, as Arm.ik
        batch = client.ik(many_poses)                    # IkBatch, as Arm.ik_batch (binary)
        run = client.run("scenarios/ok_task.yaml", out_dir="out")

Numbers travel as shortest round-trip JSON or raw float64, so results equal the library's bit
for bit.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import orjson

from lynxplan.exceptions import LynxplanError

#: Batches at least this large travel as binary arrays instead of JSON.
BINARY_BATCH = 1_000
_FINAL = ("succeeded", "failed", "cancelled", "interrupted")


class ServiceError(LynxplanError):
    """The server answered with a problem (RFC 9457).

    Attributes:
        status: HTTP status code.
        detail: The problem's detail line.
        field: The offending request field, or None.
    """

    def __init__(self, status: int, detail: str, field: str | None = None) -> None:
        self.status, self.detail, self.field = status, detail, field
        where = f" (field {field})" if field else ""
        super().__init__(f"server answered {status}: {detail}{where}")


@dataclass(frozen=True)
class RunResult:
    """A scenario run on the server.

    Attributes:
        id: Run id.
        state: ``queued``, ``running``, ``succeeded``, ``failed``, ``cancelled``, ``interrupted``.
        ok: Every expectation held (None until succeeded).
        summary: The run's summary paragraph (as printed by ``lynxplan run``).
        error: Failed expectations or the error of a failed run.
        report: Its ``report.json`` content, if any.
        artifacts: Relative names of its output files.
        timings: Durations on the server, in [s].
    """

    id: str
    state: str
    ok: bool | None
    summary: str | None
    error: str | None
    report: Any
    artifacts: tuple[str, ...]
    timings: Mapping[str, float]

    @property
    def result(self) -> Any:
        """The library's :class:`lynxplan.scenarios.Result`, rebuilt from the run's report
        (None until the run succeeded)."""
        from lynxplan.scenarios.base import ExpectationResult, Result

        if self.state != "succeeded" or not isinstance(self.report, Mapping):
            return None
        r = self.report
        return Result(
            kind=r["kind"],
            schema_version=r["schema_version"],
            name=r["name"],
            inputs=r["inputs"],
            metrics=r["metrics"],
            expectations=tuple(ExpectationResult(**e) for e in r["expectations"]),
            artifacts=tuple(r["artifacts"]),
            timing=r["timing"],
            details=r["details"],
            summary=self.summary or "",
        )


class Client:
    """HTTP client of a lynxplan server.

    Args:
        url: Base URL, e.g. ``"http://127.0.0.1:8000"``.
        token: Bearer token, if the server requires one.
        timeout: Per-request timeout, in [s].
    """

    def __init__(self, url: str, token: str | None = None, timeout: float = 120.0) -> None:
        import httpx

        headers = {"Authorization": f"Bearer {token}"} if token else {}
        self._http = httpx.Client(base_url=url.rstrip("/"), headers=headers, timeout=timeout)

    def __enter__(self) -> Client:
        return self

    def __exit__(self, *_: object) -> None:
        self.close()

    def close(self) -> None:
        """Close the connection pool."""
        self._http.close()

    # -- plumbing ----------------------------------------
    def _request(self, method: str, path: str, **kwargs: Any) -> Any:
        import httpx

        try:
            response = self._http.request(method, path, **kwargs)
        except httpx.HTTPError as exc:
            raise ServiceError(0, f"cannot reach {self._http.base_url}: {exc}") from exc
        if response.status_code >= 400:
            try:
                problem = response.json()
            except ValueError:
                problem = {"detail": response.text[:200]}
            raise ServiceError(
                response.status_code, str(problem.get("detail", "")), problem.get("field")
            )
        return response

    def _json(self, method: str, path: str, body: Any = None, **kwargs: Any) -> Any:
        if body is not None:
            kwargs["content"] = orjson.dumps(body, option=orjson.OPT_SERIALIZE_NUMPY)
            kwargs["headers"] = {"Content-Type": "application/json"}
        return orjson.loads(self._request(method, path, **kwargs).content)

    def _binary(self, path: str, array: np.ndarray, params: dict[str, Any]) -> dict[str, Any]:
        from lynxplan.service.wire import read_arrays

        response = self._request(
            "POST", path, content=np.ascontiguousarray(array, dtype="<f8").tobytes(),
            params=params, headers={"Content-Type": "application/octet-stream",
                                    "X-Shape": ",".join(map(str, array.shape)),
                                    "Accept": "application/x-npy-stream"},
        )  # fmt: skip
        arrays: dict[str, Any] = read_arrays(
            response.content,
            response.headers.get("content-type", ""),
            response.headers.get("X-Arrays", ""),
        )
        arrays.update(orjson.loads(response.headers.get("X-Result", "{}")))
        return arrays

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
        """IK, as the library: a (4, 4) pose gives :class:`~lynxplan.arm.model.IkResult`
        (:meth:`Arm.ik`), (N, 4, 4) poses an :class:`~lynxplan.arm.ik.IkBatch`
        (:meth:`Arm.ik_batch`)."""
        from lynxplan.arm.ik import IkBatch

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
            return IkBatch(
                *(
                    _read_only(np.asarray(fields[name], dtype=dtype))
                    for name, dtype in _IK_BATCH_FIELDS
                )
            )
        body = {
            "robot": robot,
            "T": T,
            "select": select,
            "approach_only": approach_only,
            "q_reference": None if q_reference is None else np.asarray(q_reference),
        }
        return _ik_result(self._json("POST", "/ik", body))

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
                "obstacles": [_obstacle_json(o) for o in obstacles],
                "t": None if t is None else np.asarray(t, dtype=float),
                "self_collision": self_collision}  # fmt: skip
        answer = self._json("POST", "/check", body)
        if t is None:
            return np.array(answer["clearance"], dtype=float).reshape(-1, len(obstacles))
        from lynxplan.collision import ClearanceRecord, CollisionReport, Contact

        def record(fields: dict[str, Any]) -> ClearanceRecord:
            return ClearanceRecord(**{k: _number(v) for k, v in fields.items()})

        return CollisionReport(
            min_clearance=record(answer["min_clearance"]),
            segments=tuple(record(r) for r in answer["segments"]),
            segment_ids=tuple(answer["segment_ids"]),
            contacts=tuple(Contact(**c) for c in answer["contacts"]),
            certified=answer["certified"],
            refined_intervals=answer["refined_intervals"],
            exact_queries=answer["exact_queries"],
        )

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
        from lynxplan.trajectory import Profile

        body = {
            "robot": robot,
            "waypoints": np.asarray(waypoints, dtype=float),
            "method": method,
            "rate": rate,
            "limits": dict(limits) if limits else None,
            "timing": None if timing is None else {"tt": timing[0], "ta": timing[1]},
        }
        answer = self._json("POST", "/trajectory", body)
        return [
            Profile(
                np.array(s["t"], dtype=float),
                np.array(s["q"], dtype=float),
                np.array(s["qd"], dtype=float),
                np.array(s["qdd"], dtype=float),
                time_scale=s["time_scale"],
                requested_duration=s["requested_duration"],
            )
            for s in answer["segments"]
        ]

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
        from lynxplan.collision import ClearanceRecord
        from lynxplan.planning import PlannedTrajectory, PlannerOptions, PlanningStats
        from lynxplan.planning.verify import VerificationReport

        body = {
            "robot": robot,
            "start": np.asarray(start, dtype=float),
            "goal": np.asarray(goal, dtype=float),
            "obstacles": [_obstacle_json(o) for o in obstacles],
            "seed": seed,
            "time_limit": time_limit,
            "options": dict(options) if options else None,
        }
        a = self._json("POST", "/plan", body)
        v = dict(a["verification"])
        v["min_clearance"] = ClearanceRecord(
            **{k: _number(x) for k, x in v["min_clearance"].items()}
        )
        option_fields: dict[str, Any] = {
            k: tuple(x) if isinstance(x, list) else x for k, x in a["options"].items()
        }
        return PlannedTrajectory(
            waypoints=_read_only(np.array(a["waypoints"], dtype=float)),
            t=_read_only(np.array(a["t"], dtype=float)),
            q=_read_only(np.array(a["q"], dtype=float)),
            qd=_read_only(np.array(a["qd"], dtype=float)),
            qdd=_read_only(np.array(a["qdd"], dtype=float)),
            segment=_read_only(np.array(a["segment"], dtype=np.asarray(0).dtype)),
            verification=VerificationReport(**v),
            goal_label=a["goal_label"],
            goal_index=a["goal_index"],
            path_length=a["path_length"],
            seed=a["seed"],
            stats=PlanningStats(**a["stats"]),
            options=PlannerOptions(**option_fields),
        )  # fmt: skip

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
        return RunResult(
            fields["id"],
            fields["state"],
            fields["ok"],
            fields["summary"],
            fields["error"],
            fields["report"],
            tuple(fields["artifacts"]),
            fields["timings"],
        )

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

    def download(self, result: RunResult, out_dir: str | Path) -> list[Path]:
        """Write every artifact of a run into ``out_dir``; their paths."""
        paths = []
        for name in result.artifacts:
            path = Path(out_dir) / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(self.artifact(result.id, name))
            paths.append(path)
        return paths

    def run(
        self,
        scenario: str | Path | Mapping[str, Any],
        *,
        wait: bool = True,
        quick: bool = False,
        out_dir: str | Path | None = None,
    ) -> RunResult:
        """Run a scenario on the server; with ``out_dir``, its artifacts are downloaded there."""
        run_id = self.submit(scenario, quick=quick)
        if not wait:
            return self.status(run_id)
        result = self.wait(run_id)
        if out_dir is not None and result.state == "succeeded":
            self.download(result, out_dir)
        return result


_IK_BATCH_FIELDS = (
    ("q", float),
    ("within_limits", bool),
    ("orientation_error", float),
    ("status", np.int8),
    ("reach_miss", float),
    ("deviation", float),
)


def _read_only(array: np.ndarray) -> np.ndarray:
    array.setflags(write=False)
    return array


def _number(value: Any) -> Any:
    return float("nan") if value is None else value


def _ik_result(fields: dict[str, Any]) -> Any:
    from lynxplan.arm.model import IkResult, IkSolution

    solutions = tuple(
        IkSolution(
            _read_only(np.array(s["q"], dtype=float)),
            s["branch"],
            s["within_limits"],
            s["position_error"],
            s["orientation_error"],
        )
        for s in fields["solutions"]
    )
    return IkResult(solutions, fields["selected"], fields["orientation_residual"])


def _obstacle_json(obstacle: Any) -> dict[str, Any]:
    if isinstance(obstacle, Mapping):
        return dict(obstacle)
    kind = type(obstacle).__name__.removesuffix("Obstacle").lower()
    fields = {"type": kind, "name": obstacle.name, "centre": np.asarray(obstacle.centre)}
    for name in ("size", "radius", "length"):
        if hasattr(obstacle, name):
            fields[name] = getattr(obstacle, name)
    if kind != "sphere":
        fields["rotation"] = np.asarray(obstacle.rotation)
    return fields


__all__ = ["BINARY_BATCH", "Client", "RunResult", "ServiceError", "run_remote"]


def run_remote(url: str, scenario: str | Path, out_dir: str | Path, *, quick: bool = False) -> int:
    """``lynxplan run --server URL``: run remotely, download the outputs, print the summary.

    The token comes from ``LYNXPLAN_TOKEN``. Returns the exit code (0 ok, 1 expectations failed).
    """
    import os

    with Client(url, token=os.environ.get("LYNXPLAN_TOKEN") or None) as client:
        result = client.run(scenario, quick=quick, out_dir=out_dir)
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
