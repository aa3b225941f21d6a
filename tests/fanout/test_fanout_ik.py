"""IK batches on a Dask LocalCluster: the same arrays as one serial ``Robot.ik_batch``; the
``lynxplan ik --poses FILE.npy --out FILE.npz`` batch interface, serial and fanned out."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from lynxplan.exceptions import InputError
from lynxplan.fanout import Cluster
from lynxplan.fanout.ik import ik_batch_on_dask
from lynxplan.robots import load_robot

LYNXPLAN = str(Path(sys.executable).with_name("lynxplan"))


def _poses(name: str, n: int, seed: int = 0) -> np.ndarray:
    """Tool poses of random configurations, plus a few unreachable ones (moved 1 m up)."""
    robot = load_robot(name)
    rng = np.random.default_rng(seed)
    poses = np.array(robot.fk(rng.uniform(robot.limits.lower, robot.limits.upper, (n, robot.nq))))
    poses[::50, 2, 3] += 1.0
    return poses


def _assert_same(a: object, b: object) -> None:
    for field in a._fields:  # type: ignore[attr-defined]
        x, y = np.asarray(getattr(a, field)), np.asarray(getattr(b, field))
        assert x.dtype == y.dtype and x.shape == y.shape, field
        assert x.tobytes() == y.tobytes(), field  # bit for bit, NaN slots included


@pytest.mark.parametrize("name", ["al5", "so101", "ur5"])
def test_chunks_on_dask_equal_one_serial_batch(name: str, dask_cluster: Cluster) -> None:
    robot, poses = load_robot(name), _poses(name, 1_000)
    serial = robot.ik_batch(poses)  # first: the workers then load its kernels from the cache
    seen: list[int] = []
    fanned = ik_batch_on_dask(robot, poses, cluster=dask_cluster, chunk=300,
                              progress=lambda d, n: seen.append(d))  # fmt: skip
    _assert_same(fanned, serial)
    assert seen[-1] == 1000 and len(seen) == 4
    assert not fanned.q.flags.writeable


def test_bad_chunk_is_refused(dask_cluster: Cluster) -> None:
    with pytest.raises(InputError, match=r"chunk must be at least 1\. Got: 0"):
        ik_batch_on_dask(load_robot("al5"), _poses("al5", 3), cluster=dask_cluster, chunk=0)


def _ik(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([LYNXPLAN, "ik", *args], capture_output=True, text=True, timeout=600,
                          check=False)  # fmt: skip


def test_cli_batch_serial_and_dask_write_the_same_answers(tmp_path: Path) -> None:
    robot = load_robot("so101")
    poses = _poses("so101", 500, seed=1)
    np.save(tmp_path / "poses.npy", poses)
    serial = _ik("--robot", "so101", "--poses", str(tmp_path / "poses.npy"),
                 "--out", str(tmp_path / "serial.npz"))  # fmt: skip
    fanned = _ik("--robot", "so101", "--poses", str(tmp_path / "poses.npy"),
                 "--out", str(tmp_path / "dask.npz"), "--dask-local", "2")  # fmt: skip
    assert serial.returncode == fanned.returncode == 0, fanned.stderr
    assert "500 poses, 490 reachable" in fanned.stdout
    direct = robot.ik_batch(poses)
    with np.load(tmp_path / "serial.npz") as a, np.load(tmp_path / "dask.npz") as b:
        for field in direct._fields:
            assert (
                a[field].tobytes()
                == b[field].tobytes()
                == np.asarray(getattr(direct, field)).tobytes()
            )


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (("--out", "a.npz", "--dask-local", "0"), "--dask-local needs at least 1 worker. Got: 0"),
        (("--out", "a.txt"), "ik --poses needs --out FILE.npz for the answers. Got: a.txt"),
        (("--out", "a.npz", "--deg"), "poses and answers are in m and rad"),
        (("--out", "a.npz", "--pose", "[[1]]"), "--pose is for one target; not with --poses"),
    ],
)
def test_cli_batch_bad_input_exits_2_in_one_line(
    tmp_path: Path, extra: tuple[str, ...], message: str
) -> None:
    np.save(tmp_path / "p.npy", np.eye(4)[None])
    done = _ik("--poses", str(tmp_path / "p.npy"), *extra)
    assert done.returncode == 2 and message in done.stderr, done.stderr
    assert len(done.stderr.strip().splitlines()) == 1


def test_cli_batch_bad_poses_file_exits_2(tmp_path: Path) -> None:
    np.save(tmp_path / "p.npy", np.zeros((3, 3, 3)))
    (tmp_path / "bad.npy").write_text("not numpy")
    for path, message in (
        (tmp_path / "p.npy", "(N, 4, 4)"),
        (tmp_path / "bad.npy", "not a readable .npy"),
    ):
        done = _ik("--poses", str(path), "--out", str(tmp_path / "a.npz"))
        assert done.returncode == 2 and message in done.stderr, done.stderr
    done = _ik("--pose", "[[1]]", "--dask-local", "2")
    assert done.returncode == 2 and "go with --poses FILE.npy" in done.stderr
