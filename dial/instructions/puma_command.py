"""``puma_command "ex PROG"`` or ``"move LOC"``, ``"moves LOC"``, ``"appro LOC D"``,
``"depart D"``, ``"drive J DEG"``: a VAL-II subset, time-scaled to fill the run's span.

``ex`` runs a stored program of the world file (:class:`PumaProgramArgs`, run by
:class:`dial.primitives.arm.PumaProgram`); the other verbs are one statement
(:class:`PumaStatementArgs`, run by :class:`dial.primitives.arm.PumaStatement`). MOVE is
joint-interpolated; MOVES and DEPART are straight lines. The preview plans a program
statement by statement, so that one out of reach is reported and the rest still previewed
(:mod:`dial.preview.motions`), and checks the plan (:func:`dial.preview.checks.arm_plan`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from dial.instructions.base import Args, Instruction, ParamSpec, Values
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import ARM, Choice, Integer, Name, Quantity
from dial.scene.valii import Appro, Depart, Drive, Move, Statement

if TYPE_CHECKING:
    from dial.preview.moves import Making, PreviewMove
    from dial.primitives.context import Context
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Allotment, Primitive

_PROGRAM = ParamSpec("program", Name("program"), doc="stored program in the world file")
_MOVE_TO = ParamSpec("location", Name("location"), doc="joint-interpolated move")
_MOVES_TO = ParamSpec("location", Name("location"), doc="straight-line move")
_APPRO_TO = ParamSpec("location", Name("location"))
_APPRO_BY = ParamSpec("distance", Quantity("length", "m", 0.0, 1.0), doc="back along tool z")
_DEPART_BY = ParamSpec("distance", Quantity("length", "m", -1.0, 1.0), doc="back along tool z")
_JOINT = ParamSpec(
    "joint", Integer(1, 9), doc="the arm's joint (1-6 on the PUMA, 1-7 on the Panda)"
)
_ANGLE = ParamSpec(
    "angle", Quantity("angle", "deg", -6.2832, 6.2832), doc="degrees unless suffixed"
)


@dataclass(frozen=True)
class _PumaArgs(Args):
    def effectors(self, scene: SceneNames | None) -> frozenset[str]:
        return frozenset({ARM})


@dataclass(frozen=True)
class PumaProgramArgs(_PumaArgs):
    """``ex PROG``: ``program`` names a stored program of the world file."""

    program: str

    def primitive(self, ctx: Context, allotted: Allotment) -> Primitive[Snapshot]:
        from dial.primitives.arm import PumaProgram

        return PumaProgram(ctx, allotted, self.program)

    def preview(self) -> PreviewMove:
        from dial.preview.checks import program_plan
        from dial.preview.motions import PreviewProgram
        from dial.preview.moves import Stepped

        def make(m: Making) -> PreviewProgram:
            return PreviewProgram(m.ctx, m.allotted, self.program, m.places)

        return Stepped[PreviewProgram](
            make,
            counts=lambda prim: (prim.targets, 0),
            started=program_plan,
            label=PreviewProgram.label_at,
        )


@dataclass(frozen=True)
class PumaStatementArgs(_PumaArgs):
    """One VAL-II statement (SI: m, rad); ``verb`` names it in messages."""

    statement: Statement
    verb: str

    def primitive(self, ctx: Context, allotted: Allotment) -> Primitive[Snapshot]:
        from dial.primitives.arm import PumaStatement

        return PumaStatement(ctx, allotted, self.statement, self.verb)

    def preview(self) -> PreviewMove:
        from dial.preview.checks import program_plan
        from dial.preview.motions import PreviewStatement
        from dial.preview.moves import Stepped

        def make(m: Making) -> PreviewStatement:
            return PreviewStatement(m.ctx, m.allotted, self.statement, self.verb, m.written)

        return Stepped[PreviewStatement](
            make,
            counts=lambda prim: (1, 0),
            started=program_plan,
            label=PreviewStatement.label_at,
        )


# Each verb's parameters, and the record they make (a statement's line is 1).
_VERBS: dict[str, tuple[tuple[ParamSpec[object], ...], Callable[[Values], Args]]] = {
    "ex": ((_PROGRAM,), lambda v: PumaProgramArgs(v[_PROGRAM])),
    "move": ((_MOVE_TO,), lambda v: PumaStatementArgs(Move(1, v[_MOVE_TO], False), "move")),
    "moves": ((_MOVES_TO,), lambda v: PumaStatementArgs(Move(1, v[_MOVES_TO], True), "moves")),
    "appro": (
        (_APPRO_TO, _APPRO_BY),
        lambda v: PumaStatementArgs(Appro(1, v[_APPRO_TO], v[_APPRO_BY]), "appro"),
    ),
    "depart": ((_DEPART_BY,), lambda v: PumaStatementArgs(Depart(1, v[_DEPART_BY]), "depart")),
    "drive": (
        (_JOINT, _ANGLE),
        lambda v: PumaStatementArgs(Drive(1, v[_JOINT], v[_ANGLE]), "drive"),
    ),
}
_VERB = ParamSpec("verb", Choice(tuple(_VERBS)), positional=True)


def _build(v: Values) -> Args:
    return _VERBS[v[_VERB]][1](v)


PUMA_COMMAND = Instruction(
    "puma_command",
    "fixed",
    (_VERB,),
    _build,
    'puma_command "ex PROG" | "move LOC" | "moves LOC" | "appro LOC D" | "depart D" '
    '| "drive J DEG"',
    "Run a VAL-II command or stored program, time-scaled to the run's span.",
    verbs={verb: params for verb, (params, _) in _VERBS.items()},
)
