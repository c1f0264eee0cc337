"""What every primitive shares: the robot, the world model, IK and the run's results."""

from __future__ import annotations

from dataclasses import dataclass, field

from dial.backend.driver import MujocoRobot
from dial.backend.ik import ArmIK, FingerIK
from dial.backend.locate import fingers_touching, resting_on
from dial.backend.slots import Slots
from dial.backend.snapshot import FloatArray, Snapshot
from dial.geometry import Pose, location_pose
from dial.scene.belief import Beliefs
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
    physics differs, and only sensing can make up the difference. ``beliefs`` is the
    world model around it (sizes, held objects, the log of its changes:
    :mod:`dial.scene.belief`).
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
    beliefs: Beliefs | None = None  # made from world and believed when not given

    def __post_init__(self) -> None:
        if self.beliefs is None:
            self.beliefs = Beliefs(self.world, self.believed)

    @property
    def world_model(self) -> Beliefs:
        """The world model (``beliefs``, always set after construction)."""
        assert self.beliefs is not None
        return self.beliefs

    def location(self, name: str) -> Pose:
        """A location's tool pose, relative objects where the world model believes them now
        (a held one where the tool has carried it)."""
        self.refresh(self.robot.time)
        return location_pose(self.world, self.believed, name)

    def tool(self) -> Pose:
        """The commanded tool pose: where the planner starts the next motion from."""
        return self.arm_ik.fk(self.robot.arm_target)

    def touching(self, body: str, fingers: tuple[int, ...]) -> int:
        """How many of ``fingers`` touch the object ``body`` now."""
        return fingers_touching(self.robot.model, self.robot.data, body, fingers)

    def resting(self, body: str) -> tuple[str, ...]:
        """The bodies resting on the object ``body`` now."""
        return resting_on(self.robot.model, self.robot.data, body)

    def refresh(self, t: float) -> None:
        """Carry the held objects to where the tool is, releasing those let go of."""
        if self.world_model.held:
            self.world_model.update(self.tool(), self.touching, t)


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
