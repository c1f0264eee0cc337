"""``position_contact``, ``force_contact``, ``tactile_contact`` ``finger=F [threshold=X]``:
wait until contact is signalled (POSITION, FORCE and TACTILE CONTACT).

The condition holds when the finger's reading reaches the threshold
(:mod:`dial.robot.contact`): its fingertip position error, the change in
its tendon force differentials, or its deepest taxel. In a diagram a run waits for it
(:class:`dial.primitives.sensing.ContactWait`); as a condition-only event it is tested once
(:class:`dial.primitives.sensing.ContactTest`); a watched span (``~``) senses it at every
physics step. These are the only instructions that can be watched. The preview has them
``done`` when the finger touches the world or an object.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from dial.instructions.base import FINGER, TIMEOUT, Args, Instruction, ParamSpec, Values
from dial.instructions.types import Contact, ContactKind, Quantity
from dial.units import Dimension

if TYPE_CHECKING:
    from dial.preview.moves import PreviewMove
    from dial.primitives.context import Context
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Allotment, Primitive, Sensor


@dataclass(frozen=True)
class ContactArgs(Args):
    """``kind``: the reading (tactile, force, position); ``finger``: 0-3; ``threshold``: m
    (tactile, position) or N (force); ``timeout``: s."""

    kind: ContactKind
    finger: int
    threshold: float
    timeout: float

    def time_limit(self) -> float:
        return self.timeout

    def contact(self) -> Contact:
        return Contact(self.kind, self.finger, self.threshold)

    def primitive(self, ctx: Context, allotted: Allotment) -> Primitive[Snapshot]:
        from dial.primitives.sensing import ContactWait

        return ContactWait(ctx, allotted, self.contact())

    def sensor(self, ctx: Context) -> Sensor[Snapshot]:
        from dial.primitives.sensing import ContactTest

        return ContactTest(self.contact())

    def preview(self) -> PreviewMove:
        from dial.preview.moves import Sensed

        return Sensed(self.finger)


def _contact(
    kind: ContactKind, dim: Dimension, unit: str, default: float, what: str
) -> Instruction:
    threshold = ParamSpec(
        "threshold", Quantity(dim, unit, 0.0, 1000.0, lo_open=True), default, doc=what
    )

    def build(v: Values) -> Args:
        return ContactArgs(kind, v[FINGER], v[threshold], v[TIMEOUT])

    name = f"{kind}_contact"
    return Instruction(
        name,
        "indeterminate",
        (FINGER, threshold, TIMEOUT),
        build,
        f"{name} finger=F [threshold=X{unit}] [timeout=S]",
        f"Wait until {what} on the finger passes the threshold.",
        sensing=True,
        condition=kind,
    )


POSITION_CONTACT = _contact("position", "length", "mm", 0.003, "the fingertip position error")
FORCE_CONTACT = _contact("force", "force", "N", 0.5, "the change in tendon force differential")
TACTILE_CONTACT = _contact("tactile", "length", "mm", 0.0001, "the deepest taxel reading")
