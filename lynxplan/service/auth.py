"""Bearer-token check of every request (constant time), as a pure ASGI middleware."""

from __future__ import annotations

import hmac

from starlette.types import ASGIApp, Receive, Scope, Send

from lynxplan.service.problems import problem_response

#: Paths answered without a token: the liveness probe and the (data-free) web pages.
PUBLIC_PATHS = ("/health", "/", "/docs", "/favicon.ico")
PUBLIC_PREFIXES = ("/static/",)


class TokenMiddleware:
    """Bearer-token check (constant time) on every request except :data:`PUBLIC_PATHS`."""

    def __init__(self, app: ASGIApp, token: str) -> None:
        self.app = app
        self.expected = f"Bearer {token}".encode()

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        path = scope.get("path", "")
        if scope["type"] != "http" or path in PUBLIC_PATHS or path.startswith(PUBLIC_PREFIXES):
            await self.app(scope, receive, send)
            return
        presented = b""
        for key, value in scope["headers"]:
            if key == b"authorization":
                presented = value
        if not hmac.compare_digest(presented, self.expected):
            detail = "missing bearer token" if not presented else "invalid bearer token"
            await problem_response(401, detail, "Authorization", path)(scope, receive, send)
            return
        await self.app(scope, receive, send)
