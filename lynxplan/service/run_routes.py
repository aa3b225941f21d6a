"""The scenario run routes: submit, list, poll, cancel, download artifacts."""

from __future__ import annotations

import asyncio
import mimetypes
import time
from collections.abc import Callable
from typing import Any

from fastapi import FastAPI, Query, Request
from starlette.responses import FileResponse, Response

from lynxplan.exceptions import LynxplanError
from lynxplan.service import wire
from lynxplan.service.config import ServiceConfig
from lynxplan.service.jobs import FINAL_STATES, RunManager, validate_scenario
from lynxplan.service.problems import Problem
from lynxplan.service.schemas import openapi_body

#: Period of the store checks of a long-polling GET /runs/{id}?wait=..., in [s].
RUN_POLL = 0.005
SCENARIO_MEDIA_TYPES = (
    "application/json",
    "application/yaml",
    "application/x-yaml",
    "text/yaml",
    "text/x-yaml",
    "text/plain",
)


def add_run_routes(app: FastAPI, config: ServiceConfig, runs: Callable[[], RunManager]) -> None:
    """Add the ``/runs`` routes to ``app``."""

    @app.post("/runs", status_code=202, tags=["runs"], openapi_extra=openapi_body("Scenario"))
    async def submit_run(request: Request, quick: bool = Query(False)) -> Response:
        kind = wire.media_type(request)
        if kind not in SCENARIO_MEDIA_TYPES:
            raise Problem(415, f"send the scenario as YAML or JSON. Got: {kind}", "Content-Type")
        raw = await wire.read_body(request, config.max_scenario)
        try:
            source = raw.decode("utf-8")
        except UnicodeDecodeError:
            raise Problem(422, "the scenario must be UTF-8 text", "body") from None
        if kind == "application/json":
            wire.parse_json_object(raw)
        try:
            scenario_kind, name = await asyncio.to_thread(validate_scenario, source)
        except LynxplanError as exc:
            location = getattr(exc, "location", "") or None
            reason = getattr(exc, "reason", str(exc))
            raise Problem(422, f"scenario: {reason}", location) from None
        record = runs().submit(source, scenario_kind, name, quick)
        return wire.json_response(record.as_json(), status=202)

    @app.get("/runs", tags=["runs"])
    async def list_runs(
        offset: int = Query(0, ge=0), limit: int = Query(50, ge=1, le=500)
    ) -> Response:
        records, total = runs().store.page(offset, limit)
        items = [{k: v for k, v in r.as_json().items() if k != "report"} for r in records]
        return wire.json_response(
            {"items": items, "total": total, "offset": offset, "limit": limit}
        )

    @app.get("/runs/{run_id}", tags=["runs"])
    async def get_run(
        run_id: str,
        wait: float = Query(
            0.0,
            ge=0.0,
            le=60.0,
            description="Long poll: wait up to this many seconds for the run to end, in s.",
        ),
    ) -> Response:
        record = _record(runs(), run_id)
        deadline = time.monotonic() + wait
        while record.state not in FINAL_STATES and time.monotonic() < deadline:
            await asyncio.sleep(RUN_POLL)
            record = _record(runs(), run_id)
        return wire.json_response(record.as_json())

    @app.delete("/runs/{run_id}", tags=["runs"])
    async def cancel_run(run_id: str) -> Response:
        record = _record(runs(), run_id)
        if record.state in FINAL_STATES and record.state != "cancelled":
            raise Problem(409, f"run {run_id} already ended ({record.state})", "run_id")
        cancelled = runs().cancel(run_id)
        assert cancelled is not None
        return wire.json_response(cancelled.as_json())

    @app.get("/runs/{run_id}/artifacts/{name:path}", tags=["runs"])
    async def artifact(run_id: str, name: str) -> Response:
        _record(runs(), run_id)
        path = runs().artifact(run_id, name)
        if path is None:
            raise Problem(404, f"run {run_id} has no artifact {name!r}", "name")
        media = mimetypes.guess_type(path.name)[0] or "application/octet-stream"
        return FileResponse(path, media_type=media)


def _record(manager: RunManager, run_id: str) -> Any:
    record = manager.store.get(run_id)
    if record is None:
        raise Problem(404, f"no run {run_id!r}", "run_id")
    return record
