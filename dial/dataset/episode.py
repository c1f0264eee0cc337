"""One run's frames and what is known of the run: what a sweep's worker sends its parent.

An :class:`Episode` holds plain numpy arrays and strings, so it pickles small and fast; the
writer (:mod:`dial.dataset.writer`) checks it against the dataset's features and writes it.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from dial.dataset.features import FeatureJSON, shape_of


@dataclass(frozen=True)
class EpisodeInfo:
    """What the episodes table says of a run, beside LeRobot's own columns (``dial/...``)."""

    script: str  # as given (a bundled name, or a path)
    scene: str
    tick: float  # s, as run
    seed: int
    perturb_mm: float  # how far the objects were moved from their believed poses
    shift_mm: tuple[float, float, float]  # the move itself, world x, y, z
    disturbances: tuple[str, ...]
    outcomes: Mapping[str, int]  # outcome -> runs that ended so
    success: bool  # the run completed and every criterion held
    criteria: Mapping[str, bool]
    error: str | None
    sim_time: float  # s

    def columns(self) -> dict[str, object]:
        """The ``dial/...`` columns of the episodes table (maps as JSON text: their keys vary
        from scene to scene, a table's columns do not)."""
        return {
            "dial/script": self.script,
            "dial/scene": self.scene,
            "dial/tick": self.tick,
            "dial/seed": self.seed,
            "dial/perturb_mm": self.perturb_mm,
            "dial/shift_mm": list(self.shift_mm),
            "dial/disturbances": list(self.disturbances),
            "dial/outcomes": json.dumps(dict(self.outcomes), sort_keys=True),
            "dial/success": self.success,
            "dial/criteria": json.dumps(dict(self.criteria), sort_keys=True),
            "dial/error": self.error,
            "dial/sim_time": self.sim_time,
        }


@dataclass(frozen=True)
class Episode:
    """A run's frames at ``fps``: ``columns`` maps each feature that is not a video to an
    array of shape (frames, *shape) in its dtype; ``videos`` maps each camera's feature to
    its encoded mp4 (and ``video_stats`` to LeRobot's per-channel statistics of it)."""

    fps: int
    features: Mapping[str, FeatureJSON]  # the data features, as info.json holds them
    columns: Mapping[str, NDArray[np.generic]]
    task: str
    info: EpisodeInfo
    videos: Mapping[str, bytes] = field(default_factory=dict)
    video_stats: Mapping[str, Mapping[str, NDArray[np.float64]]] = field(default_factory=dict)
    robot_type: str = "utah_hand_puma"  # the robot profile's name (info.json's robot_type)

    @property
    def length(self) -> int:
        return len(next(iter(self.columns.values())))

    def problem(self) -> str | None:
        """What makes this episode unwritable (columns that do not match its features)."""
        if not self.columns or self.length < 1:
            return "an episode needs at least one frame"
        for name, feature in self.features.items():
            if feature["dtype"] == "video":
                if name not in self.videos:
                    return f"the episode has no video for '{name}'"
                continue
            column = self.columns.get(name)
            if column is None:
                return f"the episode has no column '{name}'"
            shape = tuple(column.shape[1:])
            want = shape_of(feature)
            if want == (1,) and shape == ():
                shape = (1,)
            if len(column) != self.length or shape != want:
                return f"the column '{name}' has shape {column.shape}, not (frames, *{want})"
            if column.dtype != np.dtype(str(feature["dtype"])):
                return f"the column '{name}' is {column.dtype}, not {feature['dtype']}"
        extra = [name for name in self.columns if name not in self.features]
        return f"the column '{extra[0]}' is not a feature" if extra else None
