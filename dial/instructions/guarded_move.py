"""``guarded_move``: move the arm or a fingertip along a line until contact (GUARDED MOVE).

Runs :class:`dial.primitives.guarded.GuardedMove`: the guard is tested by the robot after
every physics step, which freezes the effector at the step where a condition first holds.
The preview moves it at once, stopping at its first touch
(:func:`dial.preview.motions.guarded`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from dial.instructions.base import DX, DY, DZ, TIMEOUT, Args, Instruction, ParamSpec, Values
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import ARM, FINGERS, Choice, Conditions, ContactKind, Finger, Quantity

if TYPE_CHECKING:
    from dial.preview.moves import PreviewMove
    from dial.primitives.context import Context
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Allotment, Primitive

FrameName = Literal["tool", "palm", "world"]

_FINGER = ParamSpec[int | None](
    "finger", Finger(), None, doc="move this fingertip (default: the arm)"
)
_UNTIL = ParamSpec("until", Conditions(), doc="contact conditions that stop the move")
_SENSE = ParamSpec[int | None]("sense", Finger(), None, doc="finger whose sensors are watched")
_MAX = ParamSpec[float | None]("max", Quantity("length", "m", 0.0, 1.0, lo_open=True), None)
_PRESS = ParamSpec(
    "press",
    Quantity("length", "m", 0.0, 0.01),
    0.0,
    doc="after contact, set the effector this much further on, to keep touching",
)
_FRAME = ParamSpec[FrameName | None]("frame", Choice[FrameName](("tool", "palm", "world")), None)
_SPEED = ParamSpec("speed", Quantity("speed", "m/s", 0.0, 1.0, lo_open=True), 0.05)


@dataclass(frozen=True)
class GuardedMoveArgs(Args):
    """A guarded move's arguments.

    ``finger``: the fingertip that moves (0-3), None for the arm's tool. ``dx``, ``dy``,
    ``dz``: the direction (m; its length is the travel when ``max`` is None). ``until``:
    contact conditions (kind, threshold in m or N), any one of which stops it. ``sense``:
    the finger whose sensors are watched (None: the moving finger, or every finger for the
    arm). ``max``: the travel (m) after which it ends ``missed``. ``press``: how much further
    on (m) the effector is set after contact. ``frame``: of the direction (None: the tool's
    for the arm, the palm's for a finger). ``speed``: m/s. ``timeout``: s.
    """

    finger: int | None
    dx: float
    dy: float
    dz: float
    until: tuple[tuple[ContactKind, float], ...]
    sense: int | None
    max: float | None
    press: float
    frame: FrameName | None
    speed: float
    timeout: float

    def time_limit(self) -> float:
        return self.timeout

    @property
    def moving_frame(self) -> FrameName:
        """The frame of the direction, its default filled in."""
        return self.frame or ("tool" if self.finger is None else "palm")

    @property
    def sensed(self) -> tuple[int, ...]:
        """The fingers whose sensors the guard watches."""
        if self.sense is not None:
            return (self.sense,)
        return (self.finger,) if self.finger is not None else tuple(range(len(FINGERS)))

    def effectors(self, scene: SceneNames | None) -> frozenset[str]:
        return frozenset({ARM if self.finger is None else FINGERS[self.finger]})

    def problem(self) -> str | None:
        if self.dx == 0.0 and self.dy == 0.0 and self.dz == 0.0:
            return "guarded_move needs a nonzero direction DX DY DZ"
        if self.finger is None and self.frame == "palm":
            return "frame=palm is for finger moves; an arm guarded_move takes frame=tool or world"
        if self.finger is not None and self.frame == "tool":
            return "frame=tool is for arm moves; a finger guarded_move takes frame=palm or world"
        return None

    def primitive(self, ctx: Context, allotted: Allotment) -> Primitive[Snapshot]:
        from dial.primitives.guarded import GuardedMove

        return GuardedMove(
            ctx,
            allotted,
            finger=self.finger,
            displacement=(self.dx, self.dy, self.dz),
            travel=self.max,
            frame=self.moving_frame,
            speed=self.speed,
            press=self.press,
            until=self.until,
            sense=self.sensed,
        )

    def preview(self) -> PreviewMove:
        from functools import partial

        from dial.preview.motions import guarded
        from dial.preview.moves import AtOnce

        line = partial(
            guarded,
            finger=self.finger,
            displacement=(self.dx, self.dy, self.dz),
            travel=self.max,
            frame=self.moving_frame,
        )
        return AtOnce(line, arm=self.finger is None)


def _build(v: Values) -> GuardedMoveArgs:
    return GuardedMoveArgs(
        v[_FINGER],
        v[DX],
        v[DY],
        v[DZ],
        v[_UNTIL],
        v[_SENSE],
        v[_MAX],
        v[_PRESS],
        v[_FRAME],
        v[_SPEED],
        v[TIMEOUT],
    )


GUARDED_MOVE = Instruction(
    "guarded_move",
    "indeterminate",
    (_FINGER, DX, DY, DZ, _UNTIL, _SENSE, _MAX, _PRESS, _FRAME, _SPEED, TIMEOUT),
    _build,
    "guarded_move [finger=F] DX DY DZ until=KIND[:THRESHOLD],... [sense=F] [max=D] "
    "[press=D] [frame=tool|palm|world] [speed=V] [timeout=S]",
    "Move along a direction until contact is sensed, checked at every physics step.",
)
