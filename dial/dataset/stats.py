"""Feature statistics as LeRobot keeps them: per episode, and over the whole dataset.

Each feature gets ``min``, ``max``, ``mean``, ``std``, ``count`` (frames) and the quantiles
``q01``, ``q10``, ``q50``, ``q90``, ``q99``. As LeRobot computes them, every axis but the last
is a batch axis: a vector's stats have its shape, a scalar column's shape (1,), and an array
of more axes has one value per index of its last axis (``observation.tactile``: one per
column of the pads, over every frame, finger and row). An episode's quantiles are exact; the
dataset's are LeRobot's aggregate: the frame-weighted mean of the episodes' quantiles. The
aggregate is updated one episode at a time, so memory does not grow with episodes.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

QUANTILES = (0.01, 0.10, 0.50, 0.90, 0.99)
QUANTILE_KEYS = tuple(f"q{round(q * 100):02d}" for q in QUANTILES)
STAT_KEYS = ("min", "max", "mean", "std", "count", *QUANTILE_KEYS)

Stats = dict[str, NDArray[np.float64]]  # stat name -> values (count: int64, shape (1,))
FeatureStats = dict[str, Stats]  # feature name -> its stats


def column_stats(values: NDArray[np.generic]) -> Stats:
    """The stats of one feature's column ``(frames, *shape)`` (a (frames,) column counts as
    shape (1,)), computed in float64."""
    frames = len(values)
    x = np.asarray(values, dtype=np.float64)
    x = x[:, None] if x.ndim == 1 else x.reshape(-1, x.shape[-1])
    stats: Stats = {
        "min": x.min(axis=0),
        "max": x.max(axis=0),
        "mean": x.mean(axis=0),
        "std": x.std(axis=0),
        "count": np.array([frames], dtype=np.int64),
    }
    quantiles = np.quantile(x, QUANTILES, axis=0)
    for key, q in zip(QUANTILE_KEYS, quantiles, strict=True):
        stats[key] = q
    return stats


def episode_stats(columns: Mapping[str, NDArray[np.generic]]) -> FeatureStats:
    return {name: column_stats(values) for name, values in columns.items()}


def merge(total: FeatureStats | None, episode: FeatureStats) -> FeatureStats:
    """The stats of the frames of ``total`` and of ``episode`` together (LeRobot's
    ``aggregate_stats``: exact min, max, mean, std and count; count-weighted quantiles)."""
    if total is None:
        return {name: dict(stats) for name, stats in episode.items()}
    out: FeatureStats = {}
    for name in total.keys() | episode.keys():
        if name not in total or name not in episode:
            out[name] = dict(total.get(name) or episode[name])
            continue
        out[name] = _merge_feature(total[name], episode[name])
    return {name: out[name] for name in sorted(out)}


def _merge_feature(a: Stats, b: Stats) -> Stats:
    na, nb = float(a["count"][0]), float(b["count"][0])
    n = na + nb
    mean = (a["mean"] * na + b["mean"] * nb) / n
    variance = ((a["std"] ** 2 + (a["mean"] - mean) ** 2) * na
                + (b["std"] ** 2 + (b["mean"] - mean) ** 2) * nb) / n  # fmt: skip
    out: Stats = {
        "min": np.minimum(a["min"], b["min"]),
        "max": np.maximum(a["max"], b["max"]),
        "mean": mean,
        "std": np.sqrt(np.maximum(variance, 0.0)),
        "count": np.array([int(na + nb)], dtype=np.int64),
    }
    for key in QUANTILE_KEYS:
        out[key] = (a[key] * na + b[key] * nb) / n
    return out


def as_json(stats: FeatureStats) -> dict[str, dict[str, object]]:
    """Nested lists of Python numbers, as stats.json holds them."""
    return {
        name: {key: np.asarray(values).tolist() for key, values in feature.items()}
        for name, feature in stats.items()
    }


def from_json(data: Mapping[str, Mapping[str, object]]) -> FeatureStats:
    """Read stats.json back (to go on aggregating when a dataset is appended to)."""
    out: FeatureStats = {}
    for name, feature in data.items():
        out[name] = {
            key: np.asarray(values, dtype=np.int64 if key == "count" else np.float64)
            for key, values in feature.items()
        }
    return out
