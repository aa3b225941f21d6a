"""The FastAPI application: routes only (decoding in :mod:`.inputs`/:mod:`.wire`, computation in
:mod:`.compute`, runs in :mod:`.jobs`)."""

from __future__ import annotations

import asyncio
import mimetypes
import platform
import time
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from importlib import resources
from typing import Any

import numpy as np
from fastapi import FastAPI, Query, Request
from fastapi.exceptions import RequestValidationError
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.responses import FileResponse, HTMLResponse, Response

from lynxplan import __version__
from lynxplan.exceptions import LynxplanError
from lynxplan.service import compute, inputs, wire
from lynxplan.service.auth import TokenMiddleware
from lynxplan.service.config import ServiceConfig
from lynxplan.service.jobs import FINAL_STATES, RunManager, validate_scenario
from lynxplan.service.problems import Problem, problem_response
from lynxplan.service.robots import describe_robot, get_robot, robot_names
from lynxplan.service.schemas import openapi_body

API_VERSION = 1
#: Hot routes served by plain Starlette routes in front of their FastAPI twins (see
#: :func:`_fast_routes`); each endpoint takes only the request.
FAST_PATHS = ("/ik", "/fk", "/check", "/trajectory")
#: Period of the store checks of a long-polling GET /runs/{id}?wait=..., in [s].
RUN_POLL = 0.005
#: Batches at least this large are solved off the event loop (or on Dask when configured).
THREAD_BATCH = 2_000
SCENARIO_MEDIA_TYPES = (
    "application/json",
    "application/yaml",
    "application/x-yaml",
    "text/yaml",
    "text/x-yaml",
    "text/plain",
)


def create_app(config: ServiceConfig) -> FastAPI:
    """The application; its run manager starts with the app's lifespan."""
    state: dict[str, RunManager] = {}

    @asynccontextmanager
    async def lifespan(_: FastAPI) -> AsyncIterator[None]:
        state["runs"] = RunManager(
            config.data_dir, workers=config.workers, timeout=config.run_timeout,
            memory_limit=config.run_memory, dask_scheduler=config.dask_scheduler,
        )  # fmt: skip
        get_robot("al5")  # load the model (and JIT caches) before the first request
        compute.ik_batch_arrays(np.eye(4)[None])
        yield
        state.pop("runs").close()

    app = FastAPI(
        title="lynxplan",
        version=__version__,
        lifespan=lifespan,
        description="Kinematics, collision checks, trajectories and scenario runs.",
        docs_url=None,  # FastAPI's Swagger page loads its assets from a CDN: served below
        redoc_url=None,
    )
    _install_error_handlers(app)
    if config.token:
        app.add_middleware(TokenMiddleware, token=config.token)

    view_lock = asyncio.Lock()

    def runs() -> RunManager:
        return state["runs"]

    async def json_body(request: Request) -> dict[str, Any]:
        return wire.parse_json_object(await wire.read_body(request, config.max_body))

    def batch_limit(request: Request) -> int:
        return config.max_batch if wire.is_binary(request) else config.max_json_batch

    # -- meta ----------------------------------------
    @app.get("/health", tags=["meta"])
    async def health() -> Response:
        return wire.json_response({"status": "ok"})

    @app.get("/version", tags=["meta"])
    async def version() -> Response:
        import pinocchio

        return wire.json_response(
            {
                "lynxplan": __version__,
                "api": API_VERSION,
                "python": platform.python_version(),
                "pinocchio": pinocchio.__version__,
                "executor": "dask" if config.dask_scheduler else "local",
            }
        )

    @app.get("/robots", tags=["robots"])
    async def robots() -> Response:
        return wire.json_response({"robots": [describe_robot(n) for n in robot_names()]})

    @app.get("/robots/{name}", tags=["robots"])
    async def robot(name: str) -> Response:
        return wire.json_response(describe_robot(name))

    # -- kinematics ----------------------------------------
    @app.post("/fk", tags=["kinematics"], openapi_extra=openapi_body("FkRequest", binary=True))
    async def fk(request: Request) -> Response:
        # Query options are read by hand: FastAPI's parameter machinery costs ~0.3 ms a request.
        robot = request.query_params.get("robot", "al5") if request.scope["query_string"] else "al5"
        if wire.is_binary(request):
            body: dict[str, Any] = {"robot": robot}
            q_value: Any = wire.decode_binary(
                request, await wire.read_body(request, config.max_body), "q"
            )
        else:
            body = await json_body(request)
            q_value = body.get("q")
        arm = get_robot(inputs.robot_name(body))
        if q_value is None:
            raise Problem(422, "q is required: joint angles (5,) or (N, 5) in rad", "q")
        q = wire.as_array(q_value, "q", (5,), limit=batch_limit(request))
        result = await _maybe_threaded(len(q) if q.ndim == 2 else 1, compute.fk_arrays, arm, q)
        if wire.wants_binary(request):
            return wire.arrays_response(
                request, {"T": result["T"]}, {"residual": result["residual"]}
            )
        return wire.json_response(result)

    @app.post("/ik", tags=["kinematics"], openapi_extra=openapi_body("IkRequest", binary=True))
    async def ik(
        request: Request,
    ) -> Response:
        start = time.perf_counter()
        params = request.query_params if request.scope["query_string"] else {}
        robot = params.get("robot", "al5")
        approach_only = inputs.query_flag(params, "approach_only", False)
        verify = inputs.query_flag(params, "verify", True)
        if wire.is_binary(request):
            raw = await wire.read_body(request, config.max_body)
            body: dict[str, Any] = {"robot": robot, "approach_only": approach_only}
            T = wire.as_array(
                wire.decode_binary(request, raw, "T"), "T", (4, 4), limit=config.max_batch
            )
            batch, only_approach = T.ndim == 3, approach_only
        else:
            body = await json_body(request)
            T, batch, only_approach = inputs.ik_target(body, config.max_json_batch)
        arm = get_robot(inputs.robot_name(body))
        if not batch:
            select = inputs.choice(body, "select", ("nearest", "report"))
            result, residual = compute.ik_single(
                arm, T, inputs.reference(body, None), select, only_approach
            )
            return wire.json_response(_ik_single_json(result, residual))
        reference = inputs.reference(body, len(T))
        arrays = await _ik_batch(runs(), config, T, reference, only_approach, verify)
        if wire.wants_binary(request):
            response = wire.arrays_response(request, arrays, {"count": len(T)})
        else:
            response = wire.json_response({"count": len(T), **arrays})
        # Server time from the first body byte to the encoded answer (RFC Server-Timing).
        response.headers["Server-Timing"] = f"app;dur={1e3 * (time.perf_counter() - start):.3f}"
        return response

    # -- collision and trajectories ----------------------------------------
    @app.post("/check", tags=["collision"], openapi_extra=openapi_body("CheckRequest"))
    async def check(request: Request) -> Response:
        body = await json_body(request)
        arm = get_robot(inputs.robot_name(body))
        q = wire.as_array(body.get("q"), "q", (5,), limit=config.max_json_batch)
        t = None if body.get("t") is None else wire.as_array(body["t"], "t", (), batch=True)
        if t is not None and t.shape != (len(q.reshape(-1, 5)),):
            raise Problem(422, f"t must have shape ({len(q.reshape(-1, 5))},). Got: {t.shape}", "t")
        obstacles = _obstacles(body)
        self_collision = inputs.flag(body, "self_collision")
        result = await asyncio.to_thread(compute.check_arrays, arm, q, t, obstacles, self_collision)
        return wire.json_response(result)

    @app.post("/trajectory", tags=["trajectory"], openapi_extra=openapi_body("TrajectoryRequest"))
    async def trajectory(request: Request) -> Response:
        body = await json_body(request)
        arm = get_robot(inputs.robot_name(body))
        waypoints = wire.as_array(body.get("waypoints"), "waypoints", (5,), limit=1000)
        if waypoints.ndim != 2 or len(waypoints) < 2:
            raise Problem(
                422, "waypoints must hold at least two configurations (M, 5)", "waypoints"
            )
        method = inputs.choice(body, "method", ("lspb", "ruckig", "toppra"))
        rate = inputs.number(body, "rate", 100.0, 1.0, 10_000.0)
        timing = _timing(body) if method == "lspb" else None
        limits = inputs.motion_limits(body, arm)
        profiles = await asyncio.to_thread(
            compute.trajectory_profiles, arm, waypoints, method, rate, limits, timing
        )
        return wire.json_response(
            {
                "method": method,
                "duration": float(sum(p.t[-1] for p in profiles)),
                "segments": [p._asdict() for p in profiles],
            }
        )

    @app.post("/plan", tags=["planning"], openapi_extra=openapi_body("PlanRequest"))
    async def plan(request: Request) -> Response:
        body = await json_body(request)
        arm = get_robot(inputs.robot_name(body))
        start = wire.as_array(body.get("start"), "start", (5,), batch=False)
        goal_value = body.get("goal")
        goal_shape = (4, 4) if isinstance(goal_value, list) and goal_value and isinstance(
            goal_value[0], list) else (5,)  # fmt: skip
        goal = wire.as_array(goal_value, "goal", goal_shape, batch=False)
        obstacles = _obstacles(body)
        seed = int(inputs.number(body, "seed", 0, 0, 2**31 - 1))
        budget = inputs.number(body, "time_limit", 1.0, 1e-3, compute.MAX_PLAN_TIME)
        options = body.get("options") or {}
        if not isinstance(options, dict):
            raise Problem(422, "options must be an object", "options")
        try:
            result = await asyncio.to_thread(
                compute.plan_json, arm, start, goal, obstacles, seed, budget, options
            )
        except TypeError as exc:  # an unknown option name
            raise Problem(422, f"options: {exc}".split(".__init__()")[-1], "options") from None
        return wire.json_response(result)

    @app.post("/view", tags=["kinematics"], openapi_extra=openapi_body("FkRequest"))
    async def view(request: Request) -> Response:
        body = await json_body(request)
        arm = get_robot(inputs.robot_name(body))
        q = wire.as_array(body.get("q"), "q", (5,), batch=False)
        async with view_lock:  # one meshcat server process at a time
            html = await asyncio.to_thread(compute.view_html, arm, q)
        return HTMLResponse(html)

    # -- runs ----------------------------------------
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

    # -- web page ----------------------------------------
    @app.get("/", include_in_schema=False)
    async def page() -> Response:
        return HTMLResponse(_static("index.html").decode())

    @app.get("/docs", include_in_schema=False)
    async def docs() -> Response:
        return HTMLResponse(_static("docs.html").decode())

    @app.get("/static/{name}", include_in_schema=False)
    async def static(name: str) -> Response:
        if "/" in name or name.startswith(".") or not _static_exists(name):
            raise Problem(404, f"no static file {name!r}", "name")
        media = mimetypes.guess_type(name)[0] or "application/octet-stream"
        return Response(_static(name), media_type=media)

    _fast_routes(app, FAST_PATHS)
    return app


def _fast_routes(app: FastAPI, paths: tuple[str, ...]) -> None:
    """Serve ``paths`` by plain Starlette routes placed first (the FastAPI routes stay, for the
    OpenAPI document only): FastAPI's route matching and dependency solving cost more than the
    whole IK of one pose. Their endpoints take the request only and decode it themselves."""
    from fastapi.routing import APIRoute
    from starlette.routing import Route

    fast = [
        Route(
            route.path, route.endpoint, methods=sorted(route.methods or ()), include_in_schema=False
        )
        for route in app.router.routes
        if isinstance(route, APIRoute) and route.path in paths
    ]
    app.router.routes[:0] = fast


def _static(name: str) -> bytes:
    return (resources.files("lynxplan.service") / "static" / name).read_bytes()


def _static_exists(name: str) -> bool:
    return (resources.files("lynxplan.service") / "static" / name).is_file()


async def _maybe_threaded(count: int, function: Any, *args: Any) -> Any:
    if count >= THREAD_BATCH:
        return await asyncio.to_thread(function, *args)
    return function(*args)


async def _ik_batch(
    manager: RunManager,
    config: ServiceConfig,
    T: np.ndarray,
    reference: Any,
    approach: bool,
    verify: bool,
) -> dict[str, np.ndarray]:
    from lynxplan.service.jobs import DaskPool

    if isinstance(manager.pool, DaskPool) and len(T) >= config.dask_batch:
        future = manager.pool.client.submit(
            compute.ik_batch_arrays, T, reference, approach, verify, pure=False
        )
        result: dict[str, np.ndarray] = await asyncio.to_thread(future.result)
        return result
    arrays: dict[str, np.ndarray] = await _maybe_threaded(
        len(T), compute.ik_batch_arrays, T, reference, approach, verify
    )
    return arrays


def _ik_single_json(result: Any, residual: float) -> dict[str, Any]:
    selected = result.selected
    return {
        "q": None if selected is None else result.solutions[selected].q,
        "selected": selected,
        "branch": None if selected is None else result.solutions[selected].branch,
        "orientation_residual": result.orientation_residual,
        "position_residual": residual,
        "solutions": [s._asdict() for s in result.solutions],
    }


def _timing(body: dict[str, Any]) -> tuple[float, float] | None:
    timing = body.get("timing")
    if timing is None:
        return None
    if not isinstance(timing, dict) or set(timing) != {"tt", "ta"}:
        raise Problem(422, "timing must be an object {tt, ta} in s", "timing")
    return (
        inputs.number(timing, "tt", 0.0, 1e-6, 3600.0),
        inputs.number(timing, "ta", 0.0, 1e-9, 1800.0),
    )


def _obstacles(body: dict[str, Any]) -> list[Any]:
    try:
        return compute.build_obstacles(inputs.obstacle_specs(body))
    except (KeyError, TypeError) as exc:
        raise Problem(422, f"obstacle: {str(exc).strip(chr(39))}", "obstacles") from None


def _record(manager: RunManager, run_id: str) -> Any:
    record = manager.store.get(run_id)
    if record is None:
        raise Problem(404, f"no run {run_id!r}", "run_id")
    return record


def _install_error_handlers(app: FastAPI) -> None:
    @app.exception_handler(Problem)
    async def on_problem(request: Request, exc: Problem) -> Response:
        return problem_response(exc.status, exc.detail, exc.field, request.url.path)

    @app.exception_handler(StarletteHTTPException)
    async def on_http(request: Request, exc: StarletteHTTPException) -> Response:
        detail = exc.detail if isinstance(exc.detail, str) else str(exc.status_code)
        if exc.status_code == 404:
            detail = f"no route {request.method} {request.url.path}"
        return problem_response(exc.status_code, detail, None, request.url.path)

    @app.exception_handler(RequestValidationError)
    async def on_validation(request: Request, exc: RequestValidationError) -> Response:
        first = exc.errors()[0] if exc.errors() else {"loc": (), "msg": "invalid request"}
        loc = [str(part) for part in first.get("loc", ())][1:]
        return problem_response(
            422, str(first.get("msg", "invalid")), ".".join(loc) or None, request.url.path
        )

    @app.exception_handler(LynxplanError)
    async def on_domain(request: Request, exc: LynxplanError) -> Response:
        field = getattr(exc, "name", None)
        return problem_response(
            422, str(exc), field if isinstance(field, str) else None, request.url.path
        )

    @app.exception_handler(Exception)
    async def on_crash(request: Request, exc: Exception) -> Response:
        return problem_response(
            500, f"internal error ({type(exc).__name__})", None, request.url.path
        )
