"""``lynxplan serve``: the HTTP API, job store and web page (FastAPI + uvicorn).

Access: on loopback (the default ``--host 127.0.0.1``) no token is needed. Off loopback a
``--token-file`` is required; it holds either one shared token (one line: every caller sees and
cancels every run, as before named tokens existed) or named tokens, one ``name:token`` a line
(each caller sees, reads and cancels only the runs its own token created). Open without a token:
``/health``, the web page (``/``, ``/static/*``), ``/docs`` and ``/openapi.json`` (they hold no
data); every API call needs the token.

Cross-site: the ``Host`` header must name this server (the loopback names, the bound address,
and for a wildcard bind such as ``0.0.0.0`` also this machine's host names; ``--allowed-host``
adds a name, ``--allowed-host '*'`` turns the check off, e.g. behind a proxy that checks it).
Requests from another web origin are refused unless ``--cors-origin`` allows it.

Slow clients: a request head must arrive within ``--header-timeout`` s, a body may not stall
longer than ``--body-timeout`` s, and at most ``--max-connections`` connections are served
(503 beyond).
"""

from __future__ import annotations

import argparse
import ipaddress
import math
import os
import re
import socket
from pathlib import Path
from typing import Any

from lynxplan.exceptions import InputError

#: Smallest token length, in characters.
MIN_TOKEN = 16
_TOKEN_NAME = re.compile(r"[A-Za-z0-9_.-]{1,64}")


def default_data_dir() -> Path:
    """The user's data folder for lynxplan (``platformdirs``: XDG on Linux)."""
    import platformdirs

    return Path(platformdirs.user_data_dir("lynxplan", appauthor=False))


def register(subparsers: Any) -> None:
    """Add the ``serve`` sub-command."""
    parser = subparsers.add_parser(
        "serve",
        help="serve the HTTP API and web page",
        description=__doc__.split("\n\n", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--host", default="127.0.0.1", help="bind address (default: 127.0.0.1)")
    parser.add_argument("--port", type=int, default=8000, help="port (default: 8000)")
    parser.add_argument("--workers", type=int, default=1, help="run worker processes")
    parser.add_argument(
        "--data-dir", help="job store and artifacts (default: the user's data folder)"
    )
    parser.add_argument(
        "--token-file", help="one bearer token, or one name:token a line (named tokens)"
    )
    parser.add_argument(
        "--allowed-host",
        action="append",
        default=[],
        help="another host name the Host header may carry (repeatable; '*': any)",
    )
    parser.add_argument("--cors-origin", action="append", default=[],
                        help="a web origin (https://host:port) allowed to call the API "
                        "(repeatable)")  # fmt: skip
    parser.add_argument("--dask-scheduler", help="Dask scheduler address (tcp://host:port)")
    parser.add_argument("--run-timeout", type=float, default=600.0, help="run limit [s]")
    parser.add_argument("--run-memory", type=float, default=8.0, help="worker memory [GiB]")
    parser.add_argument("--max-body", type=float, default=64.0, help="largest body [MiB]")
    parser.add_argument("--max-upload", type=float, default=32.0,
                        help="largest total of the files uploaded with a run [MiB]")  # fmt: skip
    parser.add_argument("--max-batch", type=int, default=1_000_000, help="largest batch")
    parser.add_argument("--max-answer", type=float, default=256.0,
                        help="largest answer a request may imply, checked first [MiB]")  # fmt: skip
    parser.add_argument("--compute-workers", type=int, default=2,
                        help="processes computing /check, /trajectory, /plan")  # fmt: skip
    parser.add_argument("--header-timeout", type=float, default=10.0,
                        help="time a request head may take [s]")  # fmt: skip
    parser.add_argument("--body-timeout", type=float, default=30.0,
                        help="longest stall while a body arrives [s]")  # fmt: skip
    parser.add_argument("--max-connections", type=int, default=256,
                        help="connections served at once (503 beyond)")  # fmt: skip
    parser.add_argument("--log-level", default="warning", help="uvicorn log level")
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    """Start the server (blocks until interrupted)."""
    import uvicorn

    from lynxplan.service.app import create_app
    from lynxplan.service.config import ServiceConfig
    from lynxplan.service.protocol import protocol_class

    token, tokens = _read_tokens(args.token_file)
    if token is None and not tokens and not _is_loopback(args.host):
        raise InputError(
            f"binding to {args.host} requires --token-file (only loopback may "
            "serve without a token)"
        )
    for option, value in (("--workers", args.workers), ("--compute-workers", args.compute_workers)):
        if value < 1:
            raise InputError(f"{option} must be >= 1. Got: {value}")
    if not 0 < args.port < 65536:
        raise InputError(f"--port must be within 1..65535. Got: {args.port}")
    if args.max_connections < 1:
        raise InputError(f"--max-connections must be >= 1. Got: {args.max_connections}")
    for option, value in (
        ("--max-body", args.max_body),
        ("--max-upload", args.max_upload),
        ("--max-answer", args.max_answer),
        ("--run-memory", args.run_memory),
        ("--run-timeout", args.run_timeout),
        ("--header-timeout", args.header_timeout),
        ("--body-timeout", args.body_timeout),
    ):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise InputError(f"{option} must be a finite number > 0. Got: {value}")
    data_dir = Path(args.data_dir) if args.data_dir else default_data_dir()
    _check_data_dir(data_dir, "--data-dir" if args.data_dir else "the data folder")
    config = ServiceConfig(
        data_dir=data_dir, workers=args.workers, token=token, tokens=tokens,
        allowed_hosts=_allowed_hosts(args.host, args.allowed_host),
        cors_origins=tuple(args.cors_origin),
        max_body=int(args.max_body * 1024**2), max_batch=args.max_batch,
        max_upload=int(args.max_upload * 1024**2),
        max_answer=int(args.max_answer * 1024**2), compute_workers=args.compute_workers,
        dask_scheduler=args.dask_scheduler, run_timeout=args.run_timeout,
        run_memory=int(args.run_memory * 1024**3),
    )  # fmt: skip
    _announce(args, config)
    # numba's cache has none of the big kernels: say once (stderr, the log) that the workers'
    # first runs compile them; checked in a thread while the server starts.
    from threading import Thread

    from lynxplan._jit import announce_if_cold
    from lynxplan._numba_cache import import_numba

    import_numba()  # here, not in both threads at once (the app's start imports numba too)
    Thread(target=announce_if_cold, args=(_log_line,), daemon=True).start()
    uvicorn.run(
        create_app(config),
        host=args.host,
        port=args.port,
        log_level=args.log_level,
        access_log=False,
        server_header=False,
        http=protocol_class(args.header_timeout, args.body_timeout),
        limit_concurrency=args.max_connections,
    )
    return 0


def _log_line(line: str) -> None:
    import sys

    print(line, file=sys.stderr, flush=True)


def _announce(args: argparse.Namespace, config: Any) -> None:
    """The lines a user needs on start: URL, data folder, access, workers."""
    host = f"[{args.host}]" if ":" in args.host else args.host
    if config.tokens:
        access = f"named tokens ({', '.join(sorted(config.tokens))}): each sees its own runs"
    elif config.token:
        access = "one shared bearer token (every caller sees every run)"
    else:
        access = "no token (loopback only)"
    executor = f"Dask at {args.dask_scheduler}" if args.dask_scheduler else "local"
    print(
        f"lynxplan serve: http://{host}:{args.port}/  (web page; API docs at /docs)\n"
        f"  data folder: {config.data_dir.absolute()}\n"
        f"  access: {access}\n"
        f"  run workers: {args.workers} ({executor})\n"
        "  (the first requests compile numerical kernels; they can take tens of seconds)",
        flush=True,
    )


def _allowed_hosts(host: str, extra: list[str]) -> tuple[str, ...]:
    """Names the ``Host`` header may carry: loopback names, the bound address, for a wildcard
    bind this machine's names, and ``--allowed-host``."""
    from lynxplan.service.config import LOOPBACK_HOSTS

    names = [*LOOPBACK_HOSTS, host, f"[{host}]" if ":" in host else host]
    if host in ("0.0.0.0", "::", ""):
        names += [socket.gethostname(), socket.getfqdn()]
    names += [name.strip() for name in extra if name.strip()]
    return tuple(dict.fromkeys(name.lower() for name in names))


def _check_data_dir(folder: Path, option: str) -> None:
    """A data dir that can hold the job store (one-line error before the server starts)."""
    import sqlite3

    try:
        folder.mkdir(parents=True, exist_ok=True)
        sqlite3.connect(str(folder / "lynxplan.sqlite3")).close()
    except (OSError, sqlite3.Error) as exc:
        raise InputError(f"cannot use {option} {folder}: {exc}") from exc


def _read_tokens(path: str | None) -> tuple[str | None, dict[str, str]]:
    """(shared token, {}) or (None, named tokens) from ``--token-file`` (or LYNXPLAN_TOKEN)."""
    if path is None:
        return os.environ.get("LYNXPLAN_TOKEN") or None, {}
    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        reason = getattr(exc, "strerror", None) or "not UTF-8 text"
        raise InputError(f"cannot read --token-file {path}: {reason}") from exc
    lines = [line.strip() for line in text.splitlines()]
    lines = [line for line in lines if line and not line.startswith("#")]
    if len(lines) == 1 and ":" not in lines[0]:
        if len(lines[0]) < MIN_TOKEN:
            raise InputError(f"the token in {path} must have at least {MIN_TOKEN} characters")
        return lines[0], {}
    if not lines:
        raise InputError(f"--token-file {path} holds no token")
    tokens: dict[str, str] = {}
    for number, line in enumerate(lines, 1):
        name, _, token = line.partition(":")
        if not _TOKEN_NAME.fullmatch(name) or len(token) < MIN_TOKEN:
            raise InputError(
                f"--token-file {path}, token {number}: write one token, or name:token lines "
                f"(name: letters, digits, '._-'; token: at least {MIN_TOKEN} characters)"
            )
        if name in tokens or token in tokens.values():
            raise InputError(f"--token-file {path}, token {number}: name or token repeated")
        tokens[name] = token
    return None, tokens


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
