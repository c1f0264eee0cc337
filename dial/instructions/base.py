"""How an instruction is declared: its parameters, its typed argument record, its length.

Each instruction is declared once, in its own module that :mod:`dial.instructions.catalogue`
lists (``guarded_move.py`` for ``guarded_move``):

- an :class:`Instruction`: its name, its length (zero, fixed or indeterminate), its
  parameters (:class:`ParamSpec`: name, type with units, default) and how to build its
  argument record from the bound values; the checker binds definitions against it;
- its argument record, an :class:`Args` subclass: a frozen dataclass of the bound
  arguments in SI units, which says what an event of the instruction does: which effectors
  it commands and whether its arguments fit together (the check), the contact condition
  it waits for, the primitive or sensor that runs it, and how ``dial preview`` moves it.

A checked script carries these records (``EventDef.args``). Their run-time parts import
the primitive (or the preview's motion) when first asked for, so that checking a script
loads neither MuJoCo nor trio.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Generic, Literal, TypeVar, cast

from dial.instructions.scene_names import SceneNames
from dial.instructions.types import Contact, ContactKind, Finger, ParamType, Quantity

if TYPE_CHECKING:
    from dial.preview.moves import PreviewMove
    from dial.primitives.context import Context
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Allotment, Primitive, Sensor

Length = Literal["zero", "fixed", "indeterminate"]
T = TypeVar("T")
T_co = TypeVar("T_co", covariant=True)

DEFAULT_TIMEOUT = 10.0  # s, of simulated time


class Required(Enum):
    """The default of a parameter that has none."""

    REQUIRED = "required"


REQUIRED = Required.REQUIRED


@dataclass(frozen=True)
class ParamSpec(Generic[T_co]):
    """One parameter: its name, type, default (``REQUIRED`` if none) and role."""

    name: str
    type: ParamType[T_co]
    default: T_co | Required = REQUIRED
    positional: bool = False
    doc: str = ""

    @property
    def required(self) -> bool:
        return self.default is REQUIRED


class Values:
    """An event's bound values by parameter name (SI), each read back through its spec."""

    def __init__(self, values: Mapping[str, object]) -> None:
        self._values = values

    def __getitem__(self, spec: ParamSpec[T]) -> T:
        # Bound by ``spec.type.parse`` or defaulted to ``spec.default``: a T either way.
        return cast("T", self._values[spec.name])


class Args:
    """An event's bound arguments (SI units): the base of every instruction's record.

    The defaults suit a sensing instruction with no effector that ends at once.
    """

    def time_limit(self) -> float | None:
        """Simulated s after which an indeterminate run ends ``timeout``; None: never."""
        return None

    def effectors(self, scene: SceneNames | None) -> frozenset[str]:
        """The effectors an event commands (the arm, fingers), given its scene's names."""
        return frozenset()

    def problem(self) -> str | None:
        """Why these arguments do not fit together, or None: the instruction's own check."""
        return None

    def contact(self) -> Contact | None:
        """The contact condition a watched span of the event senses (contact waits)."""
        return None

    def primitive(self, ctx: Context, allotted: Allotment) -> Primitive[Snapshot]:
        """The primitive that runs a fixed-length or indeterminate event."""
        raise NotImplementedError(f"{type(self).__name__} is sensed, not stepped")

    def sensor(self, ctx: Context) -> Sensor[Snapshot]:
        """The sensor of a zero-length event, or of a condition-only event's test."""
        raise NotImplementedError(f"{type(self).__name__} is stepped, not sensed")

    def preview(self) -> PreviewMove:
        """How ``dial preview`` moves a run of the event (:mod:`dial.preview.moves`)."""
        raise NotImplementedError(f"{type(self).__name__} declares no preview")


@dataclass(frozen=True)
class Instruction:
    """An instruction the scripts can bind events to (DESIGN 3).

    ``build`` makes the argument record from the bound values. ``sensing``: no effector
    ever; only these may be condition-only events. ``verbs``: the parameters after each
    verb word, for a verb-style instruction (``puma_command "moves LOC"``).
    ``positional_counts``: the allowed numbers of positional words, when optional ones
    come in groups (``arm_move``). ``condition``: for the contact instructions, the kind of
    contact their condition reads; only these can be watched with ``~`` (DESIGN 2.7).
    """

    name: str
    length: Length
    params: tuple[ParamSpec[object], ...]
    build: Callable[[Values], Args]
    usage: str
    summary: str
    sensing: bool = False
    verbs: Mapping[str, tuple[ParamSpec[object], ...]] = field(default_factory=dict)
    positional_counts: tuple[int, ...] = ()
    condition: ContactKind | None = None

    def spec(self, name: str) -> ParamSpec[object] | None:
        return next((p for p in self.params if p.name == name), None)


# Parameters that several instructions share.
TIMEOUT = ParamSpec(
    "timeout",
    Quantity("time", "s", 0.0, 3600.0, lo_open=True),
    DEFAULT_TIMEOUT,
    doc="give up (outcome timeout) after this much simulated time",
)
FINGER = ParamSpec("finger", Finger(), doc="which finger")
_LENGTH = Quantity("length", "m", -1.0, 1.0)
DX, DY, DZ = (
    ParamSpec(n, _LENGTH, positional=True, doc=f"{n[-1]} displacement") for n in ("dx", "dy", "dz")
)
