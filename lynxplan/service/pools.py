"""The executors of runs: a pool of warm local worker processes (``--workers``), each run bounded
in time (the worker is killed and replaced when a run exceeds it or is cancelled) and in memory
(``RLIMIT_AS`` of the worker), or a Dask cluster (``--dask-scheduler``), whose workers need not
share this disk: the task returns the artifacts' bytes."""

from __future__ import annotations

import contextlib
import multiprocessing
import queue
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lynxplan.service.execute import execute_run, execute_run_packed
from lynxplan.shipped import scenario_path

#: Scenario each worker runs once before it reports ready (the OK task: the service's benchmark).
WARM_UP_SCENARIO = scenario_path("ok_task.yaml")


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
    _rehearse(WARM_UP_SCENARIO)


def _rehearse(scenario: Path) -> None:
    """Run ``scenario`` once (quick, into a temporary folder, errors ignored): its first run
    loads the numba kernels, collision models and caches that imports alone do not (measured:
    the first OK-task run of a fresh worker takes 1.1 s, later ones 0.45 s)."""
    if not scenario.is_file():  # an installed package without the repository's scenarios
        return
    with tempfile.TemporaryDirectory(prefix="lynxplan-warm-") as folder:
        execute_run(str(scenario), str(Path(folder) / "out"), True)


def _die_with_parent() -> None:
    """Linux: receive SIGKILL when the server process dies (even by kill -9)."""
    try:
        import ctypes
        import signal

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass


@dataclass
class Job:
    run_id: str
    scenario_path: Path
    out_dir: Path
    quick: bool
    source: str
    cancelled: threading.Event = field(default_factory=threading.Event)


Finish = Callable[[Job, dict[str, Any]], None]


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

    def execute(self, job: Job, timeout: float) -> dict[str, Any]:
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
        self._queue: queue.Queue[Job | None] = queue.Queue()
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

    def submit(self, job: Job) -> None:
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

    def submit(self, job: Job) -> None:
        """Submit a run; a thread waits for it (bounded by the time limit)."""
        threading.Thread(target=self._wait, args=(job,), daemon=True).start()

    def _wait(self, job: Job) -> None:
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


__all__ = ["DaskPool", "Finish", "Job", "LocalPool"]
