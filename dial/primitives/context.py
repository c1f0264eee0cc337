"""What every primitive shares: the robot, the world model, IK and the run's results."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from dial.backend.driver import MujocoRobot, Slots
from dial.backend.ik import ArmIK, FingerIK
from dial.backend.snapshot import FloatArray
from dial.errors import DialError
from dial.scene.world import Location, World
from dial.scheduler.types import Ended, Outcome, Primitive, RunInfo


def rpy_matrix(rpy: tuple[float, float, float]) -> FloatArray:
    """R = Rz(yaw) Ry(pitch) Rx(roll), fixed axes."""
    (cr, sr), (cp, sp), (cy, sy) = ((np.cos(a), np.sin(a)) for a in rpy)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def location_pose(
    world: World, believed: dict[str, tuple[FloatArray, FloatArray]], name: str
) -> tuple[FloatArray, FloatArray]:
    """A named location's tool pose in the world: position (3,), rotation (3, 3).

    An object-relative location follows the object's *believed* pose.
    """
    loc: Location = world.locations[name]
    pos, rot = np.array(loc.pos, dtype=np.float64), rpy_matrix(loc.rpy)
    if loc.body is None:
        return pos, rot
    body_pos, body_rot = believed[loc.body]
    if loc.axes == "world":
        return body_pos + pos, rot
    return body_pos + body_rot @ pos, body_rot @ rot


@dataclass(frozen=True)
class StopContact:
    """Where a finger touched when a guarded move stopped on its contact (world m).

    ``tactile``: the taxel centroid, None when the array felt nothing (the contact was on
    the cap or a phalanx); ``link``: the contact point of the finger's links, None when they
    touched nothing outside the robot. See :mod:`dial.backend.locate`.
    """

    tactile: FloatArray | None
    link: FloatArray | None


@dataclass
class Context:
    """Shared by the primitives of one run.

    ``believed`` holds each object's pose as the world model believes it
    (position (3,), rotation (3, 3)); with ``--perturb`` the true pose in the
    physics differs, and only sensing can make up the difference.
    """

    robot: MujocoRobot
    world: World
    believed: dict[str, tuple[FloatArray, FloatArray]]
    arm_ik: ArmIK = field(default_factory=ArmIK)
    finger_ik: FingerIK = field(default_factory=FingerIK)
    point_sets: dict[str, list[list[float]]] = field(default_factory=dict)
    # finger -> where it touched when the latest guarded move sensing it stopped on contact
    stops: dict[int, StopContact] = field(default_factory=dict)
    results: dict[str, dict[str, Any]] = field(default_factory=dict)

    def location(self, name: str) -> tuple[FloatArray, FloatArray]:
        return location_pose(self.world, self.believed, name)


class RobotPrimitive(Primitive):
    """A primitive on the MuJoCo robot: its run, arguments and command slots."""

    def __init__(self, ctx: Context, info: RunInfo) -> None:
        self.ctx, self.info = ctx, info
        self.args = info.event.args
        self.slots = Slots(ctx.robot, info.event.effectors)

    def arg(self, name: str) -> Any:
        return self.args[name]


def done(**data: Any) -> Ended:
    return Ended(Outcome.DONE, data=data)


def missed(message: str, **data: Any) -> Ended:
    return Ended(Outcome.MISSED, message, data)


class PrimitiveError(DialError):
    """A run that cannot go on; it ends ``error`` with this message."""
