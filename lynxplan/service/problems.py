"""RFC 9457 problem details: one exception type and one response builder for every error."""

from __future__ import annotations

from typing import Any

import orjson
from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.responses import Response

from lynxplan.exceptions import LynxplanError

PROBLEM_MEDIA_TYPE = "application/problem+json"

_TITLES = {
    400: "Bad request",
    401: "Unauthorized",
    404: "Not found",
    405: "Method not allowed",
    409: "Conflict",
    413: "Content too large",
    415: "Unsupported media type",
    422: "Unprocessable content",
    500: "Internal server error",
    503: "Service unavailable",
}


class Problem(Exception):  # noqa: N818 (named after RFC 9457)
    """An error answered as ``application/problem+json``.

    Attributes:
        status: HTTP status code.
        detail: One line a client can act on.
        field: The offending request field (dotted path such as ``T[2]``), or None.
    """

    def __init__(self, status: int, detail: str, field: str | None = None) -> None:
        self.status = status
        self.detail = detail
        self.field = field
        super().__init__(detail)


def problem_body(status: int, detail: str, field: str | None, instance: str) -> dict[str, Any]:
    """The JSON object of a problem: type, title, status, detail, instance and ``field``."""
    body: dict[str, Any] = {
        "type": "about:blank",
        "title": _TITLES.get(status, "Error"),
        "status": status,
        "detail": detail,
        "instance": instance,
    }
    if field is not None:
        body["field"] = field
    return body


def problem_response(
    status: int, detail: str, field: str | None = None, instance: str = ""
) -> Response:
    """A problem+json response (no traceback, one-line detail)."""
    headers = {"WWW-Authenticate": "Bearer"} if status == 401 else None
    return Response(
        orjson.dumps(
            problem_body(status, detail.splitlines()[0] if detail else "", field, instance)
        ),
        status_code=status,
        media_type=PROBLEM_MEDIA_TYPE,
        headers=headers,
    )


def install_error_handlers(app: FastAPI) -> None:
    """Answer every error of ``app`` as problem+json (never a traceback)."""

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
