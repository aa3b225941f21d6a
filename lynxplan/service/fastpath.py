"""An ASGI front for the hot routes: their endpoints called directly, without FastAPI's router,
middleware stack and dependency machinery, which cost several times the whole IK of one pose
(measured: a bare uvicorn ASGI endpoint serves about three times the requests/s of a bare
FastAPI one on the same core).

The FastAPI routes of those paths stay in the application for the OpenAPI document and as the
fallback of other methods; errors are answered by the same mapping
(:func:`~lynxplan.service.problems.error_response`).
"""

from __future__ import annotations

from collections.abc import Awaitable, Callable

from fastapi import FastAPI
from fastapi.routing import APIRoute
from starlette.requests import Request
from starlette.responses import Response
from starlette.types import Receive, Scope, Send

from lynxplan.service.problems import error_response

Endpoint = Callable[[Request], Awaitable[Response]]


class FastPath:
    """ASGI app: requests to ``paths`` go straight to their endpoints (each takes the request
    only and decodes it itself); everything else, lifespan included, to ``app``."""

    def __init__(self, app: FastAPI, paths: tuple[str, ...]) -> None:
        self.app = app
        self.endpoints: dict[tuple[str, str], Endpoint] = {
            (method, route.path): route.endpoint
            for route in app.router.routes
            if isinstance(route, APIRoute) and route.path in paths
            for method in route.methods or ()
        }

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        endpoint = (
            self.endpoints.get((scope["method"], scope["path"]))
            if scope["type"] == "http"
            else None
        )
        if endpoint is None:
            await self.app(scope, receive, send)
            return
        request = Request(scope, receive)
        try:
            response = await endpoint(request)
        except Exception as exc:  # every error becomes problem+json, never a traceback
            response = error_response(exc, scope["method"], scope["path"])
        await response(scope, receive, send)


__all__ = ["FastPath"]
