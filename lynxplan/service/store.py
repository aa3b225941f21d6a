"""The SQLite job store of scenario runs: one row per run (state, inputs, report, artifacts,
timings), in ``lynxplan.sqlite3`` of the data dir."""

from __future__ import annotations

import json
import sqlite3
import threading
import time
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
    timings TEXT NOT NULL DEFAULT '{}',
    owner TEXT NOT NULL DEFAULT ''
)
"""
#: Stores written before run ownership lack the ``owner`` column: added on open.
_ADD_OWNER = "ALTER TABLE runs ADD COLUMN owner TEXT NOT NULL DEFAULT ''"


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
        owner: Name of the token that created the run (``""``: no token or one shared token).
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
    owner: str = ""

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
            columns = [row[1] for row in self._db.execute("PRAGMA table_info(runs)")]
            if "owner" not in columns:
                self._db.execute(_ADD_OWNER)

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
                "INSERT INTO runs (id, state, kind, name, quick, created, owner) "
                "VALUES (?,?,?,?,?,?,?)",
                (
                    record.id,
                    record.state,
                    record.kind,
                    record.name,
                    int(record.quick),
                    record.created,
                    record.owner,
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

    def page(
        self, offset: int, limit: int, owner: str | None = None
    ) -> tuple[list[RunRecord], int]:
        """Runs (of ``owner`` only, unless None), newest first, and their total count."""
        where, args = ("", ()) if owner is None else ("WHERE owner = ? ", (owner,))
        with self._lock:
            rows = self._db.execute(
                f"SELECT * FROM runs {where}ORDER BY created DESC, rowid DESC LIMIT ? OFFSET ?",
                (*args, limit, offset),
            ).fetchall()
            total = int(self._db.execute(f"SELECT COUNT(*) FROM runs {where}", args).fetchone()[0])
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
     artifacts, timings, owner) = row  # fmt: skip
    return RunRecord(
        run_id, state, kind, name, bool(quick), created, started, finished,
        None if ok is None else bool(ok), summary, error,
        None if report is None else json.loads(report), tuple(json.loads(artifacts)),
        json.loads(timings), owner,
    )  # fmt: skip


__all__ = ["DEFAULT_RUN_MEMORY", "DEFAULT_RUN_TIMEOUT", "FINAL_STATES", "RUN_STATES", "JobStore",
           "RunRecord"]  # fmt: skip
