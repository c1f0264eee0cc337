"""``arm_move DX DY DZ [RX RY RZ] [frame=tool|world]``: a relative straight-line move of the
tool.

Runs :class:`dial.primitives.arm.ArmMove`; the preview steps it and checks its plan
(:func:`dial.preview.checks.arm_plan`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from dial.instructions.base import DX, DY, DZ, Args, Instruction, ParamSpec, Values
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import ARM, Choice, Quantity

if TYPE_CHECKING:
    from dial.preview.moves import Making, PreviewMove
    from dial.preview.scene import Scene
    from dial.primitives.arm import ArmMove
    from dial.primitives.context import Context
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Allotment, Primitive

FrameName = Literal["tool", "world"]
_TURN = Quantity("angle", "rad", -6.2832, 6.2832)
RX, RY, RZ = (ParamSpec(n, _TURN, 0.0, positional=True, doc="rotation") for n in ("rx", "ry", "rz"))
_FRAME = ParamSpec("frame", Choice[FrameName](("tool", "world")), "tool")


@dataclass(frozen=True)
class ArmMoveArgs(Args):
    """``dx``, ``dy``, ``dz``: the tool's displacement (m) and ``rx``, ``ry``, ``rz`` its
    rotation (roll, pitch, yaw; rad), in ``frame`` (the tool's, or the world's)."""

    dx: float
    dy: float
    dz: float
    rx: float
    ry: float
    rz: float
    frame: FrameName

    def effectors(self, scene: SceneNames | None) -> frozenset[str]:
        return frozenset({ARM})

    def primitive(self, ctx: Context, allotted: Allotment) -> Primitive[Snapshot]:
        return self._primitive(ctx, allotted)

    def _primitive(self, ctx: Context, allotted: Allotment) -> ArmMove:
        from dial.primitives.arm import ArmMove

        return ArmMove(
            ctx, allotted, (self.dx, self.dy, self.dz), (self.rx, self.ry, self.rz), self.frame
        )

    def preview(self) -> PreviewMove:
        from dial.preview.checks import arm_plan
        from dial.preview.moves import Stepped

        def make(m: Making) -> ArmMove:
            return self._primitive(m.ctx, m.allotted)

        def started(scene: Scene, prim: ArmMove) -> list[str]:
            return arm_plan(scene, prim, ["the arm_move"] * len(prim.segments))

        return Stepped(make, counts=lambda prim: (1, 0), started=started)


def _build(v: Values) -> ArmMoveArgs:
    return ArmMoveArgs(v[DX], v[DY], v[DZ], v[RX], v[RY], v[RZ], v[_FRAME])


ARM_MOVE = Instruction(
    "arm_move",
    "fixed",
    (DX, DY, DZ, RX, RY, RZ, _FRAME),
    _build,
    "arm_move DX DY DZ [RX RY RZ] [frame=tool|world]",
    "Relative straight-line Cartesian move of the tool.",
    positional_counts=(3, 6),
)
