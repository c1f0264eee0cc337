"""The read-only model view: what a robot is, as primitives and checks may read it.

It holds names and numbers only, no simulator object: the arm's joints and their ranges,
the tool site, and the hand's fingers, each with its joints in mask order, its fingertip
site, its tactile sensor (if any) and its links. A robot profile (a ``robot.toml`` beside
its MJCF) fills the same fields for another hand on another arm; the MuJoCo driver fills
them from its model (:func:`dial.backend.model.robot_view`).

Masks follow the paper: hand joint ``k = 4*f + j`` is joint ``j`` of finger ``f``
(abduction, then flexion from the palm out). A finger with fewer than four joints leaves
its last bits unused.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from dial.robot.snapshot import FloatArray

LoadSensing = Literal["tendon", "actuator", "joint"]


@dataclass(frozen=True)
class FingerView:
    """One finger: ``joints`` (MJCF joint names, mask order), ``tip_site`` (the site the
    fingertip's position is read at), ``tactile`` (the MuJoCo tactile sensor on its pad, or
    None) and ``bodies`` (its links, whose contacts locate a touch off the pad)."""

    name: str
    joints: tuple[str, ...]
    tip_site: str
    tactile: str | None
    bodies: tuple[str, ...]


@dataclass(frozen=True, eq=False)
class RobotView:
    """A robot's parts and limits. Arrays are read-only; angles in rad.

    ``arm_range``: (arm joints, 2) lower and upper limits, in ``arm_joints`` order.
    ``hand_range``: (16, 2), mask order. ``load``: how joint load is sensed (``tendon``:
    flexor minus extensor tension; ``actuator``: actuator force; ``joint``: joint torque).
    ``taxels``: rows and columns of each tactile array.
    """

    name: str
    arm_joints: tuple[str, ...]
    arm_range: FloatArray
    tool_site: str
    fingers: tuple[FingerView, ...]
    hand_range: FloatArray
    load: LoadSensing
    taxels: tuple[int, int]

    def finger(self, f: int) -> FingerView:
        """Finger ``f`` (0-based, mask order)."""
        return self.fingers[f]
