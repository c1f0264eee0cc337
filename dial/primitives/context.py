"""What every primitive shares: the robot, the world model, IK and the run's results."""

from __future__ import annotations

from dataclasses import dataclass, field

from dial.backend.driver import MujocoRobot
from dial.backend.ik import ArmIK, FingerIK
from dial.backend.slots import Slots
from dial.backend.snapshot import FloatArray, Snapshot
from dial.geometry import Pose, location_pose
from dial.scene.world import World
from dial.scheduler.types import Ended, Outcome, Primitive, RunInfo


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
    believed: dict[str, Pose]
    arm_ik: ArmIK = field(default_factory=ArmIK)
    finger_ik: FingerIK = field(default_factory=FingerIK)
    point_sets: dict[str, list[list[float]]] = field(default_factory=dict)
    # finger -> where it touched when the latest guarded move sensing it stopped on contact
    stops: dict[int, StopContact] = field(default_factory=dict)
    results: dict[str, dict[str, object]] = field(default_factory=dict)

    def location(self, name: str) -> Pose:
        return location_pose(self.world, self.believed, name)


class RobotPrimitive(Primitive[Snapshot]):
    """A primitive on the MuJoCo robot: its run, arguments and command slots."""

    def __init__(self, ctx: Context, info: RunInfo) -> None:
        self.ctx, self.info = ctx, info
        self.args = info.event.args
        self.slots = Slots(ctx.robot, info.event.effectors)

    def arg(self, name: str) -> object:
        return self.args[name]

    def num(self, name: str) -> float:
        """A bound numeric argument (SI units)."""
        value = self.args[name]
        assert isinstance(value, int | float), f"{name} is bound as a number"
        return float(value)


def done(**data: object) -> Ended:
    return Ended(Outcome.DONE, data=data)


def missed(message: str, **data: object) -> Ended:
    return Ended(Outcome.MISSED, message, data)
