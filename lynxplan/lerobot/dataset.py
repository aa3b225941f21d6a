"""LeRobot datasets: servo-safe frames written as one, and a recorded episode read back.

The on-disk format is LeRobot's dataset format v3.0 (``codebase_version: v3.0``, lerobot 0.4.x;
checked against ``LeRobotDataset`` of the ``lerobot-dataset`` 0.4.4 package, which loads what
:func:`write_dataset` writes)::

    meta/info.json                           fps, features (dtype, shape, names), totals, paths
    meta/stats.json                          min/max/mean/std/count/q01..q99 per feature
    meta/tasks.parquet                       the task strings (pandas index) and task_index
    meta/episodes/chunk-000/file-000.parquet one row per episode: length, data file, frame range,
                                             its stats
    data/chunk-000/file-000.parquet          one row per frame: action, observation.state,
                                             timestamp, frame_index, episode_index, index,
                                             task_index

``action`` holds each frame's goal positions (LeRobot units, the keys of
:attr:`ServoFrames.keys <lynxplan.lerobot.export.ServoFrames.keys>` as ``names``).
``observation.state`` of a written (planned, not recorded) frame is the previous frame's action
(the first frame's own): what an arm that reached every goal would have read before the frame was
sent. :func:`read_episode` also reads the older v2.x layout (one parquet file per episode).

Writing needs ``pyarrow`` and ``pandas`` (``pip install 'lynxplan[lerobot]'``), reading
``pyarrow``; LeRobot itself (and torch) is not needed. A folder lynxplan wrote holds
``lynxplan.json`` (the files it wrote); it is replaced only with ``overwrite=True`` and only when
it holds nothing else.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from lynxplan.exceptions import InputError
from lynxplan.lerobot.export import ServoFrames

#: The format version written (LeRobot's ``CODEBASE_VERSION`` of lerobot 0.4.x).
CODEBASE_VERSION = "v3.0"
#: The file lynxplan leaves in a dataset folder it wrote (the list of its files).
MARKER = "lynxplan.json"
#: LeRobot's defaults kept in info.json (files per chunk, MB per data / video file).
CHUNKS_SIZE, DATA_FILES_SIZE_IN_MB, VIDEO_FILES_SIZE_IN_MB = 1000, 100, 200
DATA_PATH = "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet"
EPISODES_PATH = "meta/episodes/chunk-000/file-000.parquet"
#: Quantiles LeRobot keeps in its stats (its ``QUANTILES`` normalisation).
QUANTILES = (0.01, 0.10, 0.50, 0.90, 0.99)
_INDEX_FEATURES = ("timestamp", "frame_index", "episode_index", "index", "task_index")
#: The two vector features of a frame.
ACTION, STATE = "action", "observation.state"


class RecordedEpisode(NamedTuple):
    """One episode of a LeRobot dataset: a vector feature over its frames."""

    t: np.ndarray
    """Frame times from the episode's start, shape (K,), in [s] (the ``timestamp`` column)."""
    values: np.ndarray
    """The feature's values, shape (K, m), in LeRobot units."""
    names: tuple[str, ...]
    """The m value names, e.g. ``("shoulder_pan.pos", ..., "gripper.pos")``."""
    fps: float
    """The dataset's frame rate, in [frames/s]."""
    robot_type: str | None
    """The dataset's ``robot_type`` (``so101_follower``), if given."""

    def frames(self) -> dict[str, np.ndarray]:
        """Name -> column, shape (K,): the form :meth:`LeRobotUnits.to_joints` takes."""
        return {name: self.values[:, i] for i, name in enumerate(self.names)}


def _modules() -> tuple[Any, Any, Any]:
    try:
        import pandas as pd
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError as exc:
        raise InputError(
            f"LeRobot datasets need pyarrow and pandas ({exc}); pip install 'lynxplan[lerobot]'"
        ) from None
    return pa, pq, pd


def _stats(array: np.ndarray) -> dict[str, np.ndarray]:
    """LeRobot's per-feature statistics of (K, m) values (its keys; quantiles exact)."""
    values = np.asarray(array, dtype=float)
    stats = {
        "min": values.min(axis=0),
        "max": values.max(axis=0),
        "mean": values.mean(axis=0),
        "std": values.std(axis=0),
        "count": np.array([len(values)]),
    }
    for q in QUANTILES:
        stats[f"q{round(q * 100):02d}"] = np.quantile(values, q, axis=0)
    return stats


def _columns(episodes: Sequence[ServoFrames], task_count: int) -> dict[str, np.ndarray]:
    """Every frame of every episode as LeRobot's columns (episode after episode)."""
    actions, states, times, frame_index, episode_index, task_index = [], [], [], [], [], []
    for e, frames in enumerate(episodes):
        grip = frames.gripper
        action = frames.values if np.isnan(grip).all() else np.column_stack((frames.values, grip))
        actions.append(action)
        states.append(np.vstack((action[:1], action[:-1])))
        times.append(np.arange(len(action)) / frames.fps)
        frame_index.append(np.arange(len(action)))
        episode_index.append(np.full(len(action), e))
        task_index.append(np.full(len(action), min(e, task_count - 1)))
    count = sum(len(a) for a in actions)
    return {
        ACTION: np.vstack(actions).astype(np.float32),
        STATE: np.vstack(states).astype(np.float32),
        "timestamp": np.concatenate(times).astype(np.float32),
        "frame_index": np.concatenate(frame_index).astype(np.int64),
        "episode_index": np.concatenate(episode_index).astype(np.int64),
        "index": np.arange(count, dtype=np.int64),
        "task_index": np.concatenate(task_index).astype(np.int64),
    }


def _features(names: Sequence[str]) -> dict[str, Any]:
    vector = {"dtype": "float32", "shape": [len(names)], "names": list(names)}
    scalar = {"shape": [1], "names": None}
    features: dict[str, Any] = {ACTION: dict(vector), STATE: dict(vector)}
    features["timestamp"] = {"dtype": "float32", **scalar}
    features.update({key: {"dtype": "int64", **scalar} for key in _INDEX_FEATURES[1:]})
    return features


def _check_episodes(episodes: Sequence[ServoFrames]) -> tuple[int, tuple[str, ...]]:
    if not episodes:
        raise InputError("write_dataset: no episodes")
    fps = {float(frames.fps) for frames in episodes}
    keys = {frames.keys for frames in episodes}
    if len(fps) != 1 or len(keys) != 1:
        raise InputError("write_dataset: every episode must have the same fps and action keys")
    rate = fps.pop()
    if rate != round(rate) or rate < 1:
        raise InputError(f"fps = {rate:g}: a LeRobot dataset's fps is a whole number >= 1")
    return round(rate), keys.pop()


def _write_tables(
    folder: Path, columns: dict[str, np.ndarray], lengths: list[int], tasks: list[str]
) -> None:
    pa, pq, pd = _modules()
    names = list(columns)
    arrays = []
    for key in names:
        data = columns[key]
        if data.ndim == 2:
            flat = pa.array(data.ravel(), type=pa.float32())
            arrays.append(pa.FixedSizeListArray.from_arrays(flat, data.shape[1]))
        else:
            arrays.append(pa.array(data))
    data_file = folder / DATA_PATH.format(chunk_index=0, file_index=0)
    data_file.parent.mkdir(parents=True)
    pq.write_table(pa.Table.from_arrays(arrays, names=names), data_file, compression="snappy")
    rows: dict[str, list[Any]] = {
        "episode_index": [],
        "tasks": [],
        "length": [],
        "data/chunk_index": [],
        "data/file_index": [],
        "dataset_from_index": [],
        "dataset_to_index": [],
    }
    start = 0
    for e, length in enumerate(lengths):
        part = {key: value[start : start + length] for key, value in columns.items()}
        rows["episode_index"].append(e)
        rows["tasks"].append([tasks[min(e, len(tasks) - 1)]])
        rows["length"].append(length)
        rows["data/chunk_index"].append(0)
        rows["data/file_index"].append(0)
        rows["dataset_from_index"].append(start)
        rows["dataset_to_index"].append(start + length)
        for key, value in part.items():
            matrix = value if value.ndim == 2 else value[:, None]
            for stat, numbers in _stats(matrix).items():
                rows.setdefault(f"stats/{key}/{stat}", []).append(numbers.tolist())
        start += length
    rows["meta/episodes/chunk_index"] = [0] * len(lengths)
    rows["meta/episodes/file_index"] = [0] * len(lengths)
    (folder / EPISODES_PATH).parent.mkdir(parents=True)
    pq.write_table(pa.Table.from_pydict(rows), folder / EPISODES_PATH)
    pd.DataFrame({"task_index": range(len(tasks))}, index=tasks).to_parquet(
        folder / "meta" / "tasks.parquet"
    )


def _replaceable(target: Path) -> list[Path]:
    """The files of a dataset folder lynxplan wrote, or an InputError saying why not."""
    marker = target / MARKER
    if not marker.is_file():
        raise InputError(f"{target} exists and was not written by lynxplan; choose another folder")
    try:
        listed = {str(p) for p in json.loads(marker.read_text(encoding="utf-8"))["files"]}
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise InputError(f"{marker}: unreadable ({exc}); choose another folder") from None
    present = {str(p.relative_to(target)) for p in target.rglob("*") if p.is_file()}
    foreign = sorted(present - listed - {MARKER})
    if foreign:
        raise InputError(
            f"{target} holds files lynxplan did not write ({foreign[0]}"
            f"{f' and {len(foreign) - 1} more' if len(foreign) > 1 else ''}); "
            "choose another folder"
        )
    return [target / name for name in sorted(present)]


def write_dataset(
    root: str | Path,
    episodes: ServoFrames | Sequence[ServoFrames],
    *,
    tasks: str | Sequence[str] = "lynxplan trajectory",
    robot_type: str = "so101_follower",
    provenance: dict[str, Any] | None = None,
    overwrite: bool = False,
) -> Path:
    """Write frames as a LeRobot dataset (format v3.0, module docstring) in the folder ``root``.

    Args:
        root: The dataset folder (created; its parent must exist).
        episodes: One :class:`~lynxplan.lerobot.export.ServoFrames` per episode (same fps,
            a whole number, and same keys).
        tasks: The task text of each episode (one text: every episode's).
        robot_type: info.json's ``robot_type`` (LeRobot's follower type).
        provenance: Extra facts kept in ``lynxplan.json`` (units, calibration, source).
        overwrite: Replace a dataset lynxplan wrote there before.

    Raises:
        InputError: ``root`` exists (and ``overwrite`` is False, or it holds files lynxplan did
            not write), its parent is not a folder, fps not whole, pyarrow/pandas missing.
    """
    items = [episodes] if isinstance(episodes, ServoFrames) else list(episodes)
    fps, keys = _check_episodes(items)
    texts = [tasks] if isinstance(tasks, str) else [str(t) for t in tasks]
    if not texts or len(texts) not in (1, len(items)) or len(set(texts)) != len(texts):
        raise InputError("tasks: one text, or one distinct text per episode")
    target = Path(root)
    if not target.parent.is_dir():
        raise InputError(f"{target.parent} is not a folder")
    old: list[Path] = []
    if target.exists():
        if not overwrite:
            raise InputError(f"{target} exists; pass overwrite=True (--overwrite) to replace it")
        old = _replaceable(target)
    _modules()
    lengths = [len(frames.t) for frames in items]
    columns = _columns(items, len(texts))
    staging = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    try:
        _write_tables(staging, columns, lengths, texts)
        meta = staging / "meta"
        stats = {
            k: {s: v.tolist() for s, v in _stats(_matrix(c)).items()} for k, c in columns.items()
        }
        (meta / "stats.json").write_text(json.dumps(stats, indent=4), encoding="utf-8")
        info = {
            "codebase_version": CODEBASE_VERSION,
            "robot_type": robot_type,
            "total_episodes": len(items),
            "total_frames": sum(lengths),
            "total_tasks": len(texts),
            "chunks_size": CHUNKS_SIZE,
            "data_files_size_in_mb": DATA_FILES_SIZE_IN_MB,
            "video_files_size_in_mb": VIDEO_FILES_SIZE_IN_MB,
            "fps": fps,
            "splits": {"train": f"0:{len(items)}"},
            "data_path": DATA_PATH,
            "video_path": None,
            "features": _features(keys),
        }
        (meta / "info.json").write_text(json.dumps(info, indent=4), encoding="utf-8")
        files = sorted(str(p.relative_to(staging)) for p in staging.rglob("*") if p.is_file())
        marker = {"written_by": "lynxplan", "files": files, **(provenance or {})}
        (staging / MARKER).write_text(json.dumps(marker, indent=2), encoding="utf-8")
        for path in old:  # only files lynxplan wrote there (checked above)
            path.unlink()
        if old:
            for folder in sorted((p for p in target.rglob("*") if p.is_dir()), reverse=True):
                folder.rmdir()
            target.rmdir()
        os.replace(staging, target)
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return target


def _matrix(values: np.ndarray) -> np.ndarray:
    return values if values.ndim == 2 else values[:, None]


def _names(source: Path, key: str, feature: Any) -> tuple[str, ...]:
    names = feature.get("names") if isinstance(feature, dict) else None
    if isinstance(names, dict) and len(names) == 1:  # v2.0: {"motors": [...]}
        names = next(iter(names.values()))
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise InputError(f"{source}: features.{key}.names must be a list of value names")
    return tuple(names)


def _info(source: Path) -> dict[str, Any]:
    path = source / "meta" / "info.json"
    if not path.is_file():
        raise InputError(f"{source}: not a LeRobot dataset (no meta/info.json)")
    try:
        info = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise InputError(f"{path}: not readable JSON ({exc})") from None
    if not isinstance(info, dict) or not isinstance(info.get("features"), dict):
        raise InputError(f"{path}: no features")
    return info


def _episode_files(source: Path, info: dict[str, Any], episode: int) -> list[Path]:
    """The data files holding the frames of ``episode`` (v3.0: from meta/episodes; v2.x: the
    per-episode file of ``data_path``)."""
    _, pq, _ = _modules()
    data_path = str(info.get("data_path", DATA_PATH))
    if "{episode_index" in data_path:  # v2.x
        chunk = episode // int(info.get("chunks_size", CHUNKS_SIZE))
        return [source / data_path.format(episode_chunk=chunk, episode_index=episode)]
    rows = [
        row
        for path in sorted((source / "meta" / "episodes").glob("*/*.parquet"))
        for row in pq.read_table(
            path, columns=["episode_index", "data/chunk_index", "data/file_index"]
        ).to_pylist()
        if row["episode_index"] == episode
    ]
    return [
        source
        / data_path.format(chunk_index=r["data/chunk_index"], file_index=r["data/file_index"])
        for r in rows
    ]


def read_episode(root: str | Path, episode: int = 0, key: str = STATE) -> RecordedEpisode:
    """One episode's ``key`` feature (``observation.state``: the recorded joint positions;
    ``action``: the goals sent) of a LeRobot dataset folder (format v3.0 or v2.x).

    Raises:
        InputError: no dataset there, no such episode or feature, unreadable files.
    """
    source = Path(root)
    info = _info(source)
    features = info["features"]
    if key not in features:
        raise InputError(f"{source}: no feature {key!r}; features: {', '.join(features)}")
    names = _names(source, key, features[key])
    total = int(info.get("total_episodes", 0))
    if not 0 <= episode < total:
        raise InputError(f"episode = {episode}: {source} has episodes 0..{total - 1}")
    _, pq, _ = _modules()
    files = [path for path in _episode_files(source, info, episode) if path.is_file()]
    if not files:
        raise InputError(f"{source}: the data file of episode {episode} is missing")
    try:
        tables = [
            pq.read_table(path, columns=[key, "timestamp", "episode_index", "frame_index"])
            for path in files
        ]
    except Exception as exc:  # pyarrow's errors: a damaged or foreign file
        raise InputError(f"{files[0]}: not readable as LeRobot data ({exc})") from None
    rows = [r for table in tables for r in table.to_pylist() if r["episode_index"] == episode]
    rows.sort(key=lambda r: r["frame_index"])
    if not rows:
        raise InputError(f"{source}: episode {episode} has no frames")
    values = np.array([r[key] for r in rows], dtype=float).reshape(len(rows), -1)
    if values.shape[1] != len(names):
        raise InputError(f"{source}: {key} has {values.shape[1]} values, names {len(names)}")
    t = np.array([r["timestamp"] for r in rows], dtype=float)
    fps = float(info.get("fps", math.nan))
    return RecordedEpisode(t - t[0], values, names, fps, info.get("robot_type"))
