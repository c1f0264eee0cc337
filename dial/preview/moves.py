"""How ``dial preview`` moves a run: each instruction's record declares one (``Args.preview``).

- :class:`Stepped`: a fixed-length run. The preview makes its primitive (the run's own, or
  one made for the preview), starts it on the posed scene, checks its plan, steps it every
  control period with the set-points going straight to the pose, and checks where it got.
- :class:`AtOnce`: a run whose end cannot be known in advance (a guarded move, a grasp),
  moved whole at its start by a motion of :mod:`dial.preview.motions`.
- :class:`Sensed`: sensing and contact waits: ``done`` when their finger touches the world
  or an object, else ``missed``; ``done`` when they have no finger.

The walk (:class:`dial.preview.walk.Walk`) is the :class:`Stage`: a move calls the one
method of it that moves its kind.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Generic, NamedTuple, Protocol, TypeVar

from dial.robot.snapshot import Snapshot
from dial.scheduler.primitive import Allotment, Outcome, Primitive

if TYPE_CHECKING:
    from dial.preview.places import Places
    from dial.preview.scene import Scene
    from dial.primitives.context import Context

P = TypeVar("P", bound=Primitive[Snapshot])
Check = Callable[[], None]  # pose the scene and record its problems


@dataclass
class Found:
    """What a motion previewed at once found: its outcome, and problems (messages)."""

    outcome: Outcome
    problems: list[str] = field(default_factory=list)


class Making(NamedTuple):
    """What the preview makes a stepped run's primitive with: the run's context and
    allotment, where world-file statements are written, and the event's parameters as
    written (for labels)."""

    ctx: Context
    allotted: Allotment
    places: Places
    written: str


def _no_problems(scene: Scene, prim: Primitive[Snapshot]) -> list[str]:
    return []


def _no_label(prim: Primitive[Snapshot], progress: float) -> str:
    return ""


class Stage(Protocol):
    """What a move asks of the walk."""

    def stepped(self, move: Stepped[P]) -> Outcome | None:
        """Start the run's primitive; it is stepped from now on (None), or it failed."""
        ...

    def at_once(self, move: AtOnce) -> Outcome:
        """Move the run whole now."""
        ...

    def sensed(self, move: Sensed) -> Outcome:
        """The outcome of a sensing run, from the pose."""
        ...


class PreviewMove(Protocol):
    """How the preview moves a run of an instruction."""

    def begin(self, stage: Stage) -> Outcome | None:
        """Move the run (or start moving it): its outcome, or None while it is stepped."""
        ...


@dataclass(frozen=True)
class Stepped(Generic[P]):
    """A fixed-length run, stepped on its own primitive.

    ``started``: problems with its plan; ``finished``: problems with where it got;
    ``counts``: the arm targets and hand motions it adds to the preview's counts, once
    started; ``label``: what it is doing at a progress, for the contacts it is blamed for.
    """

    make: Callable[[Making], P]
    counts: Callable[[P], tuple[int, int]]
    started: Callable[[Scene, P], list[str]] = _no_problems
    finished: Callable[[Scene, P], list[str]] = _no_problems
    label: Callable[[P, float], str] = _no_label

    def begin(self, stage: Stage) -> Outcome | None:
        return stage.stepped(self)


@dataclass(frozen=True)
class AtOnce:
    """A guarded move or a grasp, moved whole at its start; ``arm``: it moves the arm (else
    a finger or the hand), for the counts."""

    motion: Callable[[Scene, Check], Found]
    arm: bool

    def begin(self, stage: Stage) -> Outcome:
        return stage.at_once(self)


@dataclass(frozen=True)
class Sensed:
    """Sensing: ``done`` when ``finger`` touches the world or an object (None: ``done``)."""

    finger: int | None = None

    def begin(self, stage: Stage) -> Outcome:
        return stage.sensed(self)
