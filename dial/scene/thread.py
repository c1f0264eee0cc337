"""Screw threads that let go: the light bulb's thread (see ``objects_lightbulb.xml``).

A threaded object is a free body welded (equality ``P_thread_weld``) to a carrier whose slide
``P_thread_rise`` and hinge ``P_thread_turn`` are coupled like a screw. MuJoCo cannot switch
a constraint off by itself, so the physics driver calls :meth:`Thread.update` after every
physics step: once the turn reaches the top of its range, the weld is switched off and the
object is free. Releasing is one-way; ``mj_resetData`` re-engages it (``eq_active0``).
A world file's ``[thread] turns`` sets how many turns that takes (:func:`set_turns`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco

from dial.scene.reader import WorldFileError
from dial.scene.world import World

WELD_SUFFIX = "_thread_weld"
RELEASE_MARGIN = 0.01  # rad below the top of the turn range; MuJoCo's limits are soft


@dataclass(frozen=True)
class Thread:
    """One releasable thread of a compiled model."""

    name: str  # the prefix P, e.g. "lightbulb"
    weld: int  # equality id of the weld
    turn_qpos: int  # qpos address of the turn hinge
    release_turn: float  # rad; turn at which the weld lets go

    def turn(self, data: mujoco.MjData) -> float:
        """How far the object is unscrewed, rad (the turn hinge's position)."""
        return float(data.qpos[self.turn_qpos])

    def engaged(self, data: mujoco.MjData) -> bool:
        return bool(data.eq_active[self.weld])

    def update(self, data: mujoco.MjData) -> bool:
        """Release the object once unscrewed; ``True`` only on the step it lets go."""
        if data.eq_active[self.weld] and data.qpos[self.turn_qpos] >= self.release_turn:
            data.eq_active[self.weld] = 0
            return True
        return False


def find_threads(model: mujoco.MjModel) -> tuple[Thread, ...]:
    """Every ``P_thread_weld`` equality with its ``P_thread_turn`` joint, in equality order."""
    threads = []
    for i in range(model.neq):
        name = model.equality(i).name
        if not name.endswith(WELD_SUFFIX):
            continue
        prefix = name.removesuffix(WELD_SUFFIX)
        turn = model.joint(f"{prefix}_thread_turn")
        top = float(turn.range[1])
        threads.append(Thread(prefix, i, int(turn.qposadr[0]), top - RELEASE_MARGIN))
    return tuple(threads)


def set_turns(model: mujoco.MjModel, world: World) -> None:
    """Apply the world file's ``[thread] turns``: every thread's turn range becomes
    [0, 2 pi turns], so it lets go after that many turns (screwed tight at 0, as compiled).

    Call it before :func:`find_threads`, which reads the release point from the range.
    """
    if world.thread_turns is None:
        return
    threads = find_threads(model)
    if not threads:
        raise WorldFileError(
            world.path,
            "thread",
            f"the scene's model ({world.model_path.name}) has no screw thread "
            f"(an equality named P{WELD_SUFFIX})",
        )
    for thread in threads:
        model.jnt_range[model.joint(f"{thread.name}_thread_turn").id, 1] = (
            2.0 * math.pi * world.thread_turns
        )
