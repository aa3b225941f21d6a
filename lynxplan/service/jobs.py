"""Scenario runs: the job store plus the executor that runs them.

Layout of the data dir::

    lynxplan.sqlite3          one row per run (state, inputs, report, artifacts, timings)
    runs/<id>/scenario.yaml   the scenario as submitted (YAML or JSON text)
    runs/<id>/files/          the URDF and meshes uploaded with it (:mod:`.uploads`), if any
    runs/<id>/out/            its artifacts (written atomically by the runner's staging folder)

The store is :mod:`.store`, one run's execution :mod:`.execute`, the worker pools :mod:`.pools`.
On start, runs left ``queued`` or ``running`` by a previous server process are marked
``interrupted``; finished runs keep their report and artifacts. Texts a run reports (its error,
summary, failed expectations) never show the server's paths: the run's folder reads as ``.``.
"""

from __future__ import annotations

import json
import shutil
import threading
import time
import uuid
from pathlib import Path
from typing import Any

from lynxplan.service.execute import execute_run, execute_run_packed, validate_scenario
from lynxplan.service.pools import DaskPool, Job, LocalPool
from lynxplan.service.store import (
    DEFAULT_RUN_MEMORY,
    DEFAULT_RUN_TIMEOUT,
    FINAL_STATES,
    RUN_STATES,
    JobStore,
    RunRecord,
)


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
        self.data_dir = Path(data_dir).absolute()
        (self.data_dir / "runs").mkdir(parents=True, exist_ok=True)
        self.store = JobStore(self.data_dir / "lynxplan.sqlite3")
        self.interrupted = self.store.mark_interrupted()
        self._jobs: dict[str, Job] = {}
        self._lock = threading.Lock()
        self.pool: LocalPool | DaskPool
        if dask_scheduler:
            self.pool = DaskPool(dask_scheduler, timeout, self._finish)
        else:
            self.pool = LocalPool(workers, timeout, memory_limit, self._finish)

    def run_dir(self, run_id: str) -> Path:
        """Folder of one run."""
        return self.data_dir / "runs" / run_id

    def new_run(self) -> tuple[str, Path]:
        """A new run id and its (created) folder, for the files uploaded with the run."""
        run_id = uuid.uuid4().hex
        folder = self.run_dir(run_id)
        folder.mkdir(parents=True)
        return run_id, folder

    def submit(
        self,
        source: str,
        kind: str,
        name: str,
        quick: bool,
        owner: str = "",
        run_id: str | None = None,
    ) -> RunRecord:
        """Store and queue a validated scenario (into the folder of :meth:`new_run` when
        ``run_id`` is given); the new record (state ``queued``)."""
        if run_id is None:
            run_id, folder = self.new_run()
        else:
            folder = self.run_dir(run_id)
        (folder / "scenario.yaml").write_text(source, encoding="utf-8")
        record = RunRecord(run_id, "queued", kind, name, quick, time.time(), owner=owner)
        self.store.insert(record)
        job = Job(run_id, folder / "scenario.yaml", folder / "out", quick, source)
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

    def _finish(self, job: Job, answer: dict[str, Any]) -> None:
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
                error=self._public(job, answer["error"]),
                timings=timings,
            )
            return
        timings["run"] = answer["seconds"]
        report = answer["report"]
        if report is not None and (self.run_dir(job.run_id) / "files").is_dir():
            # the report echoes robot.urdf: the uploaded URDF's path in the run's folder
            report = json.loads(self._public(job, json.dumps(report)))
            report_file = job.out_dir / "report.json"
            if report_file.is_file():
                report_file.write_text(self._public(job, report_file.read_text()))
        self.store.transition(
            job.run_id, ("queued", "running"), state="succeeded", finished=now,
            ok=answer["ok"], summary=self._public(job, answer["summary"]),
            report=report, artifacts=answer["artifacts"], timings=timings,
            error=self._public(job, "; ".join(answer["failures"])) or None,
        )  # fmt: skip

    def _public(self, job: Job, text: str) -> str:
        """``text`` without the server's paths: the run's folder as ``.``, the data dir as
        ``<data-dir>`` (also as resolved, in case it is reached through a link)."""
        folder = self.run_dir(job.run_id)
        for path, shown in (
            (folder / "files", "."),
            (folder, "."),
            (self.data_dir, "<data-dir>"),
        ):
            for spelling in sorted({str(path.resolve()), str(path)}, key=len, reverse=True):
                text = text.replace(spelling + "/", "" if shown == "." else shown + "/")
                text = text.replace(spelling, shown)
        return text

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
    "DaskPool",
    "JobStore",
    "LocalPool",
    "RunManager",
    "RunRecord",
    "execute_run",
    "execute_run_packed",
    "validate_scenario",
]
