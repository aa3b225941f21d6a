"""uvicorn's httptools protocol with read deadlines, against slow clients (slowloris).

uvicorn bounds only the idle time between requests (keep-alive). Here a request's head (request
line and headers) must arrive within ``head_timeout`` seconds of the connection or of its first
byte, and its body must not stall for more than ``body_timeout`` seconds between chunks; a
connection past either is answered 408 (head) or closed (body). The number of connections is
capped by uvicorn's ``limit_concurrency`` (503 beyond it), set by ``lynxplan serve``.
"""

from __future__ import annotations

import asyncio
from typing import Any

from uvicorn.protocols.http.httptools_impl import HttpToolsProtocol

#: Defaults of ``lynxplan serve --header-timeout`` / ``--body-timeout``, in [s].
HEAD_TIMEOUT = 10.0
BODY_TIMEOUT = 30.0
_TIMEOUT_BODY = (
    b'{"type":"about:blank","title":"Request timeout","status":408,'
    b'"detail":"the request head did not arrive in time"}'
)
_TIMEOUT_ANSWER = (
    b"HTTP/1.1 408 Request Timeout\r\ncontent-type: application/problem+json\r\n"
    b"connection: close\r\ncontent-length: %d\r\n\r\n%s" % (len(_TIMEOUT_BODY), _TIMEOUT_BODY)
)


class DeadlineProtocol(HttpToolsProtocol):
    """:class:`HttpToolsProtocol` with head and body read deadlines (class attributes; see
    :func:`protocol_class`)."""

    head_timeout = HEAD_TIMEOUT
    body_timeout = BODY_TIMEOUT

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self._deadline: asyncio.TimerHandle | None = None

    def _arm(self, seconds: float, head: bool) -> None:
        self._disarm()
        self._deadline = self.loop.call_later(seconds, self._expire, head)

    def _disarm(self) -> None:
        if self._deadline is not None:
            self._deadline.cancel()
            self._deadline = None

    def _expire(self, head: bool) -> None:
        self._deadline = None
        if self.transport.is_closing():
            return
        if head:
            self.transport.write(_TIMEOUT_ANSWER)
        self.transport.close()

    def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
        super().connection_made(transport)
        self._arm(self.head_timeout, head=True)

    def connection_lost(self, exc: Exception | None) -> None:
        self._disarm()
        super().connection_lost(exc)

    def on_message_begin(self) -> None:
        super().on_message_begin()
        if self._deadline is None:  # a keep-alive connection's next request
            self._arm(self.head_timeout, head=True)

    def on_headers_complete(self) -> None:
        self._arm(self.body_timeout, head=False)
        super().on_headers_complete()

    def on_body(self, body: bytes) -> None:
        self._arm(self.body_timeout, head=False)
        super().on_body(body)

    def on_message_complete(self) -> None:
        self._disarm()
        super().on_message_complete()


def protocol_class(head_timeout: float, body_timeout: float) -> type[DeadlineProtocol]:
    """A :class:`DeadlineProtocol` with these deadlines, in [s]."""
    return type(
        "ServeProtocol",
        (DeadlineProtocol,),
        {"head_timeout": head_timeout, "body_timeout": body_timeout},
    )
