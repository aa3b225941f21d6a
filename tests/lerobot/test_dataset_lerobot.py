"""LeRobot's own dataset reader loads what lynxplan writes, and lynxplan reads what LeRobot writes.

LeRobot's reader (``LeRobotDataset``) imports torch and torchvision: on Python 3.11 the
``lerobot-dataset`` 0.4.4 package (the reader without the rest of LeRobot; import name
``ledataset``) plus ``torch==2.14.1 torchvision==0.29.1`` took 2 min 39 s and 6.3 GB of venv on the
2-core CI machine, too heavy for CI (``lerobot`` 0.4.4 itself pins torch < 2.11: a download of
torch 2.10 with CUDA 12 libraries). This test runs that reader in its own interpreter, named by
``LYNXPLAN_LEROBOT_PYTHON``, and is skipped (with this reason) when none is named::

    python3 -m venv /work/lerobot-venv
    /work/lerobot-venv/bin/pip install lerobot-dataset==0.4.4 torch==2.14.1 torchvision==0.29.1
    export LYNXPLAN_LEROBOT_PYTHON=/work/lerobot-venv/bin/python
    pytest tests/lerobot/test_dataset_lerobot.py

(with ``lerobot`` itself installed instead, the script imports ``lerobot.datasets``).
Without it, tests/lerobot/test_dataset.py checks the same files against the v3.0 layout.
"""

from __future__ import annotations

import json
import os
import subprocess
import textwrap
from pathlib import Path

import numpy as np
import pytest

from lynxplan.lerobot import lerobot_units, read_episode, servo_frames, write_dataset
from tests.lerobot.sample import SAMPLE_CALIBRATION

pytest.importorskip("pyarrow", reason="the [lerobot] extra (pyarrow) is needed")

LEROBOT_PYTHON = os.environ.get("LYNXPLAN_LEROBOT_PYTHON")
pytestmark = pytest.mark.skipif(
    not LEROBOT_PYTHON or not Path(LEROBOT_PYTHON).is_file(),
    reason="LeRobot's dataset reader needs torch (6.3 GB, not in CI): set LYNXPLAN_LEROBOT_PYTHON "
    "to a Python with lerobot-dataset 0.4.4 (see this module's docstring)",
)

SCRIPT = textwrap.dedent(
    """
    import importlib.metadata as md, json, sys
    import numpy as np
    try:
        from ledataset.datasets.lerobot_dataset import LeRobotDataset
        version = "lerobot-dataset " + md.version("lerobot-dataset")
    except ImportError:
        from lerobot.datasets.lerobot_dataset import LeRobotDataset
        version = "lerobot " + md.version("lerobot")
    ours, theirs = sys.argv[1], sys.argv[2]
    ds = LeRobotDataset("local/ours", root=ours)
    items = [ds[i] for i in range(len(ds))]
    out = {
        "version": version, "fps": ds.fps, "episodes": ds.num_episodes, "frames": ds.num_frames,
        "robot_type": ds.meta.robot_type, "names": ds.features["action"]["names"],
        "action": [item["action"].tolist() for item in items],
        "state": [item["observation.state"].tolist() for item in items],
        "episode_index": [int(item["episode_index"]) for item in items],
        "timestamp": [float(item["timestamp"]) for item in items],
        "task": [item["task"] for item in items],
    }
    names = out["names"]
    features = {k: {"dtype": "float32", "shape": (6,), "names": names}
                for k in ("action", "observation.state")}
    made = LeRobotDataset.create("local/theirs", fps=30, features=features, root=theirs,
                                 robot_type="so101_follower", use_videos=False)
    for k in range(7):
        v = np.array([k, -k, 2 * k, 10, -10, 50], dtype=np.float32)
        made.add_frame({"action": v, "observation.state": v + 1, "task": "recorded"})
    made.save_episode()
    made.finalize()
    print(json.dumps(out))
    """
)


def test_lerobots_reader_loads_lynxplans_dataset(tmp_path, so101_calibrated):
    robot = so101_calibrated
    units = lerobot_units(robot, SAMPLE_CALIBRATION)
    q = robot.random_configurations(3, seed=11) * 0.5
    first = servo_frames(robot, units, [0.0, 1.0, 2.0], q, gripper=[0, 80, 10], fps=30)
    second = servo_frames(robot, units, [0.0, 1.5], q[:2][::-1], gripper=40.0, fps=30)
    ours = write_dataset(tmp_path / "ours", [first, second], tasks=["draw", "return"])
    done = subprocess.run(
        [LEROBOT_PYTHON, "-c", SCRIPT, str(ours), str(tmp_path / "theirs")],
        capture_output=True,
        text=True,
        timeout=600,
        env={**os.environ, "HF_HUB_OFFLINE": "1", "HF_LEROBOT_HOME": str(tmp_path / "home")},
    )
    assert done.returncode == 0, done.stderr[-3000:]
    loaded = json.loads(done.stdout.strip().splitlines()[-1])
    k1, k2 = len(first.t), len(second.t)
    assert (loaded["fps"], loaded["episodes"], loaded["frames"]) == (30, 2, k1 + k2)
    assert loaded["robot_type"] == "so101_follower" and loaded["names"][-1] == "gripper.pos"
    expected = np.vstack([np.column_stack((f.values, f.gripper)) for f in (first, second)])
    np.testing.assert_allclose(loaded["action"], expected, atol=1e-4)  # float32
    np.testing.assert_allclose(loaded["state"][1:k1], expected[: k1 - 1], atol=1e-4)
    assert loaded["episode_index"] == [0] * k1 + [1] * k2
    assert loaded["task"] == ["draw"] * k1 + ["return"] * k2
    np.testing.assert_allclose(loaded["timestamp"][k1:], second.t, atol=1e-6)
    # ... and lynxplan reads the episode LeRobot's own writer recorded
    theirs = read_episode(tmp_path / "theirs", 0)
    assert theirs.fps == 30 and theirs.robot_type == "so101_follower"
    ramp = np.arange(7.0)
    np.testing.assert_array_equal(
        theirs.values, np.column_stack((ramp, -ramp, 2 * ramp, [10] * 7, [-10] * 7, [50] * 7)) + 1
    )
    np.testing.assert_allclose(theirs.t, ramp / 30, atol=1e-6)
    print(f"LeRobot reader: {loaded['version']}")
