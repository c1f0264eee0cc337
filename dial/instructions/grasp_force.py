"""``grasp_force "JMASK_TMASK FORCE" [speed=RAD/S] [timeout=S]``: close the masked joints
until each tendon-masked joint feels FORCE (GRASP WITH FORCE).

Runs :class:`dial.primitives.hand.GraspForce`. The preview closes the joints at once until
each finger touches something or reaches its limits, and carries what they hold
(:func:`dial.preview.motions.grasp`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from dial.instructions.base import TIMEOUT, Args, Instruction, ParamSpec, Values
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import MaskPair, Quantity, mask_fingers

if TYPE_CHECKING:
    from dial.preview.moves import PreviewMove
    from dial.primitives.context import Context
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Allotment, Primitive

# Largest tension a tendon actuator can pull (N); grasp thresholds must stay below it.
TENDON_TENSION_LIMIT = 50.0

_MASKS = ParamSpec("masks", MaskPair(), positional=True, doc="joints to close, tendons to watch")
_FORCE = ParamSpec(
    "force",
    Quantity("force", "N", 0.0, TENDON_TENSION_LIMIT, lo_open=True),
    positional=True,
    doc="flexor-minus-extensor tension that stops a joint",
)
_SPEED = ParamSpec(
    "speed",
    Quantity("angular_speed", "rad/s", 0.0, 10.0, lo_open=True),
    0.8,
    doc="closing speed of each joint",
)


@dataclass(frozen=True)
class GraspForceArgs(Args):
    """``jmask``: the joints to close; ``tmask``: the joints whose tendons are watched (within
    ``jmask``); ``force``: the flexor-minus-extensor tension (N) that stops a finger;
    ``speed``: rad/s; ``timeout``: s."""

    jmask: int
    tmask: int
    force: float
    speed: float
    timeout: float

    def time_limit(self) -> float:
        return self.timeout

    def effectors(self, scene: SceneNames | None) -> frozenset[str]:
        return mask_fingers(self.jmask)

    def primitive(self, ctx: Context, allotted: Allotment) -> Primitive[Snapshot]:
        from dial.primitives.hand import GraspForce

        return GraspForce(ctx, allotted, self.jmask, self.tmask, self.force, self.speed)

    def preview(self) -> PreviewMove:
        from functools import partial

        from dial.preview.motions import grasp
        from dial.preview.moves import AtOnce

        return AtOnce(partial(grasp, jmask=self.jmask, tmask=self.tmask), arm=False)


def _build(v: Values) -> GraspForceArgs:
    jmask, tmask = v[_MASKS]
    return GraspForceArgs(jmask, tmask, v[_FORCE], v[_SPEED], v[TIMEOUT])


GRASP_FORCE = Instruction(
    "grasp_force",
    "indeterminate",
    (_MASKS, _FORCE, _SPEED, TIMEOUT),
    _build,
    'grasp_force "JMASK_TMASK FORCE" [speed=RAD/S] [timeout=S]',
    "Close masked joints until each tendon-masked joint feels FORCE (GRASP WITH FORCE).",
)
