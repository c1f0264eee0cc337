"""``limp [fingers=MASK] [save=NAME]``: the joints become back-drivable (LIMP); at the end
the reached pose is recorded, to be saved as a named pose (teaching).

Runs :class:`dial.primitives.hand.Limp`; the preview steps it (it moves nothing).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from dial.instructions.base import Args, Instruction, ParamSpec, Values
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import ALL_JOINTS, Mask, Name, mask_fingers

if TYPE_CHECKING:
    from dial.preview.moves import Making, PreviewMove
    from dial.primitives.context import Context
    from dial.primitives.hand import Limp
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Allotment, Primitive

_FINGERS = ParamSpec("fingers", Mask(), ALL_JOINTS, doc="joints to make back-drivable")
_SAVE = ParamSpec[str | None](
    "save", Name("pose"), None, doc="save the reached pose under this name"
)


@dataclass(frozen=True)
class LimpArgs(Args):
    """``fingers``: the joint mask made limp; ``save``: the name the reached pose is
    recorded under (a new pose, not one of the world file), or None."""

    fingers: int
    save: str | None

    def effectors(self, scene: SceneNames | None) -> frozenset[str]:
        return mask_fingers(self.fingers)

    def primitive(self, ctx: Context, allotted: Allotment) -> Primitive[Snapshot]:
        return self._primitive(ctx, allotted)

    def _primitive(self, ctx: Context, allotted: Allotment) -> Limp:
        from dial.primitives.hand import Limp

        return Limp(ctx, allotted, self.fingers, self.save)

    def preview(self) -> PreviewMove:
        from dial.preview.moves import Stepped

        def make(m: Making) -> Limp:
            return self._primitive(m.ctx, m.allotted)

        return Stepped(make, counts=lambda prim: (0, 0))


def _build(v: Values) -> LimpArgs:
    return LimpArgs(v[_FINGERS], v[_SAVE])


LIMP = Instruction(
    "limp",
    "fixed",
    (_FINGERS, _SAVE),
    _build,
    "limp [fingers=MASK] [save=NAME]",
    "Make joints back-drivable; record the reached pose at the end (teaching).",
)
