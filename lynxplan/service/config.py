"""Settings of one ``lynxplan serve`` process."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path


@dataclass(frozen=True)
class ServiceConfig:
    """Server settings.

    Attributes:
        data_dir: Job store and artifacts folder.
        workers: Run worker processes.
        token: Bearer token required on every request but /health (None: no check).
        max_body: Largest request body, in [bytes].
        max_batch: Largest batch (poses / configurations) in one request.
        max_json_batch: Largest batch in a JSON body (larger ones must be binary).
        dask_scheduler: Dask scheduler address, or None for the local pool.
        dask_batch: /ik batches at least this large go to Dask when configured.
        run_timeout: Wall-clock limit of one run, in [s].
        run_memory: Address-space limit of a run worker, in [bytes] (0: none).
    """

    data_dir: Path
    workers: int = 1
    token: str | None = None
    max_body: int = 64 * 1024**2
    max_batch: int = 1_000_000
    max_json_batch: int = 20_000
    dask_scheduler: str | None = None
    dask_batch: int = 50_000
    run_timeout: float = 600.0
    run_memory: int = 8 * 1024**3
    max_scenario: int = 1024**2
