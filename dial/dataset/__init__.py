"""Demonstration datasets: runs and sweeps written in the LeRobot v3.0 format (docs/datasets.md).

``Recorder`` (an observer) samples a run into an ``Episode``; ``DatasetWriter`` writes
episodes into a dataset folder. pyarrow (the ``dataset`` extra) loads when a writer is made.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from dial.dataset.episode import Episode, EpisodeInfo
    from dial.dataset.recorder import Recorder
    from dial.dataset.tables import DatasetError
    from dial.dataset.writer import DatasetWriter

__all__ = ["DatasetError", "DatasetWriter", "Episode", "EpisodeInfo", "Recorder"]

_WHERE = {
    "DatasetError": "dial.dataset.tables",
    "DatasetWriter": "dial.dataset.writer",
    "Episode": "dial.dataset.episode",
    "EpisodeInfo": "dial.dataset.episode",
    "Recorder": "dial.dataset.recorder",
}


def __getattr__(name: str) -> object:
    """Each class imported when first used: the recorder loads MuJoCo, the writer pyarrow."""
    if name in _WHERE:
        import importlib

        return getattr(importlib.import_module(_WHERE[name]), name)
    raise AttributeError(f"module 'dial.dataset' has no attribute '{name}'")
