"""``meta/info.json``, and what a writer learns from an existing dataset before appending."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

from dial.dataset import files, tables
from dial.dataset.features import FeatureJSON
from dial.dataset.stats import FeatureStats, from_json
from dial.dataset.tables import DatasetError

CODEBASE_VERSION = "v3.0"
VIDEO_FILE_MB = 200  # LeRobot's default; dial writes one video file per episode and camera


@dataclass(frozen=True)
class Existing:
    """A dataset folder as found: empty (no features), or a dataset to append to."""

    features: dict[str, FeatureJSON] | None = None
    episodes: int = 0
    frames: int = 0
    tasks: tuple[str, ...] = ()
    stats: FeatureStats | None = None
    file_mb: float | None = None
    chunks_size: int | None = None
    robot_type: str | None = None


def read_existing(root: Path, fps: int) -> Existing:
    """What ``root`` holds; a :class:`DatasetError` if it cannot be appended to at ``fps``."""
    info_path = root / files.INFO
    if not info_path.exists():
        others = [
            p.name for p in root.iterdir() if p.name != files.LOCK and not p.name.endswith(".tmp")
        ]
        if others:
            raise DatasetError(
                f"cannot write the dataset: '{root}' holds other files and no LeRobot "
                f"dataset (no {files.INFO}): give an empty or a new folder"
            )
        return Existing()
    try:
        info = files.read_json(info_path)
        version, have_fps = info.get("codebase_version"), info.get("fps")
        features = info["features"]
        episodes, frames = int(info["total_episodes"]), int(info["total_frames"])  # type: ignore[call-overload]
        stats_path = root / files.STATS
        stats = from_json(files.read_json(stats_path)) if stats_path.exists() else None  # type: ignore[arg-type]
        tasks = _read_tasks(root) if (root / files.TASKS).exists() else ()
    except (OSError, ValueError, KeyError, TypeError) as e:
        raise DatasetError(
            f"cannot append to '{root}': its metadata cannot be read ({e})"
        ) from None
    if version != CODEBASE_VERSION:
        raise DatasetError(
            f"cannot append to '{root}': it is a LeRobot {version} dataset, dial writes "
            f"{CODEBASE_VERSION}"
        )
    if have_fps != fps:
        raise DatasetError(
            f"cannot append to '{root}': it is at {have_fps} fps, not {fps} (give --fps {have_fps})"
        )
    if not isinstance(features, dict):
        raise DatasetError(f"cannot append to '{root}': {files.INFO} has no features")
    size = info.get("data_files_size_in_mb")
    chunks = info.get("chunks_size")
    robot = info.get("robot_type")
    return Existing(
        features,
        episodes,
        frames,
        tasks,
        stats,
        float(size) if isinstance(size, int | float) else None,
        int(chunks) if isinstance(chunks, int) else None,
        robot if isinstance(robot, str) else None,
    )


def _read_tasks(root: Path) -> tuple[str, ...]:
    table = tables.pa.parquet.read_table(str(root / files.TASKS), columns=["task_index", "task"])
    pairs = sorted(
        zip(table.column("task_index").to_pylist(), table.column("task").to_pylist(), strict=True)
    )
    return tuple(str(task) for _, task in pairs)


@dataclass(frozen=True)
class Totals:
    """What info.json says of a dataset beside its features (a writer's state)."""

    fps: int
    episodes: int
    frames: int
    tasks: int
    chunks_size: int
    file_bytes: int
    robot_type: str


def info_json(features: dict[str, FeatureJSON] | None, totals: Totals) -> dict[str, object]:
    """info.json, in LeRobot's key order."""
    features = features or {}
    videos = [name for name, f in features.items() if f["dtype"] == "video"]
    return {
        "codebase_version": CODEBASE_VERSION,
        "fps": totals.fps,
        "features": features,
        "total_episodes": totals.episodes,
        "total_frames": totals.frames,
        "total_tasks": totals.tasks,
        "chunks_size": totals.chunks_size,
        "data_files_size_in_mb": max(1, math.ceil(totals.file_bytes / 2**20)),
        "video_files_size_in_mb": VIDEO_FILE_MB,
        "data_path": files.DATA_PATH,
        "video_path": files.VIDEO_PATH if videos else None,
        "robot_type": totals.robot_type,
        "splits": {"train": f"0:{totals.episodes}"},
    }
