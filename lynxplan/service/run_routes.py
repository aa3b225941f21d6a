"""The scenario run routes: submit, list, poll, cancel, download artifacts.

With named tokens (``--token-file`` of ``name:token`` lines) a caller lists, reads, cancels and
downloads only the runs its own token created; another caller's run is answered 404, like a run
that does not exist. Without tokens, or with one shared token, every caller sees every run.
"""

from __future__ import annotations

import asyncio
import mimetypes
import time
from collections.abc import Callable
from typing import Any

import orjson
from fastapi import FastAPI, Query, Request
from starlette.responses import FileResponse, Response

from lynxplan.exceptions import LynxplanError
from lynxplan.service import uploads, wire
from lynxplan.service.auth import OWNER_KEY
from lynxplan.service.config import ServiceConfig
from lynxplan.service.jobs import FINAL_STATES, RunManager, remove_tree, validate_scenario
from lynxplan.service.problems import Problem
from lynxplan.service.schemas import openapi_body

JSON = "application/json"
#: Period of the store checks of a long-polling GET /runs/{id}?wait=..., in [s].
RUN_POLL = 0.005
SCENARIO_MEDIA_TYPES = (
    "application/json",
    "application/yaml",
    "application/x-yaml",
    "text/yaml",
    "text/x-yaml",
)


def add_run_routes(app: FastAPI, config: ServiceConfig, runs: Callable[[], RunManager]) -> None:
    """Add the ``/runs`` routes to ``app``."""

    @app.post("/runs", status_code=202, tags=["runs"], openapi_extra=openapi_body("Scenario"))
    async def submit_run(request: Request, quick: bool = Query(False)) -> Response:
        kind = wire.media_type(request)
        if kind not in SCENARIO_MEDIA_TYPES:
            raise Problem(415, f"send the scenario as YAML or JSON. Got: {kind}", "Content-Type")
        manager = runs()
        source, scenario_kind, name, run_id = await _accept(request, kind, config, manager)
        owner = _owner(request, None) or ""
        record = manager.submit(source, scenario_kind, name, quick, owner, run_id)
        return wire.json_response(record.as_json(), status=202)

    @app.get("/runs", tags=["runs"])
    async def list_runs(
        request: Request, offset: int = Query(0, ge=0), limit: int = Query(50, ge=1, le=500)
    ) -> Response:
        records, total = runs().store.page(offset, limit, _owner(request, None))
        items = [{k: v for k, v in r.as_json().items() if k != "report"} for r in records]
        return wire.json_response(
            {"items": items, "total": total, "offset": offset, "limit": limit}
        )

    @app.get("/runs/{run_id}", tags=["runs"])
    async def get_run(
        request: Request,
        run_id: str,
        wait: float = Query(
            0.0,
            ge=0.0,
            le=60.0,
            description="Long poll: wait up to this many seconds for the run to end, in s.",
        ),
    ) -> Response:
        record = _record(runs(), run_id, request)
        deadline = time.monotonic() + wait
        while record.state not in FINAL_STATES and time.monotonic() < deadline:
            await asyncio.sleep(RUN_POLL)
            record = _record(runs(), run_id, request)
        return wire.json_response(record.as_json())

    @app.delete("/runs/{run_id}", tags=["runs"])
    async def cancel_run(request: Request, run_id: str) -> Response:
        record = _record(runs(), run_id, request)
        if record.state in FINAL_STATES and record.state != "cancelled":
            raise Problem(409, f"run {run_id} already ended ({record.state})", "run_id")
        cancelled = runs().cancel(run_id)
        assert cancelled is not None
        return wire.json_response(cancelled.as_json())

    @app.get("/runs/{run_id}/artifacts/{name:path}", tags=["runs"])
    async def artifact(request: Request, run_id: str, name: str) -> Response:
        _record(runs(), run_id, request)
        path = runs().artifact(run_id, name)
        if path is None:
            raise Problem(404, f"run {run_id} has no artifact {name!r}", "name")
        media = mimetypes.guess_type(path.name)[0] or "application/octet-stream"
        return FileResponse(path, media_type=media)


async def _accept(
    request: Request, kind: str, config: ServiceConfig, manager: RunManager
) -> tuple[str, str, str, str | None]:
    """The scenario text of ``POST /runs`` (a plain scenario, or a bundle's, its files
    installed in a new run folder), validated: (text, kind, name, run id of that folder)."""
    # A bundle carries base64 files (4 bytes per 3) besides the scenario.
    limit = config.max_scenario + (config.max_upload // 3 + 1) * 4 if kind == JSON else 0
    raw = await wire.read_body(request, limit or config.max_scenario)
    try:
        source = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise Problem(422, "the scenario must be UTF-8 text", "body") from None
    bundle = None
    if kind == JSON:
        value = wire.parse_json_object(raw)
        if uploads.is_bundle(value):
            if config.dask_scheduler:
                raise Problem(422, "uploaded robots run on the local pool only; this "
                              "server runs on Dask", "files")  # fmt: skip
            bundle = uploads.decode_bundle(value, config.max_upload)
        elif len(raw) > config.max_scenario:
            raise Problem(413, f"the scenario exceeds the limit of {config.max_scenario} "
                          "bytes", "body")  # fmt: skip
    run_id = None
    if bundle is not None:
        run_id, folder = manager.new_run()
        try:
            source = orjson.dumps(uploads.install(bundle, folder / "files")).decode()
        except Problem:
            remove_tree(folder)
            raise
    try:
        scenario_kind, name = await asyncio.to_thread(validate_scenario, source, bundle is not None)
    except LynxplanError as exc:
        if run_id is not None:
            remove_tree(manager.run_dir(run_id))
        location = getattr(exc, "location", "") or None
        reason = getattr(exc, "reason", str(exc))
        raise Problem(422, f"scenario: {reason}", location) from None
    return source, scenario_kind, name, run_id


def _owner(request: Request, default: str | None) -> str | None:
    """The name of the caller's token (named tokens), else ``default``."""
    owner = request.scope.get(OWNER_KEY)
    return default if owner is None else str(owner)


def _record(manager: RunManager, run_id: str, request: Request) -> Any:
    """The run, if the caller may see it (its own, or any without named tokens); else 404."""
    record = manager.store.get(run_id)
    owner = _owner(request, None)
    if record is None or (owner is not None and record.owner != owner):
        raise Problem(404, f"no run {run_id[:40]!r}", "run_id")
    return record
