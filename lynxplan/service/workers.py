"""The compute pool: warm worker processes that run the routes' heavier computations (``/check``,
``/trajectory``, ``/plan``, ``/view``, and ``/fk`` and ``/ik`` past a few milliseconds of work)
outside the server process; large arrays and answers pass through shared memory.

Each worker is bounded in memory (``RLIMIT_AS``) and each computation in time: a computation
past its time limit, or whose client has disconnected, has its worker killed (and replaced in
the background). The server process itself only decodes requests, checks the sizes they imply
(:mod:`.sizes`) and forwards the answer's bytes, so no request can grow it beyond its body and
its answer. Computations wait for a free worker in arrival order; past
:data:`MAX_WAITING` waiting requests the server answers 503.
"""

from __future__ import annotations

import asyncio
import contextlib
import mmap
import multiprocessing
import os
import threading
import time
from dataclasses import dataclass
from multiprocessing import reduction
from typing import Any

import numpy as np
from starlette.requests import Request

from lynxplan.service.problems import Problem
from lynxplan.service.wire import Encoded

#: Requests that may wait for a compute worker at once (each holds its decoded body).
MAX_WAITING = 64
#: Seconds between two checks of the client's connection while a computation runs.
DISCONNECT_POLL = 0.1
#: Seconds a new worker may take to import, load the robots and report ready.
START_TIMEOUT = 180.0
#: Scheduling niceness of the compute workers: their warm-up and long computations yield the
#: cores to the server process, whose hot routes (/ik, /fk) keep their latency.
WORKER_NICENESS = 10
#: Arrays and answers at least this large, in [bytes], travel between the server and a worker
#: in shared memory (a memfd whose descriptor follows the message over the worker's socket):
#: copied once each way instead of streamed through the socket in small pieces.
SHARE_BYTES = 1 << 20


@dataclass(frozen=True)
class _Shared:
    """Stands in a message for a buffer that follows it as a memfd: an array (``dtype``,
    ``shape``) or bytes (``dtype`` empty). (Not a tuple: an answer's payload may be one.)"""

    nbytes: int
    dtype: str
    shape: tuple[int, ...]


def _write_memfd(data: Any) -> int:
    """A new memfd holding the bytes of ``data`` (a C-contiguous buffer)."""
    fd = os.memfd_create("lynxplan-compute", os.MFD_CLOEXEC)
    try:
        view = memoryview(data).cast("B")
        written = 0
        while written < len(view):
            written += os.write(fd, view[written:])
    except BaseException:
        os.close(fd)
        raise
    return fd


def _send_shared(connection: Any, message: Any, buffers: list[Any]) -> None:
    """``message``, then each of ``buffers`` as a memfd (its descriptor passed, then closed)."""
    fds = [_write_memfd(buffer) for buffer in buffers]
    try:
        connection.send(message)
        for fd in fds:
            reduction.send_handle(connection, fd, 0)
    finally:
        for fd in fds:
            os.close(fd)


def _receive_shared(connection: Any, shared: _Shared) -> Any:
    """The buffer ``shared`` stands for, from the memfd that follows on ``connection``: an
    array (a private copy-on-write mapping: no copy) or bytes."""
    fd = reduction.recv_handle(connection)
    try:
        if not shared.dtype:
            with mmap.mmap(fd, shared.nbytes, prot=mmap.PROT_READ) as mapped:
                return mapped[:]
        mapped = mmap.mmap(fd, shared.nbytes, flags=mmap.MAP_PRIVATE,
                           prot=mmap.PROT_READ | mmap.PROT_WRITE)  # fmt: skip
        return np.frombuffer(mapped, dtype=shared.dtype).reshape(shared.shape)
    finally:
        os.close(fd)


def _share_arrays(kwargs: dict[str, Any]) -> tuple[dict[str, Any], list[Any]]:
    """``kwargs`` with its large arrays replaced by :class:`_Shared`, and those arrays."""
    sent, buffers = dict(kwargs), []
    for name, value in kwargs.items():
        if isinstance(value, np.ndarray) and value.nbytes >= SHARE_BYTES:
            array = np.ascontiguousarray(value)
            sent[name] = _Shared(array.nbytes, array.dtype.str, array.shape)
            buffers.append(array)
    return sent, buffers


def _receive_arrays(connection: Any, kwargs: dict[str, Any]) -> dict[str, Any]:
    """``kwargs`` with each :class:`_Shared` replaced by its array (in message order)."""
    return {name: _receive_shared(connection, value) if isinstance(value, _Shared) else value
            for name, value in kwargs.items()}  # fmt: skip


def _send_answer(connection: Any, answer: tuple[int, Any]) -> None:
    """A task's ``(status, payload)``; a large content travels as a memfd."""
    status, payload = answer
    content = payload[0] if isinstance(payload, tuple) else payload
    if status != 200 or not isinstance(content, bytes) or len(content) < SHARE_BYTES:
        connection.send(answer)
        return
    marker = _Shared(len(content), "", ())
    shared = (marker, *payload[1:]) if isinstance(payload, tuple) else marker
    _send_shared(connection, (status, shared), [content])


def _receive_answer(connection: Any) -> tuple[int, Any]:
    """The worker's ``(status, payload)``, a content sent as a memfd read back."""
    status, payload = connection.recv()
    content = payload[0] if isinstance(payload, tuple) else payload
    if isinstance(content, _Shared):
        data = _receive_shared(connection, content)
        payload = (data, *payload[1:]) if isinstance(payload, tuple) else data
    return status, payload


def _worker_main(connection: Any, memory_limit: int) -> None:
    """A compute worker: run the tasks received on ``connection`` until it closes."""
    from lynxplan.service import compute

    _exit_with_parent()
    with contextlib.suppress(OSError):
        os.nice(WORKER_NICENESS)  # the server's hot routes keep their latency under heavy work
    if memory_limit > 0:
        import resource

        resource.setrlimit(resource.RLIMIT_AS, (memory_limit, memory_limit))
    compute.warm_up()
    connection.send("ready")
    while True:
        try:
            name, kwargs = connection.recv()
            kwargs = _receive_arrays(connection, kwargs)
        except (EOFError, OSError, RuntimeError):
            return
        _send_answer(connection, compute.run_task(name, kwargs, memory_limit))


def _exit_with_parent() -> None:
    """Exit when the server process dies (even by kill -9, even mid-task): a thread watches
    the parent's pid. (PR_SET_PDEATHSIG would fire when the *thread* that started the worker
    ends, and workers are started from short-lived threads.)"""
    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(0)

    threading.Thread(target=watch, daemon=True, name="parent-watch").start()


class _Worker:
    """One compute worker process, killed on a timeout or a disconnect and started again."""

    def __init__(self, memory_limit: int) -> None:
        self._memory_limit = memory_limit
        self._process: Any = None
        self._connection: Any = None
        self._starting = threading.Lock()  # one start at a time; a run waits for it

    @property
    def alive(self) -> bool:
        process = self._process
        return process is not None and process.is_alive()

    def ensure(self) -> None:
        """Start the process (and wait until it is warm) unless it runs."""
        with self._starting:
            if not self.alive:
                self._start()

    def _start(self) -> None:
        self.kill()
        context = multiprocessing.get_context("spawn")
        parent, child = context.Pipe()
        process = context.Process(target=_worker_main, args=(child, self._memory_limit),
                                  daemon=True, name="lynxplan-compute-worker")  # fmt: skip
        process.start()
        child.close()
        self._process, self._connection = process, parent
        try:
            ready = parent.poll(START_TIMEOUT) and parent.recv() == "ready"
        except (EOFError, OSError):
            ready = False
        if not ready:
            self.kill()
            raise RuntimeError("a compute worker did not start")

    def kill(self) -> None:
        process, connection = self._process, self._connection
        self._process = self._connection = None
        if process is not None:
            process.kill()
            process.join(5)
        if connection is not None:
            connection.close()

    def run(self, message: tuple[str, dict[str, Any]], timeout: float,
            cancelled: threading.Event) -> tuple[int, Any]:  # fmt: skip
        """The worker's answer ``(status, payload)`` to ``message``; the worker is killed when
        ``cancelled`` is set or after ``timeout`` seconds."""
        try:
            self.ensure()
            connection = self._connection
            if connection is None:
                raise RuntimeError("the pool is closing")
            task, kwargs = message
            sent, buffers = _share_arrays(kwargs)
            _send_shared(connection, (task, sent), buffers)
        except (RuntimeError, OSError) as exc:
            self.kill()
            return 503, (f"no compute worker available: {exc}", None)
        deadline = time.monotonic() + timeout
        while True:
            try:
                if connection.poll(0.05):
                    return _receive_answer(connection)
            except (EOFError, OSError, RuntimeError):
                self.kill()
                return 503, ("the compute worker died (memory limit?); the request was not run "
                             "to its end", None)  # fmt: skip
            if cancelled.is_set():
                self.kill()
                return 499, ("the client disconnected", None)
            if time.monotonic() > deadline:
                self.kill()
                return 503, (f"the computation exceeded its time limit of {timeout:g} s", None)


class ComputePool:
    """``workers`` compute worker processes, each limited to ``memory_limit`` bytes of address
    space (0: none), each computation to ``timeout`` seconds."""

    def __init__(self, workers: int, memory_limit: int, timeout: float) -> None:
        self.timeout = timeout
        self._workers = [_Worker(memory_limit) for _ in range(max(1, workers))]
        self._idle: asyncio.Queue[_Worker] | None = None
        self._waiting = 0
        self._closed = False

    def start(self) -> None:
        """Start and warm the workers in the background (the server answers meanwhile)."""
        for worker in self._workers:
            threading.Thread(target=self._ensure_quietly, args=(worker,), daemon=True).start()

    @staticmethod
    def _ensure_quietly(worker: _Worker) -> None:
        with contextlib.suppress(RuntimeError):
            worker.ensure()

    async def call(self, request: Request | None, task: str, **kwargs: Any) -> bytes:
        """The answer's bytes of ``task`` (a name in :data:`compute.TASKS`) run by a worker;
        Problem with the worker's status otherwise. The worker is killed if the client of
        ``request`` disconnects meanwhile."""
        content, _, _ = await self.call_encoded(request, task, **kwargs)
        return content

    async def call_encoded(self, request: Request | None, task: str, **kwargs: Any) -> Encoded:
        """As :meth:`call`: the answer's (content, media type, headers); a task that answers
        bytes answers JSON."""
        loop = asyncio.get_running_loop()
        if self._idle is None:
            self._idle = asyncio.Queue()
            for worker in self._workers:
                self._idle.put_nowait(worker)
        if self._waiting >= MAX_WAITING:
            raise Problem(503, f"the server is busy ({self._waiting} computations wait); retry")
        self._waiting += 1
        try:
            worker = await self._idle.get()
        finally:
            self._waiting -= 1
        cancelled = threading.Event()
        future = loop.run_in_executor(None, worker.run, (task, kwargs), self.timeout, cancelled)
        future.add_done_callback(lambda _: self._release(worker, loop))
        try:
            while not future.done():
                await asyncio.wait({future}, timeout=DISCONNECT_POLL)
                if not future.done() and request is not None and await request.is_disconnected():
                    cancelled.set()
            status, payload = future.result()
        except asyncio.CancelledError:
            cancelled.set()
            raise
        if status == 200:
            if isinstance(payload, tuple):
                content, media, headers = payload
                return content, media, headers
            return payload, "application/json", {}
        detail, field = payload
        raise Problem(status, detail, field)

    def _release(self, worker: _Worker, loop: asyncio.AbstractEventLoop) -> None:
        """Give ``worker`` back to the idle queue (after starting it again if it was killed)."""
        if self._closed or self._idle is None:
            return
        if worker.alive:
            self._idle.put_nowait(worker)
            return

        def restart() -> None:
            delay = 1.0
            while not self._closed:
                try:
                    worker.ensure()
                    break
                except RuntimeError:  # e.g. a memory limit too small to import: back off
                    time.sleep(delay)
                    delay = min(2 * delay, 60.0)
            if not self._closed and self._idle is not None:
                loop.call_soon_threadsafe(self._idle.put_nowait, worker)

        threading.Thread(target=restart, daemon=True, name="compute-restart").start()

    def close(self) -> None:
        """Kill the workers."""
        self._closed = True
        for worker in self._workers:
            worker.kill()


__all__ = ["MAX_WAITING", "ComputePool"]
