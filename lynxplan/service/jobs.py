"""Scenario runs: a SQLite job store in the data dir and the workers that execute the runs.

Layout of the data dir::

    lynxplan.sqlite3          one row per run (state, inputs, report, artifacts, timings)
    runs/<id>/scenario.yaml   the scenario as submitted (YAML or JSON text)
    runs/<id>/out/            its artifacts (written atomically by the runner's staging folder)

Runs execute in a pool of worker processes (``--workers``), each run bounded in time (the worker
is killed and replaced when a run exceeds it or is cancelled) and in memory (``RLIMIT_AS`` of the
worker), or on a Dask cluster (``--dask-scheduler``), whose workers need not share this disk: the
task returns the artifacts' bytes. On start, runs left ``queued`` or ``running`` by a previous
server process are marked ``interrupted``; finished runs keep their report and artifacts.
"""

from __future__ import annotations

import contextlib
import json
import multiprocessing
import queue
import shutil
import sqlite3
import tempfile
import threading
import time
import uuid
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

#: Every state of a run; the last four are final.
RUN_STATES = ("queued", "running", "succeeded", "failed", "cancelled", "interrupted")
FINAL_STATES = frozenset(RUN_STATES[2:])
#: Default wall-clock limit of one run, in [s].
DEFAULT_RUN_TIMEOUT = 600.0
#: Default address-space limit of one worker process, in [bytes] (0: none).
DEFAULT_RUN_MEMORY = 8 * 1024**3

_SCHEMA = """
CREATE TABLE IF NOT EXISTS runs (
    id TEXT PRIMARY KEY,
    state TEXT NOT NULL,
    kind TEXT NOT NULL,
    name TEXT NOT NULL,
    quick INTEGER NOT NULL,
    created REAL NOT NULL,
    started REAL,
    finished REAL,
    ok INTEGER,
    summary TEXT,
    error TEXT,
    report TEXT,
    artifacts TEXT NOT NULL DEFAULT '[]',
    timings TEXT NOT NULL DEFAULT '{}'
)
"""


@dataclass(frozen=True)
class RunRecord:
    """One run as stored.

    Attributes:
        id: Run id (32 hex digits).
        state: One of :data:`RUN_STATES`.
        kind: Scenario kind; name: the scenario's name.
        quick: Whether slow outputs (plots, HTML) were skipped.
        created, started, finished: Unix times, in [s] (None until reached).
        ok: Every expectation held (None until the run succeeded).
        summary: The run's one-paragraph summary.
        error: One-line error of a failed run.
        report: The run's ``report.json`` content, if it wrote one.
        artifacts: Relative paths of its output files.
        timings: Durations, in [s]: ``queued``, ``run`` (worker), ``total``.
    """

    id: str
    state: str
    kind: str
    name: str
    quick: bool
    created: float
    started: float | None = None
    finished: float | None = None
    ok: bool | None = None
    summary: str | None = None
    error: str | None = None
    report: Any = None
    artifacts: tuple[str, ...] = ()
    timings: dict[str, float] = field(default_factory=dict)

    def as_json(self) -> dict[str, Any]:
        """The record as a JSON object (``progress`` 0 queued, 0.5 running, 1 final)."""
        progress = 1.0 if self.state in FINAL_STATES else 0.5 if self.state == "running" else 0.0
        return {
            "id": self.id, "state": self.state, "progress": progress, "kind": self.kind,
            "name": self.name, "quick": self.quick, "created": self.created,
            "started": self.started, "finished": self.finished, "ok": self.ok,
            "summary": self.summary, "error": self.error, "report": self.report,
            "artifacts": list(self.artifacts), "timings": self.timings,
        }  # fmt: skip


class JobStore:
    """The SQLite table of runs (WAL journal: a killed server never leaves it corrupt)."""

    def __init__(self, path: Path) -> None:
        self._db = sqlite3.connect(str(path), check_same_thread=False, isolation_level=None)
        self._lock = threading.Lock()
        with self._lock:
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=NORMAL")
            self._db.execute(_SCHEMA)

    def close(self) -> None:
        """Close the database."""
        with self._lock:
            self._db.close()

    def integrity(self) -> str:
        """SQLite's ``PRAGMA integrity_check`` answer (``"ok"``)."""
        with self._lock:
            return str(self._db.execute("PRAGMA integrity_check").fetchone()[0])

    def insert(self, record: RunRecord) -> None:
        """Store a new run."""
        with self._lock:
            self._db.execute(
                "INSERT INTO runs (id, state, kind, name, quick, created) VALUES (?,?,?,?,?,?)",
                (
                    record.id,
                    record.state,
                    record.kind,
                    record.name,
                    int(record.quick),
                    record.created,
                ),
            )

    def update(self, run_id: str, **values: Any) -> None:
        """Set columns of one run (JSON-encodes report, artifacts and timings)."""
        for key in ("report", "artifacts", "timings"):
            if key in values:
                values[key] = json.dumps(values[key], allow_nan=False, default=_jsonable)
        if "ok" in values and values["ok"] is not None:
            values["ok"] = int(values["ok"])
        columns = ", ".join(f"{key} = ?" for key in values)
        with self._lock:
            self._db.execute(f"UPDATE runs SET {columns} WHERE id = ?", (*values.values(), run_id))

    def transition(self, run_id: str, source: tuple[str, ...], **values: Any) -> bool:
        """Update a run only if its state is one of ``source``; whether it was."""
        with self._lock:
            row = self._db.execute("SELECT state FROM runs WHERE id = ?", (run_id,)).fetchone()
        if row is None or row[0] not in source:
            return False
        self.update(run_id, **values)
        return True

    def get(self, run_id: str) -> RunRecord | None:
        """The run, or None."""
        with self._lock:
            row = self._db.execute("SELECT * FROM runs WHERE id = ?", (run_id,)).fetchone()
        return None if row is None else _record(row)

    def page(self, offset: int, limit: int) -> tuple[list[RunRecord], int]:
        """Runs, newest first, and the total count."""
        with self._lock:
            rows = self._db.execute(
                "SELECT * FROM runs ORDER BY created DESC, rowid DESC LIMIT ? OFFSET ?",
                (limit, offset),
            ).fetchall()
            total = int(self._db.execute("SELECT COUNT(*) FROM runs").fetchone()[0])
        return [_record(row) for row in rows], total

    def mark_interrupted(self) -> int:
        """Mark runs a previous server left queued or running as ``interrupted``; their count."""
        with self._lock:
            cursor = self._db.execute(
                "UPDATE runs SET state = 'interrupted', finished = ?, "
                "error = 'the server stopped during this run' "
                "WHERE state IN ('queued', 'running')",
                (time.time(),),
            )
            return int(cursor.rowcount)


def _jsonable(value: Any) -> Any:
    return value.tolist() if hasattr(value, "tolist") else str(value)


def _record(row: tuple[Any, ...]) -> RunRecord:
    (run_id, state, kind, name, quick, created, started, finished, ok, summary, error, report,
     artifacts, timings) = row  # fmt: skip
    return RunRecord(
        run_id, state, kind, name, bool(quick), created, started, finished,
        None if ok is None else bool(ok), summary, error,
        None if report is None else json.loads(report), tuple(json.loads(artifacts)),
        json.loads(timings),
    )  # fmt: skip


# -- executing one run (in a worker process or on a Dask worker) --------------------
def execute_run(scenario_path: str, out_dir: str, quick: bool) -> dict[str, Any]:
    """Run a scenario file into ``out_dir``; never raises.

    Returns:
        ``{"ok", "summary", "failures", "report", "artifacts", "seconds"}``, or ``{"error": line}``.
    """
    from lynxplan.exceptions import LynxplanError

    start = time.perf_counter()
    try:
        result = _run_scenario(scenario_path, out_dir, quick)
    except LynxplanError as exc:
        return {"error": str(exc).splitlines()[0] if str(exc) else type(exc).__name__}
    except MemoryError:
        return {"error": "the run exceeded the worker's memory limit"}
    except Exception as exc:
        return {"error": f"internal error: {type(exc).__name__}: {exc}".splitlines()[0]}
    out = Path(out_dir)
    report_path = out / "report.json"
    report = json.loads(report_path.read_text()) if report_path.is_file() else None
    return {
        "ok": bool(result.ok),
        "summary": str(result.summary),
        "failures": list(result.failed_expectations),
        "report": report,
        "artifacts": sorted(result.artifacts),
        "seconds": time.perf_counter() - start,
    }


def _run_scenario(scenario_path: str, out_dir: str, quick: bool) -> Any:
    from lynxplan.scenarios import run_scenario

    return run_scenario(scenario_path, out_dir, quick=quick, force=True)


def execute_run_packed(source: str, quick: bool) -> dict[str, Any]:
    """:func:`execute_run` of scenario text in a temporary folder, artifacts returned as bytes
    (``"files"``: relative path -> content), for workers that do not share the server's disk."""
    with tempfile.TemporaryDirectory(prefix="lynxplan-run-") as folder:
        scenario = Path(folder) / "scenario.yaml"
        scenario.write_text(source, encoding="utf-8")
        out = Path(folder) / "out"
        answer = execute_run(str(scenario), str(out), quick)
        if "error" not in answer:
            answer["files"] = {name: (out / name).read_bytes() for name in answer["artifacts"]}
        return answer


def validate_scenario(source: str) -> tuple[str, str]:
    """Validate scenario text (YAML or JSON) without running it; its (kind, name).

    A scenario sent over the network may not name files on the server: a ``robot.urdf`` path
    is refused (built-in robot names only).

    Raises:
        lynxplan.exceptions.ScenarioError: naming the key path and the reason.
    """
    from lynxplan.exceptions import ScenarioError
    from lynxplan.scenarios import load_scenario

    with tempfile.TemporaryDirectory(prefix="lynxplan-check-") as folder:
        path = Path(folder) / "scenario.yaml"
        path.write_text(source, encoding="utf-8")
        scenario = load_scenario(path).scenario
    if getattr(getattr(scenario, "robot", None), "urdf", None) is not None:
        raise ScenarioError(
            "<request>",
            "robot.urdf",
            "the service runs built-in robots only "
            "(robot: {name: ...}); it does not read URDF paths on its disk",
        )
    return str(getattr(scenario, "kind", "")), str(getattr(scenario, "name", "") or "")


# -- local worker processes ----------------------------------------
def _worker_main(connection: Any, memory_limit: int) -> None:
    """A worker process: run scenarios received on ``connection`` until it closes."""
    _die_with_parent()
    if memory_limit > 0:
        import resource

        resource.setrlimit(resource.RLIMIT_AS, (memory_limit, memory_limit))
    _warm_up()
    connection.send("ready")
    while True:
        try:
            message = connection.recv()
        except (EOFError, OSError):
            return
        connection.send(execute_run(*message))


def _warm_up() -> None:
    """Import every scenario kind and load the arm before the first run (fast first runs)."""
    import importlib

    from lynxplan.arm.model import load_arm
    from lynxplan.scenarios.registry import KIND_MODULES

    importlib.import_module("lynxplan.scenarios.runner")
    for module in KIND_MODULES.values():
        with contextlib.suppress(ImportError):
            importlib.import_module(module)
    load_arm()


def _die_with_parent() -> None:
    """Linux: receive SIGKILL when the server process dies (even by kill -9)."""
    try:
        import ctypes
        import signal

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


@dataclass
class _Job:
    run_id: str
    scenario_path: Path
    out_dir: Path
    quick: bool
    source: str
    cancelled: threading.Event = field(default_factory=threading.Event)


Finish = Callable[[_Job, dict[str, Any]], None]


class _WorkerSlot:
    """One worker process, replaced when killed (timeout, cancel) or dead."""

    def __init__(self, memory_limit: int) -> None:
        self._memory_limit = memory_limit
        self._process: Any = None
        self._connection: Any = None

    def ensure(self) -> None:
        if self._process is not None and self._process.is_alive():
            return
        context = multiprocessing.get_context("spawn")
        parent, child = context.Pipe()
        process = context.Process(
            target=_worker_main,
            args=(child, self._memory_limit),
            daemon=True,
            name="lynxplan-run-worker",
        )
        process.start()
        child.close()
        self._process, self._connection = process, parent
        try:
            ready = parent.poll(120) and parent.recv() == "ready"
        except (EOFError, OSError):
            ready = False
        if not ready:
            self.kill()
            raise RuntimeError("a run worker did not start")

    def kill(self) -> None:
        if self._process is not None:
            self._process.kill()
            self._process.join(5)
            self._connection.close()
        self._process = self._connection = None

    def execute(self, job: _Job, timeout: float) -> dict[str, Any]:
        try:
            self.ensure()
            self._connection.send((str(job.scenario_path), str(job.out_dir), job.quick))
        except (RuntimeError, OSError) as exc:
            self.kill()
            return {"error": f"worker failure: {exc}"}
        deadline = time.monotonic() + timeout
        while True:
            try:
                if self._connection.poll(0.05):
                    answer: dict[str, Any] = self._connection.recv()
                    return answer
            except (EOFError, OSError):
                self.kill()
                return {"error": "the worker process died during the run (memory limit?)"}
            if job.cancelled.is_set():
                self.kill()
                return {"cancelled": True}
            if time.monotonic() > deadline:
                self.kill()
                return {"error": f"the run exceeded its time limit of {timeout:g} s"}


class LocalPool:
    """``workers`` worker processes fed from one queue."""

    def __init__(self, workers: int, timeout: float, memory_limit: int, finish: Finish) -> None:
        self._queue: queue.Queue[_Job | None] = queue.Queue()
        self._timeout, self._finish = timeout, finish
        self._slots = [_WorkerSlot(memory_limit) for _ in range(workers)]
        self._threads = [
            threading.Thread(target=self._serve, args=(slot,), daemon=True, name=f"run-slot-{i}")
            for i, slot in enumerate(self._slots)
        ]
        for thread in self._threads:
            thread.start()

    def _serve(self, slot: _WorkerSlot) -> None:
        with contextlib.suppress(RuntimeError):
            slot.ensure()  # start (and warm) the worker before the first run arrives
        while (job := self._queue.get()) is not None:
            if job.cancelled.is_set():
                continue
            self._finish(job, {"started": time.time()})
            self._finish(job, slot.execute(job, self._timeout))

    def submit(self, job: _Job) -> None:
        """Queue a run."""
        self._queue.put(job)

    def close(self) -> None:
        """Stop the workers (running runs are killed)."""
        for _ in self._threads:
            self._queue.put(None)
        for slot in self._slots:
            slot.kill()


class DaskPool:
    """Runs (and large IK batches) submitted to a Dask ``distributed`` scheduler."""

    def __init__(self, address: str, timeout: float, finish: Finish) -> None:
        import distributed

        connect: Any = distributed.Client
        self.client: Any = connect(address, timeout=30, set_as_default=False)
        self._timeout, self._finish = timeout, finish

    def submit(self, job: _Job) -> None:
        """Submit a run; a thread waits for it (bounded by the time limit)."""
        threading.Thread(target=self._wait, args=(job,), daemon=True).start()

    def _wait(self, job: _Job) -> None:
        self._finish(job, {"started": time.time()})
        future: Any = self.client.submit(execute_run_packed, job.source, job.quick, pure=False)
        deadline = time.monotonic() + self._timeout
        while not future.done():
            if job.cancelled.is_set():
                future.cancel()
                self._finish(job, {"cancelled": True})
                return
            if time.monotonic() > deadline:
                future.cancel()
                self._finish(
                    job, {"error": f"the run exceeded its time limit of {self._timeout:g} s"}
                )
                return
            time.sleep(0.05)
        try:
            answer = future.result()
        except Exception as exc:
            answer = {"error": f"dask: {type(exc).__name__}: {exc}".splitlines()[0]}
        for name, content in answer.pop("files", {}).items():
            target = job.out_dir / name
            target.parent.mkdir(parents=True, exist_ok=True)
            target.write_bytes(content)
        self._finish(job, answer)

    def close(self) -> None:
        """Disconnect from the scheduler."""
        self.client.close()


class RunManager:
    """The job store plus the executor (local pool or Dask)."""

    def __init__(
        self,
        data_dir: Path,
        *,
        workers: int = 1,
        timeout: float = DEFAULT_RUN_TIMEOUT,
        memory_limit: int = DEFAULT_RUN_MEMORY,
        dask_scheduler: str | None = None,
    ) -> None:
        self.data_dir = Path(data_dir)
        (self.data_dir / "runs").mkdir(parents=True, exist_ok=True)
        self.store = JobStore(self.data_dir / "lynxplan.sqlite3")
        self.interrupted = self.store.mark_interrupted()
        self._jobs: dict[str, _Job] = {}
        self._lock = threading.Lock()
        self.pool: LocalPool | DaskPool
        if dask_scheduler:
            self.pool = DaskPool(dask_scheduler, timeout, self._finish)
        else:
            self.pool = LocalPool(workers, timeout, memory_limit, self._finish)

    def run_dir(self, run_id: str) -> Path:
        """Folder of one run."""
        return self.data_dir / "runs" / run_id

    def submit(self, source: str, kind: str, name: str, quick: bool) -> RunRecord:
        """Store and queue a validated scenario; the new record (state ``queued``)."""
        run_id = uuid.uuid4().hex
        folder = self.run_dir(run_id)
        folder.mkdir(parents=True)
        (folder / "scenario.yaml").write_text(source, encoding="utf-8")
        record = RunRecord(run_id, "queued", kind, name, quick, time.time())
        self.store.insert(record)
        job = _Job(run_id, folder / "scenario.yaml", folder / "out", quick, source)
        with self._lock:
            self._jobs[run_id] = job
        self.pool.submit(job)
        return record

    def cancel(self, run_id: str) -> RunRecord | None:
        """Cancel a queued or running run (its worker is killed); the record, or None."""
        with self._lock:
            job = self._jobs.get(run_id)
        if job is not None:
            job.cancelled.set()
        self.store.transition(
            run_id,
            ("queued", "running"),
            state="cancelled",
            finished=time.time(),
            error="cancelled by the client",
        )
        return self.store.get(run_id)

    def _finish(self, job: _Job, answer: dict[str, Any]) -> None:
        if "started" in answer:
            self.store.transition(
                job.run_id, ("queued",), state="running", started=answer["started"]
            )
            return
        with self._lock:
            self._jobs.pop(job.run_id, None)
        record = self.store.get(job.run_id)
        if record is None or record.state in FINAL_STATES:
            return
        now = time.time()
        started = record.started or now
        timings = {"queued": started - record.created, "total": now - record.created}
        if "cancelled" in answer:
            return
        if "error" in answer:
            shutil.rmtree(job.out_dir, ignore_errors=True)
            self.store.transition(
                job.run_id,
                ("queued", "running"),
                state="failed",
                finished=now,
                error=answer["error"],
                timings=timings,
            )
            return
        timings["run"] = answer["seconds"]
        self.store.transition(
            job.run_id, ("queued", "running"), state="succeeded", finished=now,
            ok=answer["ok"], summary=answer["summary"], report=answer["report"],
            artifacts=answer["artifacts"], timings=timings,
            error="; ".join(answer["failures"]) or None,
        )  # fmt: skip

    def artifact(self, run_id: str, name: str) -> Path | None:
        """Path of an artifact the run listed (never a path outside its folder), or None."""
        record = self.store.get(run_id)
        if record is None or name not in record.artifacts:
            return None
        path = self.run_dir(run_id) / "out" / name
        return path if path.is_file() else None

    def close(self) -> None:
        """Stop the executor and close the store."""
        self.pool.close()
        self.store.close()


def remove_tree(path: Path) -> None:
    """Remove a run folder (best effort)."""
    shutil.rmtree(path, ignore_errors=True)


__all__ = [
    "DEFAULT_RUN_MEMORY",
    "DEFAULT_RUN_TIMEOUT",
    "FINAL_STATES",
    "RUN_STATES",
    "JobStore",
    "RunManager",
    "RunRecord",
    "execute_run",
    "execute_run_packed",
    "validate_scenario",
]
