"""Fan-out on Dask: long batches (workspace sweeps, IK batches, SmallArmBench) in chunks on a
cluster, results merged in the serial order and identical to the serial run.

:mod:`lynxplan.fanout.cluster` is the generic part (connect or start a LocalCluster, submit
chunks, gather in order, progress); :mod:`lynxplan.fanout.workspace` and
:mod:`lynxplan.fanout.ik` split their own work.
"""

from lynxplan.fanout.cluster import Cluster, cluster_from_options, map_chunks, open_client

__all__ = ["Cluster", "cluster_from_options", "map_chunks", "open_client"]
