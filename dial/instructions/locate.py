"""``locate "LOCATION" [also=OBJECT,...]``: the tool is at LOCATION of its object; shift the
object's believed position (and that of every ``also`` object) there.

Sensed by :class:`dial.primitives.sensing.Locate`; the preview has it ``done``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from dial.instructions.base import Args, Instruction, ParamSpec, Values
from dial.instructions.types import Name, Names

if TYPE_CHECKING:
    from dial.preview.moves import PreviewMove
    from dial.primitives.context import Context
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Sensor

_LOCATION = ParamSpec(
    "location",
    Name("location", anchored=True),
    positional=True,
    doc="where the tool is now, relative to the object found",
)
_ALSO = ParamSpec("also", Names("object"), (), doc="objects that moved with it")


@dataclass(frozen=True)
class LocateArgs(Args):
    """``location``: a location relative to an object; ``also``: objects that moved with
    it (aliases of the world file)."""

    location: str
    also: tuple[str, ...]

    def sensor(self, ctx: Context) -> Sensor[Snapshot]:
        from dial.primitives.sensing import Locate

        return Locate(ctx, self.location, self.also)

    def preview(self) -> PreviewMove:
        from dial.preview.moves import Sensed

        return Sensed()


def _build(v: Values) -> LocateArgs:
    return LocateArgs(v[_LOCATION], v[_ALSO])


LOCATE = Instruction(
    "locate",
    "zero",
    (_LOCATION, _ALSO),
    _build,
    'locate "LOCATION" [also=OBJECT,...]',
    "The tool is at LOCATION of its object: shift the object's believed position there.",
    sensing=True,
)
