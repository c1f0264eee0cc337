"""The task's progress over a run: the scene's criteria measured in every recorded frame.

The measuring is :func:`dial.scene.evaluate.reading`, the same code that judges the
criteria at the end of a run, so a plot and the verdict never disagree. Screw threads add
how far their object is unscrewed (the light bulb's turn).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass

import mujoco
import numpy as np

from dial.backend.snapshot import FloatArray
from dial.scene.criteria import Criterion
from dial.scene.evaluate import reading
from dial.scene.thread import find_threads


@dataclass(frozen=True)
class Series:
    """One plotted quantity: ``name`` (an entity path part), ``label`` and ``unit``."""

    name: str
    label: str
    unit: str


class TaskProbe:
    """Samples a scene's measurable criteria, and its threads' turns, from ``MjData``."""

    def __init__(
        self, model: mujoco.MjModel, criteria: tuple[Criterion, ...], objects: Mapping[str, str]
    ) -> None:
        """``objects`` maps the world file's aliases to body names: labels use the aliases."""
        self.model = model
        alias = {body: name for name, body in objects.items()}
        data = mujoco.MjData(model)
        mujoco.mj_forward(model, data)
        self._criteria = [c for c in criteria if reading(c, model, data) is not None]
        self._threads = find_threads(model)
        self.series: list[Series] = []
        for c in self._criteria:
            r = reading(c, model, data)
            assert r is not None
            label = f"{alias.get(r.subject, r.subject)} {r.quantity}"
            self.series.append(Series(c.name, label, r.unit))
        self.series += [Series(f"{t.name}_turn", f"{t.name} turn", "deg") for t in self._threads]

    def sample(self, data: mujoco.MjData) -> FloatArray:
        """(len(series),) values now; ``data`` must be current (after a step or forward)."""
        values = []
        for c in self._criteria:
            r = reading(c, self.model, data)
            values.append(math.nan if r is None else r.value)
        values += [math.degrees(t.turn(data)) for t in self._threads]
        return np.asarray(values, dtype=np.float64)
