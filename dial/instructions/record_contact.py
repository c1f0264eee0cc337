"""``record_contact finger=F [into=SET] [at=now|stop] [source=tactile|links]``: append where
the finger touches (world frame) to a point set.

Sensed by :class:`dial.primitives.sensing.RecordContact`; the preview has it ``done`` when
the finger touches the world or an object.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from dial.instructions.base import FINGER, Args, Instruction, ParamSpec, Values
from dial.instructions.types import Choice, Name

if TYPE_CHECKING:
    from dial.preview.moves import PreviewMove
    from dial.primitives.context import Context
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Sensor

When = Literal["now", "stop"]
Source = Literal["tactile", "links"]
_INTO = ParamSpec("into", Name("set"), "contacts", doc="point set to append to")
_AT = ParamSpec(
    "at",
    Choice[When](("now", "stop")),
    "now",
    doc="now, or where the latest guarded move sensing the finger stopped",
)
_SOURCE = ParamSpec(
    "source",
    Choice[Source](("tactile", "links")),
    "tactile",
    doc="the taxel centroid, or the contact point of the finger's links",
)


@dataclass(frozen=True)
class RecordContactArgs(Args):
    """``finger``: 0-3; ``into``: the point set; ``at``: now, or where the latest guarded
    move sensing the finger stopped; ``source``: the taxel centroid or the links' contact
    point."""

    finger: int
    into: str
    at: When
    source: Source

    def sensor(self, ctx: Context) -> Sensor[Snapshot]:
        from dial.primitives.sensing import RecordContact

        return RecordContact(ctx, self.finger, self.into, self.at, self.source)

    def preview(self) -> PreviewMove:
        from dial.preview.moves import Sensed

        return Sensed(self.finger)


def _build(v: Values) -> RecordContactArgs:
    return RecordContactArgs(v[FINGER], v[_INTO], v[_AT], v[_SOURCE])


RECORD_CONTACT = Instruction(
    "record_contact",
    "zero",
    (FINGER, _INTO, _AT, _SOURCE),
    _build,
    "record_contact finger=F [into=SET] [at=now|stop] [source=tactile|links]",
    "Append where the finger touches (world frame) to a point set.",
    sensing=True,
)
