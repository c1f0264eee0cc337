"""What every primitive shares: the robot's seam, the world model, IK and the run's results.

Primitives read their snapshot and the read-only :class:`~dial.robot.view.RobotView`, and
write through their :class:`~dial.robot.slots.Slots`; they never see the physics or the
driver (:mod:`dial.robot.protocol`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from dial.geometry import Pose, location_pose
from dial.robot.protocol import ArmKinematics, Commanded, FingerKinematics
from dial.robot.slots import Slots
from dial.robot.snapshot import Snapshot, Touch
from dial.robot.view import RobotView
from dial.scene.belief import Beliefs
from dial.scene.world import World
from dial.scheduler.primitive import Allotment, Ended, Outcome, Primitive


@dataclass
class Context:
    """Shared by the primitives of one run.

    ``robot``: what their slots write (set-points, limp joints, guards); ``view``: what the
    robot is (joint ranges, fingers). ``believed`` holds each object's pose as the world
    model believes it (position (3,), rotation (3, 3)); with ``--perturb`` the true pose in
    the physics differs, and only sensing can make up the difference. ``beliefs`` is the
    world model around it (sizes, held objects, the log of its changes:
    :mod:`dial.scene.belief`); the engine gives it what the fingers touch.
    """

    robot: Commanded
    view: RobotView
    world: World
    believed: dict[str, Pose]
    arm_ik: ArmKinematics
    finger_ik: FingerKinematics
    point_sets: dict[str, list[list[float]]] = field(default_factory=dict)
    # finger -> where it touched when the latest guarded move sensing it stopped on contact
    stops: dict[int, Touch] = field(default_factory=dict)
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
        self.refresh()
        return location_pose(self.world, self.believed, name)

    def tool(self) -> Pose:
        """The commanded tool pose: where the planner starts the next motion from."""
        return self.arm_ik.fk(self.robot.arm_target)

    def refresh(self) -> None:
        """Carry the held objects to where the tool is, releasing those let go of."""
        if self.world_model.held:
            self.world_model.update(self.tool())


class RobotPrimitive(Primitive[Snapshot]):
    """A primitive on a robot: the run's context, allotment and command slots."""

    def __init__(self, ctx: Context, allotted: Allotment) -> None:
        self.ctx, self.allotted = ctx, allotted
        self.slots = Slots(ctx.robot, allotted.effectors)


def done(**data: object) -> Ended:
    return Ended(Outcome.DONE, data=data)


def missed(message: str, **data: object) -> Ended:
    return Ended(Outcome.MISSED, message, data)
