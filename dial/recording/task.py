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

from dial.robot.snapshot import FloatArray
from dial.scene.criteria import Criterion
from dial.scene.evaluate import reader
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
        readers = [(c, reader(c, model)) for c in criteria]
        self._readers = [read for _, read in readers if read is not None]
        self._threads = find_threads(model)
        self.series: list[Series] = []
        for c, read in readers:
            if read is not None:
                r = read(data)
                self.series.append(
                    Series(c.name, f"{alias.get(r.subject, r.subject)} {r.quantity}", r.unit)
                )
        self.series += [Series(f"{t.name}_turn", f"{t.name} turn", "deg") for t in self._threads]

    def sample(self, data: mujoco.MjData) -> FloatArray:
        """(len(series),) values now; ``data`` must be current (after a step or forward)."""
        values = [read(data).value for read in self._readers]
        values += [math.degrees(t.turn(data)) for t in self._threads]
        return np.asarray(values, dtype=np.float64)
