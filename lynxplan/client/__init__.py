"""A Python client of ``lynxplan serve`` that returns the library's own types.

Example::

    from lynxplan.client import Client

    with Client("http://127.0.0.1:8000") as client:
        T = client.fk([0.1, 0.5, -0.5, 0.3, 0.2])       # (4, 4) ndarray, as Arm.fk
        result = client.ik(T)                            # IkResult, as Arm.ik
        batch = client.ik(many_poses)                    # IkBatch, as Arm.ik_batch (binary)
        run = client.run("scenarios/ok_task.yaml", out_dir="out")

Numbers travel as shortest round-trip JSON or raw float64, so results equal the library's bit
for bit.
"""

from lynxplan.client.api import BINARY_BATCH, Client, run_remote
from lynxplan.client.results import RunResult
from lynxplan.client.transport import ServiceError

__all__ = ["BINARY_BATCH", "Client", "RunResult", "ServiceError", "run_remote"]
