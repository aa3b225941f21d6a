"""``lynxplan serve``: the HTTP API, job store and web page (FastAPI + uvicorn)."""

from __future__ import annotations

import argparse
import ipaddress
import math
import os
from pathlib import Path
from typing import Any

from lynxplan.exceptions import InputError


def register(subparsers: Any) -> None:
    """Add the ``serve`` sub-command."""
    parser = subparsers.add_parser("serve", help="serve the HTTP API and web page")
    parser.add_argument("--host", default="127.0.0.1", help="bind address (default: 127.0.0.1)")
    parser.add_argument("--port", type=int, default=8000, help="port (default: 8000)")
    parser.add_argument("--workers", type=int, default=1, help="run worker processes")
    parser.add_argument("--data-dir", default="lynxplan-data", help="job store and artifacts")
    parser.add_argument("--token-file", help="file holding the bearer token")
    parser.add_argument("--dask-scheduler", help="Dask scheduler address (tcp://host:port)")
    parser.add_argument("--run-timeout", type=float, default=600.0, help="run limit [s]")
    parser.add_argument("--run-memory", type=float, default=8.0, help="worker memory [GiB]")
    parser.add_argument("--max-body", type=float, default=64.0, help="largest body [MiB]")
    parser.add_argument("--max-batch", type=int, default=1_000_000, help="largest batch")
    parser.add_argument("--log-level", default="warning", help="uvicorn log level")
    parser.set_defaults(handler=handle)


def handle(args: argparse.Namespace) -> int:
    """Start the server (blocks until interrupted)."""
    import uvicorn

    from lynxplan.service.app import create_app
    from lynxplan.service.config import ServiceConfig

    token = _read_token(args.token_file)
    if token is None and not _is_loopback(args.host):
        raise InputError(
            f"binding to {args.host} requires --token-file (only loopback may "
            "serve without a token)"
        )
    if args.workers < 1 or not 0 < args.port < 65536:
        raise InputError("--workers must be >= 1 and --port within 1..65535")
    for option, value in (
        ("--max-body", args.max_body),
        ("--run-memory", args.run_memory),
        ("--run-timeout", args.run_timeout),
    ):
        if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0):
            raise InputError(f"{option} must be a finite number > 0. Got: {value}")
    _check_data_dir(Path(args.data_dir))
    config = ServiceConfig(
        data_dir=Path(args.data_dir), workers=args.workers, token=token,
        max_body=int(args.max_body * 1024**2), max_batch=args.max_batch,
        dask_scheduler=args.dask_scheduler, run_timeout=args.run_timeout,
        run_memory=int(args.run_memory * 1024**3),
    )  # fmt: skip
    uvicorn.run(
        create_app(config),
        host=args.host,
        port=args.port,
        log_level=args.log_level,
        access_log=False,
        server_header=False,
    )
    return 0


def _check_data_dir(folder: Path) -> None:
    """A data dir that can hold the job store (one-line error before the server starts)."""
    import sqlite3

    try:
        folder.mkdir(parents=True, exist_ok=True)
        sqlite3.connect(str(folder / "lynxplan.sqlite3")).close()
    except (OSError, sqlite3.Error) as exc:
        raise InputError(f"cannot use --data-dir {folder}: {exc}") from exc


def _read_token(path: str | None) -> str | None:
    if path is None:
        return os.environ.get("LYNXPLAN_TOKEN") or None
    try:
        token = Path(path).read_text(encoding="utf-8").strip()
    except OSError as exc:
        raise InputError(f"cannot read --token-file {path}: {exc.strerror}") from exc
    if len(token) < 16:
        raise InputError(f"the token in {path} must have at least 16 characters")
    return token


def _is_loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False
