"""``fit_plane [SET] [object=OBJECT]`` and ``fit_superquadric [SET] [object=OBJECT]``:
least-squares fits to a point set (:mod:`dial.haptics`); their results (normal, residual,
extents; size, shape exponents and pose) go to the log and the summary. With ``object=``, the
fit is also what the world model believes of that object (:mod:`dial.scene.belief`).

Sensed by :class:`dial.primitives.sensing.Fit`; the preview has them ``done``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from dial.instructions.base import Args, Instruction, ParamSpec, Values
from dial.instructions.types import Name

if TYPE_CHECKING:
    from dial.preview.moves import PreviewMove
    from dial.primitives.context import Context
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Sensor

_SET = ParamSpec("set", Name("set"), "contacts", positional=True)
_OBJECT = ParamSpec[str | None](
    "object",
    Name("object"),
    None,
    doc="the object the points lie on: the fit becomes its believed pose and size",
)


@dataclass(frozen=True)
class _FitArgs(Args):
    """``set``: the point set fitted; ``object``: the alias of the object it measures (None:
    the world model learns nothing from it)."""

    set: str
    object: str | None

    def preview(self) -> PreviewMove:
        from dial.preview.moves import Sensed

        return Sensed()


@dataclass(frozen=True)
class FitPlaneArgs(_FitArgs):
    def sensor(self, ctx: Context) -> Sensor[Snapshot]:
        from dial.haptics import fit_plane
        from dial.primitives.sensing import Fit

        return Fit(ctx, self.set, fit_plane, self.object)


@dataclass(frozen=True)
class FitSuperquadricArgs(_FitArgs):
    def sensor(self, ctx: Context) -> Sensor[Snapshot]:
        from dial.haptics import fit_superquadric
        from dial.primitives.sensing import Fit

        return Fit(ctx, self.set, fit_superquadric, self.object)


def _fit(name: str, args: type[_FitArgs], summary: str) -> Instruction:
    def build(v: Values) -> Args:
        return args(v[_SET], v[_OBJECT])

    usage = f"{name} [SET] [object=OBJECT]"
    return Instruction(name, "zero", (_SET, _OBJECT), build, usage, summary, sensing=True)


FIT_PLANE = _fit(
    "fit_plane",
    FitPlaneArgs,
    "Least-squares plane through a point set: normal, residual, extents.",
)
FIT_SUPERQUADRIC = _fit(
    "fit_superquadric",
    FitSuperquadricArgs,
    "Least-squares superquadric through a point set: size, shape exponents, pose.",
)
