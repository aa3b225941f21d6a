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
    403: "Forbidden",
    404: "Not found",
    405: "Method not allowed",
    408: "Request timeout",
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


def error_response(exc: Exception, method: str, path: str) -> Response:
    """The problem+json answer to any exception raised while serving ``method path`` (one
    mapping for the FastAPI routes and the fast path): Problem as given, HTTP errors with their
    status, validation and domain errors 422, anything else 500 without a traceback."""
    if isinstance(exc, Problem):
        return problem_response(exc.status, exc.detail, exc.field, path)
    if isinstance(exc, StarletteHTTPException):
        detail = exc.detail if isinstance(exc.detail, str) else str(exc.status_code)
        if exc.status_code == 404:
            detail = f"no route {method} {path}"
        return problem_response(exc.status_code, detail, None, path)
    if isinstance(exc, RequestValidationError):
        first = exc.errors()[0] if exc.errors() else {"loc": (), "msg": "invalid request"}
        loc = [str(part) for part in first.get("loc", ())][1:]
        return problem_response(422, str(first.get("msg", "invalid")), ".".join(loc) or None, path)
    if isinstance(exc, LynxplanError):
        field = getattr(exc, "name", None)
        return problem_response(422, str(exc), field if isinstance(field, str) else None, path)
    return problem_response(500, f"internal error ({type(exc).__name__})", None, path)


def install_error_handlers(app: FastAPI) -> None:
    """Answer every error of ``app`` as problem+json (never a traceback)."""

    async def on_error(request: Request, exc: Exception) -> Response:
        return error_response(exc, request.method, request.url.path)

    for kind in (Problem, StarletteHTTPException, RequestValidationError, LynxplanError, Exception):
        app.add_exception_handler(kind, on_error)
