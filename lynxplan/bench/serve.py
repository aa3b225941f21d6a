"""Bench section ``serve``: the HTTP service against a bare FastAPI + uvicorn floor.

Two servers run as subprocesses on this machine: a bare FastAPI app with one JSON endpoint (the
floor: what any endpoint costs here) and ``lynxplan serve``. Figures, measured in one run:
sequential latency p50/p99 of the floor and of ``/ik`` for one pose (keep-alive connection),
requests/s of ``/ik`` with 32 concurrent connections (wall clock, and per CPU second of the
server process: its rate per core), the server time of one 100,000-pose binary
``/ik`` batch (``Server-Timing``), and the OK task (quick) run through the service, warm. The
load generator is Python on the same cores, so the throughput figure is a lower bound.
"""

from __future__ import annotations

import asyncio
import os
import socket
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from lynxplan.bench import Figure
from lynxplan.shipped import scenario_path

SECTION = "serve"
CONNECTIONS = 32
BATCH = 100_000
_FLOOR_APP = (
    "import orjson, uvicorn\n"
    "from fastapi import FastAPI, Request\n"
    "from starlette.responses import Response\n"
    "app = FastAPI()\n"
    "@app.post('/echo')\n"
    "async def echo(request: Request) -> Response:\n"
    "    body = orjson.loads(await request.body())\n"
    "    return Response(orjson.dumps({'n': len(body)}), media_type='application/json')\n"
    "uvicorn.run(app, host='127.0.0.1', port={port}, log_level='warning', access_log=False)\n"
)


def _free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _start(command: list[str], url: str) -> subprocess.Popen[bytes]:
    import httpx

    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                               env=env)  # fmt: skip
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline:
        try:
            httpx.post(url, content=b"{}", timeout=1.0)
            return process
        except httpx.HTTPError:
            time.sleep(0.2)
    process.kill()
    raise RuntimeError(f"benchmark server did not start: {' '.join(command)}")


def _request_bytes(path: str, body: bytes) -> bytes:
    return (
        f"POST {path} HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
        f"Content-Length: {len(body)}\r\n\r\n".encode()
        + body
    )


def _round_trip(sock: socket.socket, stream: Any, request: bytes) -> float:
    start = time.perf_counter()
    sock.sendall(request)
    status = stream.readline()
    length = 0
    while (line := stream.readline()) != b"\r\n":
        if line.lower().startswith(b"content-length:"):
            length = int(line.split(b":")[1])
    stream.read(length)
    elapsed = time.perf_counter() - start
    if not status.startswith(b"HTTP/1.1 200"):
        raise RuntimeError(f"benchmark request failed: {status.decode().strip()}")
    return elapsed


def _latencies(targets: list[tuple[int, str]], body: bytes, count: int) -> list[np.ndarray]:
    """Round-trip times, in [ms], of ``count`` sequential requests to each (port, path), one
    keep-alive connection each, interleaved request by request so that every target sees the
    same machine load (a raw socket client: the figure is the server's, not an HTTP library's).
    """
    connections = []
    for port, _ in targets:
        sock = socket.create_connection(("127.0.0.1", port))
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        connections.append((sock, sock.makefile("rb")))
    requests = [_request_bytes(path, body) for _, path in targets]
    times = np.empty((len(targets), count + 50))
    try:
        for i in range(count + 50):
            for k, ((sock, stream), request) in enumerate(zip(connections, requests, strict=True)):
                times[k, i] = _round_trip(sock, stream, request)
    finally:
        for sock, stream in connections:
            stream.close()
            sock.close()
    return [row[50:] * 1e3 for row in times]  # the first 50 warm up


async def _throughput(port: int, path: str, body: bytes, seconds: float) -> float:
    """Requests/s of POST ``path`` over :data:`CONNECTIONS` keep-alive connections.

    A minimal HTTP/1.1 client on asyncio streams (httpx's own overhead would be the bottleneck
    on two cores): each connection sends a request, reads the status line, headers and
    Content-Length bytes, and repeats.
    """
    request = _request_bytes(path, body)
    done = 0
    failed = 0
    stop = time.monotonic() + seconds

    async def connection() -> None:
        nonlocal done, failed
        reader, writer = await asyncio.open_connection("127.0.0.1", port)
        try:
            while time.monotonic() < stop:
                writer.write(request)
                head = await reader.readuntil(b"\r\n\r\n")
                length = int(head.lower().split(b"content-length:")[1].split(b"\r\n")[0])
                await reader.readexactly(length)
                if head.startswith(b"HTTP/1.1 200"):
                    done += 1
                else:
                    failed += 1
        finally:
            writer.close()

    start = time.monotonic()
    await asyncio.gather(*(connection() for _ in range(CONNECTIONS)))
    elapsed = time.monotonic() - start
    if failed:
        raise RuntimeError(f"{failed} {path} requests failed during the throughput run")
    return done / elapsed


def _cpu_seconds(pid: int) -> float:
    """User + system CPU time of a process so far, in [s] (NaN where ``/proc`` is missing)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return float("nan")
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _throughput_per_core(
    process: subprocess.Popen[bytes], port: int, path: str, body: bytes, seconds: float
) -> tuple[float, float]:
    """Requests/s with :data:`CONNECTIONS` connections, and requests per CPU second of the
    server process (the rate one fully busy core would serve: the load generator shares this
    machine's cores, so the wall-clock rate alone understates the server)."""
    cpu = _cpu_seconds(process.pid)
    start = time.monotonic()
    rate = asyncio.run(_throughput(port, path, body, seconds))
    elapsed = time.monotonic() - start
    used = _cpu_seconds(process.pid) - cpu
    return rate, rate * elapsed / used if used > 0 else float("nan")


def _batch_server_ms(client: Any, poses: np.ndarray, verify: str) -> float:
    """Server time of one binary /ik batch, in [ms] (its ``Server-Timing`` header)."""
    response = client.post(
        "/ik",
        content=poses.tobytes(),
        timeout=120,
        params={"verify": verify},
        headers={
            "Content-Type": "application/octet-stream",
            "X-Shape": ",".join(map(str, poses.shape)),
            "Accept": "application/x-npy-stream",
        },
    )
    assert response.status_code == 200, response.text
    return float(response.headers["Server-Timing"].split("dur=")[1])


def run(quick: bool) -> list[Figure]:
    """Start both servers, measure, stop them."""
    import httpx
    import orjson

    from lynxplan.arm import load_arm
    from lynxplan.client import Client

    count, seconds = (300, 2.0) if quick else (3000, 8.0)
    arm = load_arm()
    T = arm.fk(np.array([0.7, 1.0, -1.2, 1.1, 0.4]))
    ik_body = orjson.dumps({"T": T.tolist()})
    floor_port, service_port = _free_port(), _free_port()
    floor_url, service_url = f"http://127.0.0.1:{floor_port}", f"http://127.0.0.1:{service_port}"
    with tempfile.TemporaryDirectory(prefix="lynxplan-bench-") as data:
        floor = _start([sys.executable, "-c", _FLOOR_APP.replace("{port}", str(floor_port))],
                       floor_url + "/echo")  # fmt: skip
        service = _start(
            [
                sys.executable,
                "-m",
                "lynxplan.cli",
                "serve",
                "--port",
                str(service_port),
                "--data-dir",
                data,
            ],
            service_url + "/health",
        )
        try:
            bare, ik = _latencies([(floor_port, "/echo"), (service_port, "/ik")], ik_body, count)
            bare_rate, bare_core = _throughput_per_core(
                floor, floor_port, "/echo", ik_body, seconds
            )
            rate, core_rate = _throughput_per_core(service, service_port, "/ik", ik_body, seconds)
            with httpx.Client(base_url=service_url) as client:
                poses = arm.fk(
                    np.random.default_rng(0).uniform(
                        arm.limits.lower, arm.limits.upper, size=(BATCH, 5)
                    )
                )
                server_ms: dict[str, list[float]] = {"true": [], "false": []}
                for _ in range(3 if quick else 7):
                    for verify, times in server_ms.items():
                        times.append(_batch_server_ms(client, poses, verify))
            scenario = scenario_path("ok_task.yaml")
            with Client(service_url) as remote:
                remote.run(scenario, quick=True)  # warm the worker
                start = time.perf_counter()
                result = remote.run(scenario, quick=True)
                run_s = time.perf_counter() - start
                assert result.ok
            from lynxplan.scenarios import run_scenario

            run_scenario(scenario, Path(data) / "local", quick=True, force=True)
            start = time.perf_counter()
            run_scenario(scenario, Path(data) / "local", quick=True, force=True)
            local_s = time.perf_counter() - start
        finally:
            for process in (floor, service):
                process.terminate()
                process.wait(30)
    p50, p99 = float(np.percentile(ik, 50)), float(np.percentile(ik, 99))
    f50, f99 = float(np.percentile(bare, 50)), float(np.percentile(bare, 99))
    batch_ms = float(np.median(server_ms["true"]))
    bare_batch_ms = float(np.median(server_ms["false"]))
    return [
        Figure(SECTION, "bare FastAPI floor p50", f50, "ms"),
        Figure(SECTION, "bare FastAPI floor p99", f99, "ms"),
        Figure(SECTION, "/ik single pose p50", p50, "ms", "<= 0.5", p50 <= 0.5),
        Figure(SECTION, "/ik single pose p99", p99, "ms", "<= 1", p99 <= 1.0),
        Figure(SECTION, "/ik p50 / floor p50", p50 / f50, "x", "<= 1.3", p50 / f50 <= 1.3),
        Figure(SECTION, f"bare floor requests/s, {CONNECTIONS} connections", bare_rate, "req/s"),
        Figure(SECTION, f"/ik requests/s, {CONNECTIONS} connections", rate, "req/s"),
        Figure(SECTION, "bare floor requests per server CPU second", bare_core, "req/s"),
        Figure(SECTION, "/ik requests per server CPU second (per core)", core_rate, "req/s",
               ">= 4000", core_rate >= 4000),
        Figure(SECTION, "/ik / floor requests per CPU second", core_rate / bare_core, "x"),
        Figure(SECTION, f"/ik {BATCH:,}-pose binary batch, server", bare_batch_ms, "ms",
               "<= 100", bare_batch_ms <= 100),
        Figure(SECTION, f"/ik {BATCH:,}-pose batch + FK residual of 4 branches", batch_ms, "ms"),
        Figure(SECTION, "OK task (quick) through the service, warm", run_s, "s", "<= 0.5",
               run_s <= 0.5),
        Figure(SECTION, "OK task (quick) in-process, warm (same files)", local_s, "s"),
    ]  # fmt: skip
