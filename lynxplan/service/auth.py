"""The checks in front of every request, as one pure ASGI middleware (:class:`Guard`), in order:

1. ``Host`` must be one of the names the server answers to (the loopback names by default,
   ``--allowed-host`` adds more): a DNS-rebinding page's requests carry its own host name.
2. A request with an ``Origin`` (every browser POST, every cross-site fetch) must come from
   the server's own origin or one of ``--cors-origin``; those get CORS headers and their
   preflights (``OPTIONS``) are answered here. Other origins: 403.
3. Bearer token (constant time) on every path but :data:`PUBLIC_PATHS`/:data:`PUBLIC_PREFIXES`:
   the liveness probe, the web page, its scripts and the API description, which hold no data.
   With named tokens the caller's name goes to the routes (``scope["lynxplan.owner"]``).
4. The body's ``Content-Type`` must be one the endpoint documents (:data:`BODY_TYPES`): a
   ``text/plain`` or form POST, which a browser sends without a preflight, is 415.
"""

from __future__ import annotations

import hmac
from collections.abc import Iterable

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from lynxplan.service.config import ServiceConfig
from lynxplan.service.problems import problem_response

#: Paths answered without a token: the liveness probe, the web page and the API description.
PUBLIC_PATHS = ("/health", "/", "/docs", "/openapi.json", "/favicon.ico")
PUBLIC_PREFIXES = ("/static/",)
JSON = ("application/json",)
ARRAYS = ("application/json", "application/x-npy", "application/octet-stream")
YAML = ("application/json", "application/yaml", "application/x-yaml", "text/yaml", "text/x-yaml")
#: Media types of the request body each POST path accepts (none listed: JSON only).
BODY_TYPES = {"/fk": ARRAYS, "/ik": ARRAYS, "/runs": YAML}
#: Key of the caller's token name in the ASGI scope (named tokens only).
OWNER_KEY = "lynxplan.owner"
_CORS_HEADERS = [
    (b"access-control-allow-methods", b"GET, POST, DELETE, OPTIONS"),
    (b"access-control-allow-headers", b"authorization, content-type, accept, x-shape"),
    (b"access-control-expose-headers", b"x-result, x-arrays, server-timing"),
    (b"access-control-max-age", b"600"),
]


class Guard:
    """Host, origin, token and content-type checks (see the module docstring)."""

    def __init__(self, app: ASGIApp, config: ServiceConfig) -> None:
        self.app = app
        self.any_host = "*" in config.allowed_hosts
        self.hosts = frozenset(h.lower() for h in config.allowed_hosts)
        self.origins = frozenset(o.rstrip("/").lower() for o in config.cors_origins)
        tokens = dict(config.tokens)
        if config.token:
            tokens[""] = config.token
        self.tokens = [(name, f"Bearer {t}".encode()) for name, t in tokens.items()]
        self.named = bool(config.tokens)

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        path = scope.get("path", "")
        headers = _headers(scope["headers"])
        host = headers.get("host", "")
        if not self.any_host and _host_name(host) not in self.hosts:
            await _refuse(scope, receive, send, 400, f"Host {host[:80]!r} is not a name of this "
                          "server (start it with --allowed-host to add one)", "Host")  # fmt: skip
            return
        origin = headers.get("origin")
        if origin is not None and origin.lower() != f"{_scheme(scope)}://{host}".lower():
            if origin.rstrip("/").lower() not in self.origins:
                await _refuse(scope, receive, send, 403, f"cross-origin request from "
                              f"{origin[:80]!r} refused (allow it with --cors-origin)",
                              "Origin")  # fmt: skip
                return
            send = _with_cors(send, origin)
            if scope["method"] == "OPTIONS":
                await send({"type": "http.response.start", "status": 204, "headers": []})
                await send({"type": "http.response.body", "body": b""})
                return
        if self.tokens and not (path in PUBLIC_PATHS or path.startswith(PUBLIC_PREFIXES)):
            owner = self._owner(headers.get("authorization", "").encode("latin-1"))
            if owner is None:
                presented = "authorization" in headers
                detail = "invalid bearer token" if presented else "missing bearer token"
                await _refuse(scope, receive, send, 401, detail, "Authorization")
                return
            if self.named:
                scope[OWNER_KEY] = owner
        if scope["method"] in ("POST", "PUT", "PATCH"):
            media = headers.get("content-type", "application/json").split(";", 1)[0]
            allowed = BODY_TYPES.get(path, JSON)
            if (media.strip().lower() or "application/json") not in allowed:
                await _refuse(scope, receive, send, 415, f"Content-Type {media[:60]!r} is not "
                              f"accepted here; send {', '.join(allowed)}",
                              "Content-Type")  # fmt: skip
                return
        await self.app(scope, receive, send)

    def _owner(self, presented: bytes) -> str | None:
        """The name of the token presented (every token compared, in constant time), or None."""
        found = None
        for name, expected in self.tokens:
            if hmac.compare_digest(presented, expected):
                found = name
        return found


def _headers(raw: Iterable[tuple[bytes, bytes]]) -> dict[str, str]:
    return {key.decode("latin-1"): value.decode("latin-1") for key, value in raw}


def _host_name(host: str) -> str:
    """The name of a ``Host`` header without its port (``[::1]:8000`` -> ``[::1]``)."""
    host = host.strip().lower()
    if host.startswith("["):
        return host.split("]", 1)[0] + "]"
    return host.rsplit(":", 1)[0] if host.count(":") == 1 else host


def _scheme(scope: Scope) -> str:
    return str(scope.get("scheme", "http"))


def _with_cors(send: Send, origin: str) -> Send:
    extra = [(b"access-control-allow-origin", origin.encode("latin-1")), (b"vary", b"Origin"),
             *_CORS_HEADERS]  # fmt: skip

    async def wrapped(message: Message) -> None:
        if message["type"] == "http.response.start":
            message = {**message, "headers": [*message.get("headers", []), *extra]}
        await send(message)

    return wrapped


async def _refuse(
    scope: Scope, receive: Receive, send: Send, status: int, detail: str, field: str
) -> None:
    await problem_response(status, detail, field, scope.get("path", ""))(scope, receive, send)
