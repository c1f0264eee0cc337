"""The teaching session's simulation: the scene at home, stepped one control period at a time.

The session owns its physics (no scheduler): every command moves set-points over a short
time, then lets the scene settle, so limp fingers come to rest on what they touch and objects
come to rest where they were pushed. A motion that collides is undone: the whole physics
state from before it is restored (:meth:`Sim.state`, :meth:`Sim.restore`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import mujoco
import numpy as np

from dial.backend.driver import MujocoRobot
from dial.backend.ik import ArmIK, FingerIK
from dial.backend.model import (
    RobotIndex,
    hand_actuators,
    hand_angles,
    hand_ctrl,
    load_model,
    profile_at,
    rest_hand,
)
from dial.geometry import location_pose, rpy_matrix, smooth
from dial.primitives.arm import Segment
from dial.primitives.context import Context
from dial.robot.snapshot import FloatArray
from dial.scene.belief import Beliefs, initial
from dial.scene.thread import find_threads, set_turns
from dial.scene.world import World
from dial.teach.contacts import Parts, collision

CONTROL_PERIOD = 0.01  # s: set-points change once per period, as in `dial run`
START_SETTLE_S = 0.5  # s: the objects settle on the table before the first command
SETTLE_S = 0.3  # s after every command: limp fingers and pushed objects come to rest
HAND_SPEED = 2.0  # rad/s: how fast a finger command moves the joints' set-points
MIN_MOTION_S = 0.1  # s: the shortest motion, so that a small step is still smooth
# Where the tool starts when the world file has no "home" location (as `dial run` does).
START = ((0.40, 0.0, 0.80), (math.pi, 0.0, 0.0))
_STATE = mujoco.mjtState.mjSTATE_INTEGRATION
_DIVERGENCE = (
    mujoco.mjtWarning.mjWARN_BADQACC,
    mujoco.mjtWarning.mjWARN_BADQPOS,
    mujoco.mjtWarning.mjWARN_BADQVEL,
)


Pose3 = tuple[FloatArray, FloatArray]  # a tool pose: position (3,) m, rotation (3, 3)


class Collision(Exception):
    """A motion was stopped; the state before it is restored. The message says why."""


@dataclass(frozen=True)
class State:
    """Everything :meth:`Sim.restore` needs to go back: physics, set-points, limp joints."""

    physics: FloatArray
    arm_target: FloatArray
    hand_target: FloatArray
    limp: np.ndarray


def believed_poses(
    model: mujoco.MjModel, data: mujoco.MjData, world: World
) -> dict[str, tuple[FloatArray, FloatArray]]:
    """Each world object's believed pose (body name -> position (3,), rotation (3, 3)): where
    ``data`` has it, unless the world file says otherwise (:func:`dial.scene.belief.initial`)."""
    out = {}
    for body in world.objects.values():
        b = model.body(body).id
        out[body] = (data.xpos[b].copy(), data.xmat[b].reshape(3, 3).copy())
    return initial(world, out)[0]


def home_pose(world: World, believed: dict[str, tuple[FloatArray, FloatArray]]) -> Pose3:
    """The tool pose the scene starts at: its ``home`` location, else high above the tables."""
    if "home" in world.locations:
        return location_pose(world, believed, "home")
    return np.array(START[0]), rpy_matrix(START[1])


class Sim:
    """One scene's model and data, the robot at its world's ``home``, objects settled."""

    def __init__(self, world: World, settle: bool = True) -> None:
        self.world = world
        profile = profile_at(world.robot)
        self.model = model = load_model(world.model_path, profile)
        set_turns(model, world)
        self.data = data = mujoco.MjData(model)
        self.index = ix = RobotIndex.from_model(model, profile)
        self.parts = Parts.of(model, ix)
        self.threads = find_threads(model)
        self.substeps = max(1, round(CONTROL_PERIOD / model.opt.timestep))
        mujoco.mj_forward(model, data)
        believed = believed_poses(model, data, world)
        self.ik = ArmIK(profile=profile)
        pos, rot = self.start_pose = home_pose(world, believed)
        home = np.array(profile.arm.home)
        q = self.ik.solve(pos, rot, home, "the start pose (location 'home')")
        data.qpos[ix.arm_qpos] = q
        rest_hand(model, data, ix)
        self.arm_target = q.copy()
        self.hand_target = hand_angles(data, ix)
        self.limp = np.zeros(16, dtype=bool)
        self.on_period: Callable[[], None] | None = None  # a live viewer's update
        self._apply()
        mujoco.mj_forward(model, data)
        # The planner of `dial run` reads the world, the IK and the joint ranges from here.
        robot = MujocoRobot(model, data, profile=profile)
        beliefs = Beliefs(world, believed, initial(world, believed)[1])
        fik = FingerIK(profile=profile)
        self.ctx = Context(robot, robot.view, world, believed, self.ik, fik, beliefs=beliefs)
        self.arm_range = robot.view.arm_range  # (arm joints, 2) rad
        self.hand_range = robot.view.hand_range  # (16, 2) rad, mask order
        if settle:
            self.run_for(START_SETTLE_S)

    # -- state ----------------------------------------------------------------------------------
    def state(self) -> State:
        physics = np.empty(mujoco.mj_stateSize(self.model, _STATE))
        mujoco.mj_getState(self.model, self.data, physics, _STATE)
        return State(physics, self.arm_target.copy(), self.hand_target.copy(), self.limp.copy())

    def restore(self, state: State) -> None:
        mujoco.mj_setState(self.model, self.data, state.physics, _STATE)
        self.arm_target = state.arm_target.copy()
        self.hand_target = state.hand_target.copy()
        self.limp = state.limp.copy()
        for w in _DIVERGENCE:
            self.data.warning[w].number = 0
        mujoco.mj_forward(self.model, self.data)

    # -- reading --------------------------------------------------------------------------------
    @property
    def time(self) -> float:
        return float(self.data.time)

    def arm_q(self) -> FloatArray:
        return np.array(self.data.qpos[self.index.arm_qpos])

    def hand_q(self) -> FloatArray:
        return hand_angles(self.data, self.index)

    def tool(self) -> tuple[FloatArray, FloatArray]:
        """The measured tool pose: the tool site's position (3,) m and rotation (3, 3)."""
        site = self.index.tool_site
        return self.data.site_xpos[site].copy(), self.data.site_xmat[site].reshape(3, 3).copy()

    def body_pose(self, body: str) -> tuple[FloatArray, FloatArray]:
        """A body's current (true) pose: position (3,) m and rotation (3, 3)."""
        b = self.model.body(body).id
        return self.data.xpos[b].copy(), self.data.xmat[b].reshape(3, 3).copy()

    # -- stepping -------------------------------------------------------------------------------
    def _apply(self) -> None:
        ix, d = self.index, self.data
        d.ctrl[ix.arm_actuators] = self.arm_target
        d.ctrl[hand_actuators(ix)] = hand_ctrl(
            np.where(self.limp, hand_angles(d, ix), self.hand_target), ix
        )

    def period(self) -> None:
        """One control period: apply the set-points, step the physics."""
        self._apply()
        m, d = self.model, self.data
        if not self.threads:
            mujoco.mj_step(m, d, nstep=self.substeps)
        else:
            for _ in range(self.substeps):  # a thread is released after the step it lets go
                mujoco.mj_step(m, d)
                for thread in self.threads:
                    thread.update(d)
        if self.on_period is not None:
            self.on_period()

    def run_for(self, seconds: float) -> None:
        for _ in range(round(seconds / CONTROL_PERIOD)):
            self.period()

    def _checked(self, periods: Iterable[None]) -> None:
        """Run a motion's periods and a settle, checking each period; undo it on a collision."""
        before = self.state()
        try:
            for _ in periods:
                self._check()
            for _ in range(round(SETTLE_S / CONTROL_PERIOD)):
                self.period()
                self._check()
            blocked = np.abs(self.arm_q() - self.arm_target).max()
            if blocked > math.radians(1.0):
                raise Collision(f"the arm is blocked {math.degrees(blocked):.1f} deg short")
        except (Collision, KeyboardInterrupt):  # Ctrl-C at a terminal stops the motion too
            self.restore(before)
            raise

    def _check(self) -> None:
        for w in _DIVERGENCE:
            if self.data.warning[w].number:
                raise Collision("the physics diverged")
        problem = collision(self.model, self.data, self.parts)
        if problem is not None:
            raise Collision(problem)

    # -- motions --------------------------------------------------------------------------------
    def move_arm(self, segments: list[Segment]) -> None:
        """Follow planned arm segments (each smoothly, at the planner's nominal speeds)."""

        def periods() -> Iterable[None]:
            for seg in segments:
                n = max(1, math.ceil(max(seg.cost, MIN_MOTION_S) / CONTROL_PERIOD))
                for k in range(1, n + 1):
                    self.arm_target = seg.at(smooth(k / n))
                    self.period()
                    yield None

        self._checked(periods())

    def move_hand(self, goal: FloatArray, mask: int) -> None:
        """Move the masked hand joints' set-points to ``goal`` (16,) rad; they stop being limp."""
        bits = [k for k in range(16) if mask >> k & 1]
        start = np.where(self.limp, self.hand_q(), self.hand_target)
        q1 = start.copy()
        q1[bits] = np.asarray(goal)[bits]
        self.limp[bits] = False
        span = float(np.abs(q1 - start).max()) / HAND_SPEED

        def periods() -> Iterable[None]:
            n = max(1, math.ceil(max(span, MIN_MOTION_S) / CONTROL_PERIOD))
            for k in range(1, n + 1):
                self.hand_target = start + (q1 - start) * smooth(k / n)
                self.period()
                yield None

        self._checked(periods())

    def go_limp(self, mask: int, seconds: float) -> None:
        """Make the masked joints back-drivable for ``seconds``, then hold where they came to."""
        bits = [k for k in range(16) if mask >> k & 1]

        def periods() -> Iterable[None]:
            self.limp[bits] = True
            for _ in range(round(seconds / CONTROL_PERIOD)):
                self.period()
                yield None
            self.hand_target[bits] = self.hand_q()[bits]
            self.limp[bits] = False

        self._checked(periods())
