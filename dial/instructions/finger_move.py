"""``finger_move finger=F DX DY DZ [frame=palm|world]``: a straight-line fingertip motion by
IK on the finger's joints (TRAJECTORY MOVE, Cartesian).

Runs :class:`dial.primitives.hand.FingerMove`; the preview steps it and checks that the
fingertip ends at its goal (:func:`dial.preview.checks.finger_goal`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from dial.instructions.base import DX, DY, DZ, FINGER, Args, Instruction, ParamSpec, Values
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import FINGERS, Choice

if TYPE_CHECKING:
    from dial.preview.moves import Making, PreviewMove
    from dial.primitives.context import Context
    from dial.primitives.hand import FingerMove
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Allotment, Primitive

FrameName = Literal["palm", "world"]
_FRAME = ParamSpec("frame", Choice[FrameName](("palm", "world")), "palm")


@dataclass(frozen=True)
class FingerMoveArgs(Args):
    """``finger``: which fingertip (0-3); ``dx``, ``dy``, ``dz``: its displacement (m) in
    ``frame`` (the palm's, or the world's)."""

    finger: int
    dx: float
    dy: float
    dz: float
    frame: FrameName

    def effectors(self, scene: SceneNames | None) -> frozenset[str]:
        return frozenset({FINGERS[self.finger]})

    def primitive(self, ctx: Context, allotted: Allotment) -> Primitive[Snapshot]:
        return self._primitive(ctx, allotted)

    def _primitive(self, ctx: Context, allotted: Allotment) -> FingerMove:
        from dial.primitives.hand import FingerMove

        return FingerMove(ctx, allotted, self.finger, (self.dx, self.dy, self.dz), self.frame)

    def preview(self) -> PreviewMove:
        from dial.preview.checks import finger_goal
        from dial.preview.moves import Stepped

        def make(m: Making) -> FingerMove:
            return self._primitive(m.ctx, m.allotted)

        return Stepped(make, counts=lambda prim: (0, 1), finished=finger_goal)


def _build(v: Values) -> FingerMoveArgs:
    return FingerMoveArgs(v[FINGER], v[DX], v[DY], v[DZ], v[_FRAME])


FINGER_MOVE = Instruction(
    "finger_move",
    "fixed",
    (FINGER, DX, DY, DZ, _FRAME),
    _build,
    "finger_move finger=F DX DY DZ [frame=palm|world]",
    "Move a fingertip along a straight line by IK on the finger's joints.",
)
