"""An independent check of a LeRobot v3.0 export with pyarrow alone.

LeRobot's own reader accepts a wrong ``total_frames`` (``len(ds)`` is that number),
timestamps off the fps grid and a declared feature missing from the parquet (returned as
None), so this checker, not the loader, has to catch them.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

INDEX = {
    "timestamp": "float32",
    "frame_index": "int64",
    "episode_index": "int64",
    "index": "int64",
    "task_index": "int64",
}
EPISODE_COLUMNS = (
    "episode_index",
    "tasks",
    "length",
    "data/chunk_index",
    "data/file_index",
    "dataset_from_index",
    "dataset_to_index",
    "meta/episodes/chunk_index",
    "meta/episodes/file_index",
)
STATS = ("min", "max", "mean", "std", "count", "q01", "q10", "q50", "q90", "q99")


def _shape(kind: pa.DataType) -> tuple[int, ...]:
    """The per-row shape an Arrow type holds (variable lists read as -1)."""
    if pa.types.is_fixed_size_list(kind):
        return (kind.list_size, *_shape(kind.value_type))
    if pa.types.is_list(kind):
        return (-1, *_shape(kind.value_type))
    return ()


def _rows_shape(column: pa.ChunkedArray) -> tuple[int, ...]:
    """The shape of every row of a column, checked to be the same for all."""
    values = column.to_pylist()
    shapes = {np.shape(v) for v in values}
    assert len(shapes) == 1, f"rows of {column.type} have shapes {shapes}"
    return shapes.pop()


def check(root: Path) -> dict[str, Any]:
    """Assert that ``root`` is a complete, consistent dataset; return what was read."""
    info = json.loads((root / "meta/info.json").read_text())
    assert info["codebase_version"] == "v3.0"
    fps = info["fps"]
    assert isinstance(fps, int) and fps > 0
    features = info["features"]
    for name, dtype in INDEX.items():
        assert features[name] == {"dtype": dtype, "shape": [1], "names": None}, name
    for name, feature in features.items():
        assert {"dtype", "shape", "names"} <= set(feature), name
        names = feature["names"]
        if names is not None and len(feature["shape"]) == 1:
            assert len(names) == feature["shape"][0], f"{name}: a name per dimension"
    data_features = {n: f for n, f in features.items() if f["dtype"] != "video"}

    data_files = sorted((root / "data").glob("*/*.parquet"))
    frames = pa.concat_tables([pq.read_table(p) for p in data_files]) if data_files else None
    assert frames is not None, "no data file"
    assert set(frames.column_names) == set(data_features), "every declared feature, no other"
    for name, feature in data_features.items():
        column = frames.column(name)
        want = tuple(feature["shape"])
        got = _rows_shape(column) if want != (1,) else (1,)
        assert got == want, f"{name}: rows of shape {got}, declared {want}"
        if want == (1,):
            assert not pa.types.is_list(column.type), name
            assert column.type == pa.from_numpy_dtype(np.dtype(feature["dtype"])), name
        else:
            assert _shape(column.type)[0] in (want[0], -1), name

    episodes = pa.concat_tables(
        [pq.read_table(p) for p in sorted((root / "meta/episodes").glob("*/*.parquet"))]
    ).to_pylist()
    tasks = pq.read_table(root / "meta/tasks.parquet")
    assert info["total_frames"] == frames.num_rows
    assert info["total_episodes"] == len(episodes)
    assert info["total_tasks"] == tasks.num_rows
    assert info["splits"] == {"train": f"0:{len(episodes)}"}

    frame_index = frames.column("frame_index").to_numpy()
    timestamp = frames.column("timestamp").to_numpy()
    assert timestamp.dtype == np.float32
    assert np.array_equal(timestamp, (frame_index / fps).astype(np.float32)), "off the fps grid"
    index = frames.column("index").to_numpy()
    assert np.array_equal(np.sort(index), np.arange(frames.num_rows))
    episode_of = frames.column("episode_index").to_numpy()
    task_of = frames.column("task_index").to_numpy()
    task_text = dict(
        zip(tasks.column("task_index").to_pylist(), tasks.column("task").to_pylist(), strict=True)
    )

    for k, ep in enumerate(episodes):
        assert ep["episode_index"] == k
        for column in EPISODE_COLUMNS:
            assert column in ep, column
        rows = np.flatnonzero(episode_of == k)
        assert len(rows) == ep["length"] == ep["dataset_to_index"] - ep["dataset_from_index"]
        assert np.array_equal(
            index[rows], np.arange(ep["dataset_from_index"], ep["dataset_to_index"])
        )
        assert np.array_equal(frame_index[rows], np.arange(ep["length"]))
        file = root / info["data_path"].format(
            chunk_index=ep["data/chunk_index"], file_index=ep["data/file_index"]
        )
        in_file = pq.read_table(file, columns=["episode_index"]).column(0).to_numpy()
        assert (in_file == k).sum() == ep["length"], f"episode {k} is in {file.name}"
        assert {task_text[t] for t in task_of[rows]} == set(ep["tasks"])
        for name in features:
            for stat in STATS:
                assert f"stats/{name}/{stat}" in ep, (name, stat)
        done = frames.column("next.done").to_numpy(zero_copy_only=False)[rows]
        assert done[-1] and not done[:-1].any(), "next.done on the last frame only"
        for key in (n for n, f in features.items() if f["dtype"] == "video"):
            video = root / info["video_path"].format(
                video_key=key,
                chunk_index=ep[f"videos/{key}/chunk_index"],
                file_index=ep[f"videos/{key}/file_index"],
            )
            assert video.is_file() and video.stat().st_size > 0, video

    stats = json.loads((root / "meta/stats.json").read_text())
    assert set(stats) == set(features)
    for name, feature in stats.items():
        assert set(feature) == set(STATS), name
        assert feature["count"] == [info["total_frames"]] or features[name]["dtype"] == "video"
    metadata = json.loads(tasks.schema.metadata[b"pandas"])
    assert metadata["index_columns"] == ["task"], "the task is the index: read back as text"
    assert all(isinstance(t, str) for t in tasks.column("task").to_pylist())
    leftovers = [p for p in root.rglob("*") if p.name.startswith(".")]
    assert leftovers == [], f"temporary or lock files left: {leftovers}"
    return {"info": info, "frames": frames, "episodes": episodes, "tasks": task_text}
