"""``hand_pose "NAME" [fingers=MASK]``: move the hand to a named pose (GOTO MOVE, or
TRAJECTORY MOVE for ``#===``).

Runs :class:`dial.primitives.hand.HandPose`; the preview steps it and checks that every
joint the pose sets is inside its range (:func:`dial.preview.checks.hand_pose`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from dial.instructions.base import Args, Instruction, ParamSpec, Values
from dial.instructions.scene_names import SceneNames
from dial.instructions.types import ALL_JOINTS, Mask, Name, mask_fingers

if TYPE_CHECKING:
    from dial.preview.moves import Making, PreviewMove
    from dial.primitives.context import Context
    from dial.primitives.hand import HandPose
    from dial.robot.snapshot import Snapshot
    from dial.scheduler.primitive import Allotment, Primitive

_POSE = ParamSpec("pose", Name("pose"), positional=True, doc="named hand pose")
_FINGERS = ParamSpec[int | None](
    "fingers", Mask(), None, doc="only these joints (default: the pose's)"
)


@dataclass(frozen=True)
class HandPoseArgs(Args):
    """``pose``: a hand pose of the world file; ``fingers``: a joint mask (bit 4*f + j) that
    limits the joints it sets (None: all the pose sets)."""

    pose: str
    fingers: int | None

    def effectors(self, scene: SceneNames | None) -> frozenset[str]:
        mask = self.fingers
        if mask is None:
            known = scene.poses.get(self.pose) if scene is not None else None
            mask = known if known is not None else ALL_JOINTS
        return mask_fingers(mask)

    def primitive(self, ctx: Context, allotted: Allotment) -> Primitive[Snapshot]:
        return self._primitive(ctx, allotted)

    def _primitive(self, ctx: Context, allotted: Allotment) -> HandPose:
        from dial.primitives.hand import HandPose

        mask = self.fingers if self.fingers is not None else ALL_JOINTS
        return HandPose(ctx, allotted, self.pose, mask)

    def preview(self) -> PreviewMove:
        from dial.preview.checks import hand_pose
        from dial.preview.moves import Stepped

        def make(m: Making) -> HandPose:
            return self._primitive(m.ctx, m.allotted)

        return Stepped(make, counts=lambda prim: (0, 1), started=hand_pose)


def _build(v: Values) -> HandPoseArgs:
    return HandPoseArgs(v[_POSE], v[_FINGERS])


HAND_POSE = Instruction(
    "hand_pose",
    "fixed",
    (_POSE, _FINGERS),
    _build,
    'hand_pose "NAME" [fingers=MASK]',
    "Move the hand to a named pose (GOTO MOVE or TRAJECTORY MOVE).",
)
