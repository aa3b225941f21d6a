"""Workspace sweeps on a Dask LocalCluster: the same estimate, bit for bit, as the serial sweep;
``lynxplan workspace --dask-local 2`` writes the same workspace.json."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

from lynxplan.arm.workspace import estimate_workspace
from lynxplan.fanout import Cluster
from lynxplan.fanout.workspace import estimate_workspace_on_dask, sample_workspace_on_dask
from lynxplan.robots import load_robot
from lynxplan.robots.workspace import sample_workspace

LYNXPLAN = str(Path(sys.executable).with_name("lynxplan"))


def test_al5_estimate_equals_the_serial_one(arm, dask_cluster: Cluster) -> None:  # type: ignore[no-untyped-def]
    # 3 chunks of the serial sweep (500,000 each), the last one short; a kept subset per chunk.
    settings = {"samples": 1_000_003, "voxel_size": 0.01, "cell": 0.002, "seed": 7, "keep": 999}
    serial = estimate_workspace(arm.geometry, arm.limits, **settings)  # type: ignore[arg-type]
    seen: list[int] = []
    fanned = estimate_workspace_on_dask(
        arm.geometry, arm.limits, cluster=dask_cluster, progress=lambda d, n: seen.append(d),
        **settings,  # type: ignore[arg-type]
    )  # fmt: skip
    for name in ("samples", "volume_revolution", "volume_voxels", "max_reach", "z_range"):
        assert getattr(fanned, name) == getattr(serial, name), name
    np.testing.assert_array_equal(fanned.positions, serial.positions)
    for name in ("occupied", "r_edges", "z_edges"):
        np.testing.assert_array_equal(
            getattr(fanned.envelope, name), getattr(serial.envelope, name)
        )
    assert sorted(seen)[-1] == 1_000_003 and len(seen) == 3


def test_any_robot_sample_equals_the_serial_one(dask_cluster: Cluster) -> None:
    robot = load_robot("so101")
    settings = {"samples": 450_001, "voxel_size": 0.01, "seed": 3, "keep": 998}
    serial = sample_workspace(robot, **settings)  # type: ignore[arg-type]
    fanned = sample_workspace_on_dask(robot, cluster=dask_cluster, **settings)  # type: ignore[arg-type]
    assert (fanned.samples, fanned.volume_voxels, fanned.max_reach, fanned.z_range) == (
        serial.samples, serial.volume_voxels, serial.max_reach, serial.z_range,
    )  # fmt: skip
    np.testing.assert_array_equal(fanned.positions, serial.positions)
    assert not fanned.positions.flags.writeable


def _workspace(out: Path, *extra: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [LYNXPLAN, "workspace", "--samples", "30000", "--seed", "5", "--out", str(out), *extra],
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip


def test_cli_writes_the_serial_outputs(tmp_path: Path, dask_cluster: Cluster) -> None:
    serial = _workspace(tmp_path / "serial", "--json", "--robot", "so101")
    fanned = _workspace(tmp_path / "dask", "--json", "--robot", "so101",
                        "--dask-scheduler", str(dask_cluster.scheduler))  # fmt: skip
    assert serial.returncode == fanned.returncode == 0, fanned.stderr
    assert fanned.stdout == serial.stdout
    for name in ("workspace.json", "workspace.html"):
        assert (tmp_path / "dask" / name).read_bytes() == (tmp_path / "serial" / name).read_bytes()


def test_cli_bad_dask_options_exit_2_in_one_line(tmp_path: Path) -> None:
    for extra, message in (
        (("--dask-local", "0"), "--dask-local needs at least 1 worker. Got: 0"),
        (("--dask-local", "2", "--dask-scheduler", "tcp://h:1"), "not both"),
        (("--dask-local", "two"), "argument --dask-local: invalid int value: 'two'"),
    ):
        done = _workspace(tmp_path / "w", *extra)
        assert done.returncode == 2 and message in done.stderr, done.stderr
        assert len(done.stderr.strip().splitlines()) == 1
