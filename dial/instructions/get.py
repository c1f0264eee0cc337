"""``get_joints``, ``get_forces``, ``get_tactile``, ``get_wrist``: record a snapshot (the
paper's GET JOINTS, GET FORCES, GET TACTILE and GET WRIST).

Zero-length sensing instructions without parameters. Each records part of the snapshot
into the run log and the event's result (:class:`dial.primitives.sensing.Get`); the
preview has them ``done``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from dial.instructions.base import Args, Instruction, Values

if TYPE_CHECKING:
    from dial.preview.moves import PreviewMove
    from dial.primitives.context import Context
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Sensor


@dataclass(frozen=True)
class _GetArgs(Args):
    """A ``get_*`` event: no arguments; :meth:`read` says what it records."""

    def read(self, snapshot: Snapshot) -> dict[str, object]:
        raise NotImplementedError

    def sensor(self, ctx: Context) -> Sensor[Snapshot]:
        from dial.primitives.sensing import Get

        return Get(self.read)

    def preview(self) -> PreviewMove:
        from dial.preview.moves import Sensed

        return Sensed()


@dataclass(frozen=True)
class GetJointsArgs(_GetArgs):
    """Records ``hand_q`` (16 hand joint angles, rad, mask order) and ``arm_q`` (6, rad)."""

    def read(self, snapshot: Snapshot) -> dict[str, object]:
        return {"hand_q": snapshot.hand_q, "arm_q": snapshot.arm_q}


@dataclass(frozen=True)
class GetForcesArgs(_GetArgs):
    """Records ``tensions``: the 32 tendon tensions (N, tendon order)."""

    def read(self, snapshot: Snapshot) -> dict[str, object]:
        return {"tensions": snapshot.tensions}


@dataclass(frozen=True)
class GetTactileArgs(_GetArgs):
    """Records ``tactile``: the 4 x 16 x 16 fingertip taxel depths (m)."""

    def read(self, snapshot: Snapshot) -> dict[str, object]:
        return {"tactile": snapshot.tactile}


@dataclass(frozen=True)
class GetWristArgs(_GetArgs):
    """Records the tool (wrist) pose: ``pos`` (3,) m and ``rot`` (3, 3)."""

    def read(self, snapshot: Snapshot) -> dict[str, object]:
        return {"pos": snapshot.tool_pos, "rot": snapshot.tool_rot}


def _get(name: str, args: type[_GetArgs], summary: str) -> Instruction:
    def build(values: Values) -> Args:
        return args()

    return Instruction(name, "zero", (), build, name, summary, sensing=True)


GET_JOINTS = _get("get_joints", GetJointsArgs, "Record the 16 hand joint angles.")
GET_FORCES = _get("get_forces", GetForcesArgs, "Record the 32 tendon tensions.")
GET_TACTILE = _get("get_tactile", GetTactileArgs, "Record the 4x16x16 fingertip taxels.")
GET_WRIST = _get("get_wrist", GetWristArgs, "Record the wrist (tool) pose.")
