"""Settings of one ``lynxplan serve`` process."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

#: Host names a loopback server answers to (the ``Host`` header, without the port).
LOOPBACK_HOSTS = ("127.0.0.1", "localhost", "::1", "[::1]")


@dataclass(frozen=True)
class ServiceConfig:
    """Server settings.

    Attributes:
        data_dir: Job store and artifacts folder.
        workers: Run worker processes.
        token: One shared bearer token required on every API request (None: no check); or
        tokens: Named tokens (name -> token, from ``name:token`` lines): each caller sees,
            reads and cancels only the runs its token created.
        allowed_hosts: Host names the ``Host`` header may carry (the bound names; ``*``: any).
        cors_origins: Origins (``scheme://host[:port]``) whose cross-origin requests are served.
        max_body: Largest request body, in [bytes].
        max_batch: Largest batch (poses / configurations) in one request.
        max_json_batch: Largest batch in a JSON body (larger ones must be binary).
        dask_scheduler: Dask scheduler address, or None for the local pool.
        dask_batch: /ik batches at least this large go to Dask when configured.
        run_timeout: Wall-clock limit of one run, in [s].
        run_memory: Address-space limit of a run worker, in [bytes] (0: none).
        max_scenario: Largest scenario text, in [bytes].
        max_upload: Largest total of the files uploaded with one run (URDF, meshes), in [bytes].
        compute_workers: Worker processes computing /check, /trajectory, /plan and /view
            (each limited to ``run_memory``).
        max_answer: Largest answer, in [bytes]: the sizes a request implies (poses, samples,
            clearances) are checked against it before anything is computed.
    """

    data_dir: Path
    workers: int = 1
    token: str | None = None
    tokens: dict[str, str] = field(default_factory=dict)
    allowed_hosts: tuple[str, ...] = LOOPBACK_HOSTS
    cors_origins: tuple[str, ...] = ()
    max_body: int = 64 * 1024**2
    max_batch: int = 1_000_000
    max_json_batch: int = 20_000
    dask_scheduler: str | None = None
    dask_batch: int = 50_000
    run_timeout: float = 600.0
    run_memory: int = 8 * 1024**3
    max_scenario: int = 1024**2
    max_upload: int = 32 * 1024**2
    compute_workers: int = 2
    max_answer: int = 256 * 1024**2
