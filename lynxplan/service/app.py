"""The FastAPI application: routes only (decoding in :mod:`.inputs`/:mod:`.wire`, computation in
:mod:`.compute`, runs in :mod:`.jobs`)."""

from __future__ import annotations

import mimetypes
import platform
from collections.abc import AsyncIterator
from contextlib import asynccontextmanager
from importlib import resources

import numpy as np
from fastapi import FastAPI
from starlette.responses import HTMLResponse, Response
from starlette.types import ASGIApp

from lynxplan import __version__
from lynxplan.service import kinematics_tasks, wire
from lynxplan.service.auth import Guard
from lynxplan.service.config import ServiceConfig
from lynxplan.service.fastpath import FastPath
from lynxplan.service.jobs import RunManager
from lynxplan.service.kinematics_routes import add_kinematics_routes
from lynxplan.service.problems import Problem, install_error_handlers
from lynxplan.service.robots import describe_robot, get_robot, robot_names
from lynxplan.service.run_routes import add_run_routes

API_VERSION = 1
#: Hot routes served by :class:`~lynxplan.service.fastpath.FastPath` in front of their FastAPI
#: twins; each endpoint takes only the request.
FAST_PATHS = ("/ik", "/fk", "/check", "/trajectory")


def create_app(config: ServiceConfig) -> ASGIApp:
    """The ASGI application: the host, origin, token and content-type checks (:mod:`.auth`) in
    front of the hot routes' fast path (:mod:`.fastpath`) in front of the FastAPI app; its run
    manager starts with the lifespan."""
    state: dict[str, RunManager] = {}

    @asynccontextmanager
    async def lifespan(_: FastAPI) -> AsyncIterator[None]:
        state["runs"] = RunManager(
            config.data_dir, workers=config.workers, timeout=config.run_timeout,
            memory_limit=config.run_memory, dask_scheduler=config.dask_scheduler,
        )  # fmt: skip
        get_robot("al5")  # load the model (and JIT caches) before the first request
        kinematics_tasks.ik_batch_arrays(np.eye(4)[None])
        compute_pool.start()  # warm in the background: /health answers meanwhile
        yield
        compute_pool.close()
        state.pop("runs").close()

    app = FastAPI(
        title="lynxplan",
        version=__version__,
        lifespan=lifespan,
        description="Kinematics, collision checks, trajectories and scenario runs.",
        docs_url=None,  # FastAPI's Swagger page loads its assets from a CDN: served below
        redoc_url=None,
    )
    install_error_handlers(app)

    def runs() -> RunManager:
        return state["runs"]

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

    compute_pool = add_kinematics_routes(app, config, runs)
    add_run_routes(app, config, runs)

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

    return Guard(FastPath(app, FAST_PATHS), config)


def _static(name: str) -> bytes:
    return (resources.files("lynxplan.service") / "static" / name).read_bytes()


def _static_exists(name: str) -> bool:
    return (resources.files("lynxplan.service") / "static" / name).is_file()
