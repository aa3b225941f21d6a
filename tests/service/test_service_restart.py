"""kill -9 during runs, restart on the same data dir: finished runs and artifacts intact,
in-progress runs ``interrupted``, the SQLite store not corrupted."""

from __future__ import annotations

import time

from service_server import SCENARIOS, Server

from lynxplan.client import Client
from lynxplan.service.jobs import JobStore


def test_kill_during_runs_then_restart(tmp_path) -> None:
    data = tmp_path / "data"
    first = Server(data, "--workers", "1")
    try:
        with Client(first.url) as client:
            done = client.run(SCENARIOS / "free_motion.yaml", quick=True)
            assert done.state == "succeeded"
            artifacts = {n: client.artifact(done.id, n) for n in done.artifacts}
            running = client.submit(SCENARIOS / "ok_task.yaml")
            queued = client.submit(SCENARIOS / "ok_task.yaml")
            deadline = time.monotonic() + 60
            while client.status(running).state != "running" and time.monotonic() < deadline:
                time.sleep(0.05)
            assert client.status(running).state == "running"
    finally:
        first.kill()
    store = JobStore(data / "lynxplan.sqlite3")
    assert store.integrity() == "ok"
    store.close()
    second = Server(data, "--workers", "1")
    try:
        with Client(second.url) as client:
            again = client.status(done.id)
            assert again == done
            assert {n: client.artifact(done.id, n) for n in again.artifacts} == artifacts
            for run_id in (running, queued):
                record = client.status(run_id)
                assert record.state == "interrupted", record
            assert client.run(SCENARIOS / "free_motion.yaml", quick=True).ok
    finally:
        second.stop()
