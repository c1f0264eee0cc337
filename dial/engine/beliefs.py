"""The world model's records in a run's log: a ``belief`` per change, a ``world`` at the end.

The world model (:mod:`dial.scene.belief`) says what changed; the engine writes it, with the
tick, as the runner writes its own records. A run whose world model changed ends with a
``world`` record (before the ``summary``): every object's believed pose (and size) beside its
true pose in the physics, which ``dial world --believed LOG`` shows. A run in which nothing
was grasped or measured writes neither, and its log is as it was before the world model
learned.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from dial.backend.driver import MujocoRobot
from dial.geometry import matrix_rpy
from dial.primitives.context import Context
from dial.scheduler.log import EventLog
from dial.scheduler.runner import Runner


def journal(log: EventLog, runner: Runner[Any]) -> Callable[[dict[str, object]], None]:
    """Writes each ``belief`` record with the tick the runner is in."""

    def write(record: dict[str, object]) -> None:
        tick = runner.loop.tick if runner.loop is not None else 0
        log.write("belief", **record, tick=tick)

    return write


def believed_world(log: EventLog, ctx: Context, robot: MujocoRobot, ticks: int) -> None:
    """The ``world`` record at the end of a run whose world model changed."""
    model = ctx.world_model
    ctx.refresh()  # a held object where the tool is now
    if not model.changed:
        return
    m, d = robot.model, robot.data
    objects: dict[str, object] = {}
    for alias, body in ctx.world.objects.items():
        b = m.body(body).id
        true = {"pos": d.xpos[b].copy(), "rpy": list(matrix_rpy(d.xmat[b].reshape(3, 3)))}
        believed = model.entry(body)
        believed["held"] = body in model.held
        off = float(np.linalg.norm(np.asarray(believed["pos"]) - d.xpos[b]))
        objects[alias] = {"body": body, "believed": believed, "true": true, "off": off}
    log.write("world", tick=ticks, t=robot.time, objects=objects)
