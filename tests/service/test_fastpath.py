"""The ASGI fast path of the hot routes: endpoints called directly, errors as problem+json."""

from __future__ import annotations

import asyncio

import httpx
import pytest
from fastapi import FastAPI, Request
from starlette.responses import Response

from lynxplan.exceptions import ShapeError
from lynxplan.service.fastpath import FastPath
from lynxplan.service.problems import PROBLEM_MEDIA_TYPE, Problem, install_error_handlers


def _app() -> FastPath:
    app = FastAPI()
    install_error_handlers(app)

    @app.post("/fast")
    async def fast(request: Request) -> Response:
        what = request.query_params.get("raise", "")
        if what == "problem":
            raise Problem(413, "too large", "body")
        if what == "domain":
            raise ShapeError("q", "(5,)", (3,))
        if what == "crash":
            raise RuntimeError("secret internals")
        return Response(b"fast:" + await request.body())

    @app.post("/slow")
    async def slow() -> dict[str, str]:
        return {"via": "fastapi"}

    return FastPath(app, ("/fast",))


def _request(method: str, path: str, **kwargs: object) -> httpx.Response:
    async def send() -> httpx.Response:
        transport = httpx.ASGITransport(app=_app())
        async with httpx.AsyncClient(transport=transport, base_url="http://test") as http:
            return await http.request(method, path, **kwargs)  # type: ignore[arg-type]

    return asyncio.run(send())


def test_fast_route_answers_and_others_pass_through() -> None:
    assert _request("POST", "/fast", content=b"x").content == b"fast:x"
    assert _request("POST", "/slow").json() == {"via": "fastapi"}
    missing = _request("GET", "/fast")  # another method falls through to FastAPI: 405
    assert missing.status_code == 405
    assert missing.headers["content-type"] == PROBLEM_MEDIA_TYPE


@pytest.mark.parametrize(
    ("what", "status", "field", "detail"),
    [
        ("problem", 413, "body", "too large"),
        ("domain", 422, "q", "q must have shape (5,). Got: (3,)"),
        ("crash", 500, None, "internal error (RuntimeError)"),
    ],
)
def test_errors_are_problems(what: str, status: int, field: str | None, detail: str) -> None:
    response = _request("POST", "/fast", params={"raise": what})
    assert response.status_code == status
    assert response.headers["content-type"] == PROBLEM_MEDIA_TYPE
    body = response.json()
    assert body["detail"] == detail
    assert body.get("field") == field
    assert body["instance"] == "/fast"
    assert "secret" not in response.text
