"""The HTTP transport of :class:`lynxplan.client.Client`: requests, problem answers turned into
:class:`ServiceError`, JSON (orjson) and binary float64 bodies."""

from __future__ import annotations

from typing import Any

import numpy as np
import orjson

from lynxplan.exceptions import LynxplanError


class ServiceError(LynxplanError):
    """The server answered with a problem (RFC 9457).

    Attributes:
        status: HTTP status code.
        detail: The problem's detail line.
        field: The offending request field, or None.
    """

    def __init__(self, status: int, detail: str, field: str | None = None) -> None:
        self.status, self.detail, self.field = status, detail, field
        where = f" (field {field})" if field else ""
        super().__init__(f"server answered {status}: {detail}{where}")


class Transport:
    """Connection pool to a lynxplan server.

    Args:
        url: Base URL, e.g. ``"http://127.0.0.1:8000"``.
        token: Bearer token, if the server requires one.
        timeout: Per-request timeout, in [s].
    """

    def __init__(self, url: str, token: str | None = None, timeout: float = 120.0) -> None:
        import httpx

        headers = {"Authorization": f"Bearer {token}"} if token else {}
        self._http = httpx.Client(base_url=url.rstrip("/"), headers=headers, timeout=timeout)

    def close(self) -> None:
        """Close the connection pool."""
        self._http.close()

    def _request(self, method: str, path: str, **kwargs: Any) -> Any:
        import httpx

        try:
            response = self._http.request(method, path, **kwargs)
        except httpx.HTTPError as exc:
            raise ServiceError(0, f"cannot reach {self._http.base_url}: {exc}") from exc
        if response.status_code >= 400:
            try:
                problem = response.json()
            except ValueError:
                problem = {"detail": response.text[:200]}
            raise ServiceError(
                response.status_code, str(problem.get("detail", "")), problem.get("field")
            )
        return response

    def _json(self, method: str, path: str, body: Any = None, **kwargs: Any) -> Any:
        if body is not None:
            kwargs["content"] = orjson.dumps(body, option=orjson.OPT_SERIALIZE_NUMPY)
            kwargs["headers"] = {"Content-Type": "application/json"}
        return orjson.loads(self._request(method, path, **kwargs).content)

    def _binary(self, path: str, array: np.ndarray, params: dict[str, Any]) -> dict[str, Any]:
        from lynxplan.service.wire import read_arrays

        response = self._request(
            "POST", path, content=np.ascontiguousarray(array, dtype="<f8").tobytes(),
            params=params, headers={"Content-Type": "application/octet-stream",
                                    "X-Shape": ",".join(map(str, array.shape)),
                                    "Accept": "application/x-npy-stream"},
        )  # fmt: skip
        arrays: dict[str, Any] = read_arrays(
            response.content,
            response.headers.get("content-type", ""),
            response.headers.get("X-Arrays", ""),
        )
        arrays.update(orjson.loads(response.headers.get("X-Result", "{}")))
        return arrays


__all__ = ["ServiceError", "Transport"]
