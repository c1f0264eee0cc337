"""The instructions of DESIGN 3 on the MuJoCo robot: one primitive class per instruction.

Each catalogue entry names its class (``Instruction.primitive``); a test checks that every
name resolves here. Zero-length instructions are sensors (``sense``); a contact
instruction tested as a condition is sensed too.
"""

from __future__ import annotations

from collections.abc import Callable

from dial.primitives.arm import ArmMove, PumaCommand
from dial.primitives.context import Context
from dial.primitives.guarded import GuardedMove
from dial.primitives.hand import FingerMove, GraspForce, HandPose, Limp
from dial.primitives.sensing import ContactWait, Fit, Get, Locate, RecordContact
from dial.robot.snapshot import Snapshot
from dial.scheduler.types import Ended, Primitive, PrimitiveFactory, RunInfo, Sensor

Made = Primitive[Snapshot] | Sensor[Snapshot]

CLASSES: dict[str, Callable[[Context, RunInfo], Made]] = {
    cls.__name__: cls
    for cls in (
        ArmMove,
        ContactWait,
        Fit,
        FingerMove,
        Get,
        GraspForce,
        GuardedMove,
        HandPose,
        Limp,
        Locate,
        PumaCommand,
        RecordContact,
    )
}


def make_factory(ctx: Context) -> PrimitiveFactory[Snapshot]:
    """The runner's factory: a fresh primitive (or sensor) per run."""

    def factory(info: RunInfo) -> Made:
        made = CLASSES[info.event.instruction.primitive](ctx, info)
        if info.instant and isinstance(made, ContactWait):
            return _Test(made)  # a contact wait tested as a condition: is it there now?
        return made

    return factory


class _Test:
    """A contact instruction as a condition-only event: a sensor, not a run."""

    def __init__(self, wait: ContactWait) -> None:
        self.wait = wait

    def sense(self, snapshot: Snapshot) -> Ended:
        return self.wait.sense(snapshot)


__all__ = ["CLASSES", "Context", "make_factory"]
