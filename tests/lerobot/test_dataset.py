"""LeRobot datasets written by lynxplan: LeRobot's v3.0 files read back with pyarrow and pandas
(what LeRobot's reader reads: tests/lerobot/test_dataset_lerobot.py loads them with LeRobot
itself), the episode round trip, and the folder rules (no file lynxplan did not write replaced)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from lynxplan.exceptions import InputError
from lynxplan.lerobot import lerobot_units, read_episode, servo_frames, write_dataset
from tests.lerobot.sample import SAMPLE_CALIBRATION

pq = pytest.importorskip("pyarrow.parquet", reason="the [lerobot] extra (pyarrow) is needed")
pd = pytest.importorskip("pandas", reason="the [lerobot] extra (pandas) is needed")

NAMES = [
    "shoulder_pan.pos",
    "shoulder_lift.pos",
    "elbow_flex.pos",
    "wrist_flex.pos",
    "wrist_roll.pos",
    "gripper.pos",
]


@pytest.fixture(scope="module")
def episodes(so101_calibrated):
    robot = so101_calibrated
    units = lerobot_units(robot, SAMPLE_CALIBRATION)
    q = robot.random_configurations(4, seed=3) * 0.6
    first = servo_frames(robot, units, np.arange(4.0), q, gripper=[0, 60, 100, 20], fps=30)
    second = servo_frames(robot, units, np.arange(4.0), q[::-1], gripper=35.0, fps=30)
    return first, second


def test_the_files_are_lerobots_v3_layout(tmp_path, episodes):
    first, second = episodes
    root = write_dataset(tmp_path / "ds", [first, second], tasks=["write O", "write K"])
    info = json.loads((root / "meta/info.json").read_text())
    k1, k2 = len(first.t), len(second.t)
    assert info["codebase_version"] == "v3.0" and info["fps"] == 30
    assert (info["total_episodes"], info["total_frames"], info["total_tasks"]) == (2, k1 + k2, 2)
    assert info["robot_type"] == "so101_follower" and info["splits"] == {"train": "0:2"}
    assert info["features"]["action"] == {"dtype": "float32", "shape": [6], "names": NAMES}
    assert info["features"]["observation.state"]["names"] == NAMES
    assert info["features"]["index"] == {"dtype": "int64", "shape": [1], "names": None}
    data = pq.read_table(root / "data/chunk-000/file-000.parquet")
    assert (
        str(data.schema.field("action").type) == "fixed_size_list<element: float>[6]"
    )  # as LeRobot writes
    rows = data.to_pydict()
    action = np.array(rows["action"])
    expected = np.vstack([np.column_stack((f.values, f.gripper)) for f in (first, second)]).astype(
        np.float32
    )
    np.testing.assert_array_equal(action, expected)
    # observation.state: the previous frame's goal (an arm that reached every goal)
    state = np.array(rows["observation.state"])
    np.testing.assert_array_equal(state[1:k1], action[: k1 - 1])
    np.testing.assert_array_equal(state[[0, k1]], action[[0, k1]])
    assert rows["index"] == list(range(k1 + k2))
    assert rows["episode_index"] == [0] * k1 + [1] * k2
    assert rows["frame_index"] == list(range(k1)) + list(range(k2))
    assert rows["task_index"] == [0] * k1 + [1] * k2
    np.testing.assert_allclose(rows["timestamp"][k1 + 3], 3 / 30, rtol=1e-7)
    # LeRobot's reader: meta/episodes (frame ranges), tasks as a pandas index, stats
    episodes_meta = pq.read_table(root / "meta/episodes/chunk-000/file-000.parquet").to_pydict()
    assert episodes_meta["dataset_from_index"] == [0, k1]
    assert episodes_meta["dataset_to_index"] == [k1, k1 + k2]
    assert episodes_meta["tasks"] == [["write O"], ["write K"]]
    assert episodes_meta["data/file_index"] == [0, 0]
    tasks = pd.read_parquet(root / "meta/tasks.parquet")
    assert list(tasks.index) == ["write O", "write K"]
    assert int(tasks.loc["write K"].task_index) == 1
    stats = json.loads((root / "meta/stats.json").read_text())
    np.testing.assert_allclose(stats["action"]["max"], action.max(axis=0), rtol=1e-12)
    np.testing.assert_allclose(stats["action"]["mean"], action.astype(float).mean(axis=0))
    assert stats["action"]["count"] == [k1 + k2]


def test_episodes_read_back(tmp_path, episodes):
    first, second = episodes
    root = write_dataset(tmp_path / "ds", [first, second])
    back = read_episode(root, 1, "action")
    assert back.names == tuple(NAMES) and back.fps == 30.0
    np.testing.assert_allclose(back.values[:, :5], second.values, atol=1e-4)  # float32
    np.testing.assert_allclose(back.values[:, 5], second.gripper, atol=1e-5)
    np.testing.assert_allclose(back.t, second.t, atol=1e-6)
    q = first.units.to_joints(back.frames()).q
    np.testing.assert_allclose(q, second.q, atol=1e-6)  # float32 of degrees: ~1e-6 rad
    state = read_episode(root, 0)
    np.testing.assert_allclose(state.values[1:, :5], first.values[:-1], atol=1e-4)


def test_folder_rules(tmp_path, episodes):
    first, _ = episodes
    root = write_dataset(tmp_path / "ds", first)
    with pytest.raises(InputError, match="exists; pass overwrite=True"):
        write_dataset(root, first)
    write_dataset(root, first, overwrite=True)  # lynxplan's own dataset: replaced
    assert read_episode(root).values.shape == (len(first.t), 6)
    foreign = root / "videos" / "notes.txt"
    foreign.parent.mkdir()
    foreign.write_text("mine")
    with pytest.raises(InputError, match=r"did not write \(videos/notes.txt\)"):
        write_dataset(root, first, overwrite=True)
    assert foreign.read_text() == "mine" and (root / "meta/info.json").is_file()
    other = tmp_path / "someone_elses"
    other.mkdir()
    with pytest.raises(InputError, match="was not written by lynxplan"):
        write_dataset(other, first, overwrite=True)
    assert not any(p.name.startswith(".ds") for p in tmp_path.iterdir())  # no staging left


def test_bad_inputs(tmp_path, episodes, so101_calibrated):
    first, _ = episodes
    units = lerobot_units(so101_calibrated, SAMPLE_CALIBRATION)
    q = np.zeros((2, 5))
    odd = servo_frames(so101_calibrated, units, [0.0, 1.0], q, fps=29.97)
    with pytest.raises(InputError, match=r"fps = 29.97: .* whole number"):
        write_dataset(tmp_path / "a", odd)
    with pytest.raises(InputError, match="not a LeRobot dataset"):
        read_episode(tmp_path)
    root = write_dataset(tmp_path / "b", first)
    with pytest.raises(InputError, match=r"episode = 3: .* episodes 0..0"):
        read_episode(root, 3)
    with pytest.raises(InputError, match=r"no feature 'observation\.images\.top'"):
        read_episode(root, 0, "observation.images.top")
