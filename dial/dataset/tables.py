"""The dataset's tables as Arrow tables: frames, episodes and tasks (pyarrow, imported here).

Column types are those LeRobot's reader casts to (``datasets`` features): a vector is a
``fixed_size_list<float>[n]``, an array of more axes nested lists, a (1,) feature a scalar.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from dial.dataset.features import INDEX_FEATURES, FeatureJSON, shape_of
from dial.errors import DialError

INSTALL = "pip install 'dial[dataset]'"

pa: Any = None  # pyarrow, once require() has imported it


class DatasetError(DialError):
    """A dataset that cannot be written: the message says why, in one line."""


def require() -> Any:
    """The ``pyarrow`` module, or a one-line :class:`DatasetError` naming the extra."""
    global pa
    if pa is None:
        try:
            import pyarrow
            import pyarrow.parquet
        except ImportError:
            raise DatasetError(f"--dataset needs pyarrow: {INSTALL}") from None
        pa = pyarrow
    return pa


def arrow_type(feature: FeatureJSON) -> Any:
    shape = shape_of(feature)
    value = pa.from_numpy_dtype(np.dtype(str(feature["dtype"])))
    if shape == (1,):
        return value
    if len(shape) == 1:
        return pa.list_(value, shape[0])
    for _ in shape:
        value = pa.list_(value)
    return value


def _column(values: NDArray[np.generic], feature: FeatureJSON) -> Any:
    kind = arrow_type(feature)
    shape = shape_of(feature)
    if shape == (1,):
        return pa.array(values.reshape(len(values)), type=kind)
    flat = pa.array(np.ascontiguousarray(values).reshape(-1))
    if len(shape) == 1:
        return pa.FixedSizeListArray.from_arrays(flat, shape[0])
    array = flat
    rows = int(np.prod(values.shape[:-1]))
    for axis in range(len(shape), 0, -1):  # innermost lists first
        size = values.shape[axis]
        offsets = pa.array(np.arange(0, rows * size + 1, size, dtype=np.int32))
        array = pa.ListArray.from_arrays(offsets, array)
        rows //= values.shape[axis - 1] if axis > 1 else 1
    return array


def data_schema(features: Mapping[str, FeatureJSON]) -> Any:
    return pa.schema(
        [pa.field(name, arrow_type(f)) for name, f in features.items() if f["dtype"] != "video"]
    )


def frames_table(
    features: Mapping[str, FeatureJSON],
    columns: Mapping[str, NDArray[np.generic]],
    fps: int,
    episode: int,
    first: int,
    task: int,
) -> Any:
    """An episode's frames: its columns, then the index columns (``timestamp`` is exactly
    ``frame_index / fps`` in float32; ``index`` counts frames over the whole dataset)."""
    n = len(next(iter(columns.values())))
    frame = np.arange(n, dtype=np.int64)
    index = {
        "timestamp": (frame / fps).astype(np.float32),
        "frame_index": frame,
        "episode_index": np.full(n, episode, dtype=np.int64),
        "index": frame + first,
        "task_index": np.full(n, task, dtype=np.int64),
    }
    arrays = [
        _column(columns[name], f) if name not in index else pa.array(index[name])
        for name, f in features.items()
        if f["dtype"] != "video"
    ]
    return pa.Table.from_arrays(arrays, schema=data_schema(features))


def episodes_schema(stats: Mapping[str, Mapping[str, NDArray[Any]]], videos: Sequence[str]) -> Any:
    """The episodes table: LeRobot's columns, each video's, the stats, then dial's own."""
    fields = [
        ("episode_index", pa.int64()),
        ("tasks", pa.list_(pa.string())),
        ("length", pa.int64()),
        ("data/chunk_index", pa.int64()),
        ("data/file_index", pa.int64()),
        ("dataset_from_index", pa.int64()),
        ("dataset_to_index", pa.int64()),
    ]
    for key in videos:
        fields += [
            (f"videos/{key}/chunk_index", pa.int64()),
            (f"videos/{key}/file_index", pa.int64()),
            (f"videos/{key}/from_timestamp", pa.float64()),
            (f"videos/{key}/to_timestamp", pa.float64()),
        ]
    for name, feature in stats.items():
        for key, values in feature.items():
            kind = pa.int64() if key == "count" else pa.float64()
            for _ in range(np.ndim(values)):
                kind = pa.list_(kind)
            fields.append((f"stats/{name}/{key}", kind))
    fields += [
        ("dial/script", pa.string()),
        ("dial/scene", pa.string()),
        ("dial/tick", pa.float64()),
        ("dial/seed", pa.int64()),
        ("dial/perturb_mm", pa.float64()),
        ("dial/shift_mm", pa.list_(pa.float64())),
        ("dial/disturbances", pa.list_(pa.string())),
        ("dial/outcomes", pa.string()),
        ("dial/success", pa.bool_()),
        ("dial/criteria", pa.string()),
        ("dial/error", pa.string()),
        ("dial/sim_time", pa.float64()),
    ]
    fields += [("meta/episodes/chunk_index", pa.int64()), ("meta/episodes/file_index", pa.int64())]
    return pa.schema(fields)


def episode_row(schema: Any, values: Mapping[str, object]) -> Any:
    """A one-row episodes table; numpy stats become nested lists."""
    row = {}
    for name in schema.names:
        value = values[name]
        row[name] = [value.tolist() if isinstance(value, np.ndarray) else value]
    return pa.Table.from_pydict(row, schema=schema)


def tasks_table(tasks: Sequence[str]) -> Any:
    """meta/tasks.parquet: ``task_index`` and ``task``, with the pandas metadata that makes
    ``task`` the index (as LeRobot reads it: without it, a frame's task reads as a number)."""
    table = pa.table(
        {
            "task_index": pa.array(range(len(tasks)), type=pa.int64()),
            "task": pa.array(list(tasks), type=pa.string()),
        }
    )
    pandas = {
        "index_columns": ["task"],
        "column_indexes": [
            {
                "name": None,
                "field_name": None,
                "pandas_type": "unicode",
                "numpy_type": "object",
                "metadata": {"encoding": "UTF-8"},
            }
        ],
        "columns": [_pandas_column("task_index", "int64"), _pandas_column("task", "unicode")],
        "attributes": {},
        "creator": {"library": "pyarrow", "version": pa.__version__},
    }
    return table.replace_schema_metadata({"pandas": json.dumps(pandas)})


def _pandas_column(name: str, kind: str) -> dict[str, object]:
    numpy = "object" if kind == "unicode" else kind
    return {
        "name": name,
        "field_name": name,
        "pandas_type": kind,
        "numpy_type": numpy,
        "metadata": None,
    }


def index_names() -> tuple[str, ...]:
    return tuple(name for name, _ in INDEX_FEATURES)
