"""Request and response encodings: JSON (orjson) for small payloads, binary arrays for large ones.

Binary requests carry one array, either as ``application/x-npy`` (a ``.npy`` file, never pickled)
or as ``application/octet-stream`` raw little-endian float64 with its shape in the ``X-Shape``
header (``"100000,4,4"``). Binary responses are ``application/x-npy-stream`` (the fastest: the
``.npy`` files of the result arrays one after another, their names in the ``X-Arrays`` header,
no checksum) or ``application/x-npz`` (a standard uncompressed archive): one ``.npy`` per
result array. Arrays are checked for dtype, shape and finiteness with numpy, never element by
element, and JSON answers serialise numpy arrays directly (``OPT_SERIALIZE_NUMPY``).
"""

from __future__ import annotations

import io
import math
import zipfile
from collections.abc import Mapping
from typing import Any

import numpy as np
import orjson
from starlette.requests import Request
from starlette.responses import Response

from lynxplan.service.problems import Problem

NPY_MEDIA_TYPE = "application/x-npy"
NPZ_MEDIA_TYPE = "application/x-npz"
STREAM_MEDIA_TYPE = "application/x-npy-stream"
RAW_MEDIA_TYPE = "application/octet-stream"
JSON_OPTIONS = orjson.OPT_SERIALIZE_NUMPY


async def read_body(request: Request, limit: int) -> bytes:
    """The request body; Problem 413 as soon as it exceeds ``limit`` bytes."""
    declared = request.headers.get("content-length")
    if declared is not None and declared.isdigit() and int(declared) > limit:
        raise Problem(413, f"request body of {int(declared)} bytes exceeds the limit of {limit}")
    chunks: list[bytes] = []
    size = 0
    async for chunk in request.stream():
        size += len(chunk)
        if size > limit:
            raise Problem(413, f"request body exceeds the limit of {limit} bytes")
        chunks.append(chunk)
    return b"".join(chunks)


def media_type(request: Request) -> str:
    """The request's media type without parameters, lower case (``application/json`` default)."""
    raw = request.headers.get("content-type", "application/json")
    return raw.split(";", 1)[0].strip().lower() or "application/json"


def is_binary(request: Request) -> bool:
    """Whether the body is a binary array (npy or raw float64)."""
    return media_type(request) in (NPY_MEDIA_TYPE, RAW_MEDIA_TYPE)


def wants_binary(request: Request) -> bool:
    """Whether the client asked for a binary answer (npz or npy stream)."""
    accept = request.headers.get("accept", "")
    return NPZ_MEDIA_TYPE in accept or STREAM_MEDIA_TYPE in accept


def parse_json_object(body: bytes) -> dict[str, Any]:
    """A JSON object; Problem 422 for malformed JSON or another top-level type."""
    if not body:
        raise Problem(422, "the request body is empty; expected a JSON object", "body")
    try:
        value = orjson.loads(body)
    except orjson.JSONDecodeError as exc:
        raise Problem(422, f"malformed JSON: {exc}", "body") from None
    if not isinstance(value, dict):
        raise Problem(422, f"expected a JSON object. Got: {type(value).__name__}", "body")
    return value


def decode_binary(request: Request, body: bytes, field: str) -> np.ndarray:
    """The array of a binary body (npy or raw float64 + ``X-Shape``), as float64.

    The shape a header declares is checked against the body's length with Python integers
    (no int64 product that wraps) before any array is made: nothing is allocated beyond the
    body itself and its float64 copy.
    """
    if media_type(request) == NPY_MEDIA_TYPE:
        return _decode_npy(body, field)
    shape_header = request.headers.get("x-shape")
    if shape_header is None:
        raise Problem(422, "raw float64 bodies need an X-Shape header, e.g. '100,4,4'", "X-Shape")
    parts = shape_header.split(",")
    digits = [p.strip() for p in parts]
    if (
        len(shape_header) > 80
        or len(parts) > MAX_DIMENSIONS
        or not all(d.isascii() and d.isdigit() for d in digits)
    ):
        raise Problem(
            422,
            f"X-Shape must be at most {MAX_DIMENSIONS} non-negative integers separated by commas."
            f" Got: {shape_header[:60]!r}",
            "X-Shape",
        )
    shape = tuple(int(d) for d in digits)
    _check_dimensions(shape, "X-Shape", f"X-Shape {_shape_text(shape)}")
    elements = math.prod(shape)  # a Python int: exact for any header
    if 8 * elements != len(body):
        raise Problem(
            422,
            f"X-Shape {_shape_text(shape)} declares {_count(elements)} float64 values "
            f"({_count(8 * elements)} bytes); the body has {len(body)} bytes",
            "X-Shape",
        )
    return np.frombuffer(body, dtype="<f8").reshape(shape)


#: Most dimensions a binary array may declare (the routes take at most 3).
MAX_DIMENSIONS = 4
#: Largest length of one dimension of a binary array (numpy refuses some zero-size arrays
#: with longer ones, and no batch limit comes near it).
MAX_DIMENSION_LENGTH = 2**31 - 1


def _check_dimensions(shape: tuple[int, ...], field: str, what: str) -> None:
    """Problem 422 naming ``field`` when a dimension of ``shape`` is longer than
    :data:`MAX_DIMENSION_LENGTH` (even of an empty array)."""
    if any(length > MAX_DIMENSION_LENGTH for length in shape):
        raise Problem(422, f"{what} has a dimension longer than {MAX_DIMENSION_LENGTH}", field)


def _decode_npy(body: bytes, field: str) -> np.ndarray:
    """The array of a ``.npy`` body: header read and checked against the body's length first
    (a header may declare any shape), never unpickled."""
    from numpy.lib import format as npy

    stream = io.BytesIO(body)
    try:
        version = npy.read_magic(stream)
        if version == (1, 0):
            shape, fortran, dtype = npy.read_array_header_1_0(stream)
        elif version in ((2, 0), (3, 0)):
            shape, fortran, dtype = npy.read_array_header_2_0(stream)
        else:
            raise ValueError(f"unsupported .npy version {version}")
    except (ValueError, OSError, EOFError, SyntaxError) as exc:
        reason = " ".join(str(exc).split())[:120]
        raise Problem(422, f"invalid .npy body: {reason}", field) from None
    if dtype.kind not in "iuf" or dtype.hasobject:
        raise Problem(422, f"the .npy array must be numeric. Got: {dtype}", field)
    if len(shape) > MAX_DIMENSIONS:
        dims = f"{len(shape)} dimensions; at most {MAX_DIMENSIONS}"
        raise Problem(422, f"the .npy array has {dims}", field)
    _check_dimensions(shape, field, f"the .npy header's shape {_shape_text(shape)}")
    elements = math.prod(shape)
    offset = stream.tell()
    if elements * dtype.itemsize != len(body) - offset:
        raise Problem(
            422,
            f"the .npy header declares shape {_shape_text(shape)} ({_count(elements)} values of "
            f"{dtype.itemsize} bytes); the body holds {len(body) - offset} bytes of data",
            field,
        )
    flat = np.frombuffer(body, dtype=dtype, count=elements, offset=offset)
    array = flat.reshape(shape, order="F" if fortran else "C")
    return np.ascontiguousarray(array, dtype=np.float64)


def _shape_text(shape: tuple[int, ...]) -> str:
    text = "(" + ", ".join(map(str, shape)) + ("," if len(shape) == 1 else "") + ")"
    return text if len(text) <= 80 else text[:77] + "..."


def _count(n: int) -> str:
    return str(n) if n < 10**12 else f"{float(n):.3g}"


def as_array(
    value: Any,
    field: str,
    trailing: tuple[int, ...],
    *,
    batch: bool = True,
    limit: int = 0,
    owner: str = "",
) -> np.ndarray:
    """A float64 array of shape ``trailing`` or (N, *trailing), checked with numpy.

    ``owner`` (e.g. ``"ur5 (6 joints)"``) is named in a shape error after the expected shape.

    Raises:
        Problem: 422 for a wrong type, shape or a non-finite value; 413 for N > ``limit`` (> 0).
    """
    if isinstance(value, np.ndarray):
        array = value
    else:
        try:
            array = np.array(value)
        except (ValueError, TypeError):
            raise Problem(422, f"{field} must be a (nested) list of numbers", field) from None
    if array.dtype.kind not in "iuf" or (array.size == 0 and array.ndim == 0):
        raise Problem(422, f"{field} must contain numbers only. Got: {_describe(value)}", field)
    expected = str(trailing) if not batch else f"{trailing} or (N, {', '.join(map(str, trailing))})"
    single = array.shape == trailing
    if not single and not (
        batch and array.ndim == len(trailing) + 1 and array.shape[1:] == trailing
    ):
        owned = f" for {owner}" if owner else ""
        raise Problem(422, f"{field} must have shape {expected}{owned}. Got: {array.shape}", field)
    if not single and array.shape[0] == 0:
        raise Problem(422, f"{field} is an empty batch: give at least one {trailing} entry", field)
    if limit and not single and array.shape[0] > limit:
        raise Problem(
            413, f"{field}: batch of {array.shape[0]} exceeds the limit of {limit}", field
        )
    array = np.ascontiguousarray(array, dtype=np.float64)
    finite = np.isfinite(array)
    if not finite.all():
        where = np.argwhere(~finite)[0].tolist()
        raise Problem(
            422, f"{field} contains NaN or infinite values (first at {where})", f"{field}{where}"
        )
    return array


def _describe(value: Any) -> str:
    text = orjson.dumps(value, default=str)[:60].decode(errors="replace")
    return text


def _default(value: Any) -> Any:
    if isinstance(value, np.ndarray):  # a strided view: one contiguous copy, still no tolist()
        return np.ascontiguousarray(value)
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"cannot serialise {type(value).__name__}")


def dumps(content: Any) -> bytes:
    """JSON bytes of ``content`` (numpy arrays natively, NaN and infinities as null)."""
    return orjson.dumps(content, option=JSON_OPTIONS, default=_default)


def json_response(content: Any, status: int = 200) -> Response:
    """A JSON response serialised by orjson (numpy arrays natively, NaN as null)."""
    return Response(dumps(content), status_code=status, media_type="application/json")


def npz_bytes(arrays: Mapping[str, np.ndarray]) -> bytes:
    """An uncompressed .npz archive of ``arrays`` (one .npy member each)."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", compression=zipfile.ZIP_STORED) as archive:
        for name, array in arrays.items():
            with archive.open(f"{name}.npy", "w", force_zip64=True) as member:
                np.lib.format.write_array(member, np.ascontiguousarray(array), allow_pickle=False)
    return buffer.getvalue()


def npy_stream_bytes(arrays: Mapping[str, np.ndarray]) -> bytes:
    """The ``.npy`` files of ``arrays`` one after another."""
    buffer = io.BytesIO()
    for array in arrays.values():
        np.lib.format.write_array(buffer, np.ascontiguousarray(array), allow_pickle=False)
    return buffer.getvalue()


#: An encoded answer: (content, media type, headers).
Encoded = tuple[bytes, str, dict[str, str]]


def answer_format(request: Request) -> str:
    """The answer format the client accepts: ``"stream"`` (npy stream), ``"npz"`` or
    ``"json"``."""
    accept = request.headers.get("accept", "")
    if STREAM_MEDIA_TYPE in accept:
        return "stream"
    return "npz" if NPZ_MEDIA_TYPE in accept else "json"


def encode_answer(
    arrays: Mapping[str, np.ndarray], scalars: Mapping[str, Any], answer: str
) -> Encoded:
    """``arrays`` and ``scalars`` in format ``answer`` (:func:`answer_format`): JSON (one
    object), or the arrays binary (npy stream or npz) with the scalars as JSON in the
    ``X-Result`` header and the array names in ``X-Arrays``."""
    if answer == "json":
        return dumps({**scalars, **arrays}), "application/json", {}
    stream = answer == "stream"
    content = npy_stream_bytes(arrays) if stream else npz_bytes(arrays)
    headers = {"X-Result": orjson.dumps(scalars).decode(), "X-Arrays": ",".join(arrays)}
    return content, STREAM_MEDIA_TYPE if stream else NPZ_MEDIA_TYPE, headers


def encoded_response(encoded: Encoded) -> Response:
    """The response of an :data:`Encoded` answer."""
    content, media, headers = encoded
    return Response(content, media_type=media, headers=headers)


def arrays_response(
    request: Request, arrays: Mapping[str, np.ndarray], scalars: Mapping[str, Any]
) -> Response:
    """A binary answer in the format the client accepts (npy stream, else npz); ``scalars``
    travel as JSON in the ``X-Result`` header, the array names in ``X-Arrays``."""
    answer = "stream" if STREAM_MEDIA_TYPE in request.headers.get("accept", "") else "npz"
    return encoded_response(encode_answer(arrays, scalars, answer))


def read_arrays(data: bytes, media: str, names: str) -> dict[str, np.ndarray]:
    """Arrays of a binary answer (client side): npy stream (names from ``X-Arrays``) or npz."""
    if media.startswith(STREAM_MEDIA_TYPE):
        buffer = io.BytesIO(data)
        return {
            name: np.lib.format.read_array(buffer, allow_pickle=False) for name in names.split(",")
        }
    return read_npz(data)


def read_npz(data: bytes) -> dict[str, np.ndarray]:
    """Arrays of an npz answer (client side)."""
    with np.load(io.BytesIO(data), allow_pickle=False) as archive:
        return {name: archive[name] for name in archive.files}
