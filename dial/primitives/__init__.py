"""The instructions of DESIGN 3 on the MuJoCo robot: one primitive class per instruction."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from dial.primitives.arm import ArmMove, PumaCommand
from dial.primitives.context import Context
from dial.primitives.guarded import GuardedMove
from dial.primitives.hand import FingerMove, GraspForce, HandPose, Limp
from dial.primitives.sensing import make_sensing
from dial.scheduler.types import Primitive, PrimitiveFactory, RunInfo

_MAKERS: dict[str, Callable[[Context, RunInfo], Any]] = {
    "hand_pose": HandPose,
    "grasp_force": GraspForce,
    "limp": Limp,
    "finger_move": FingerMove,
    "puma_command": PumaCommand,
    "arm_move": ArmMove,
    "guarded_move": GuardedMove,
}


def make_factory(ctx: Context) -> PrimitiveFactory:
    """The scheduler's factory: a fresh primitive per run."""

    def factory(info: RunInfo) -> Primitive:
        maker = _MAKERS.get(info.event.instruction.name, make_sensing)
        primitive: Primitive = maker(ctx, info)
        return primitive

    return factory


__all__ = ["Context", "make_factory"]
