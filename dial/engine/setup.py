"""Setting a run up: the scene's world and model, the robot at home, the perturbation.

The world model is recorded as the **believed** object poses before ``--perturb`` moves
the true ones, so that only sensing can make up the difference (DESIGN 5).
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np

from dial.backend.disturb import Disturbances
from dial.backend.driver import MujocoRobot
from dial.backend.ik import ArmIK, FingerIK
from dial.backend.locate import FingerContacts, resting_on
from dial.backend.model import (
    RobotIndex,
    finger_bodies,
    load_model,
    profile_at,
    rest_hand,
    scene_bodies,
)
from dial.disturb import Disturbance
from dial.geometry import Pose, location_pose, rpy_matrix
from dial.parser.script import Script
from dial.primitives.context import Context
from dial.robot.snapshot import Snapshot
from dial.scene.belief import Beliefs, Feeling, initial
from dial.scene.of_script import script_world
from dial.scene.resolve import bundled_name
from dial.scene.thread import set_turns
from dial.scene.world import World
from dial.scheduler.log import EventLog
from dial.scheduler.primitive import Primitive, Sensor
from dial.scheduler.types import RunInfo

SETTLE_S = 0.5  # objects settle on the table before the script starts
# Where the tool starts when the world file has no "home" location: high above the tables,
# pointing down (world m; rpy as in world files).
START = ((0.40, 0.0, 0.80), (np.pi, 0.0, 0.0))


def perturb(model: mujoco.MjModel, world: World, mm: float, seed: int) -> list[float]:
    """Shift the scene's objects by ``mm`` in a seeded horizontal direction; the shift in m.

    It moves the model (a free body's initial position, a fixed object's position), before
    any ``MjData`` is made from it: with sleeping on, MuJoCo places a fixed body only once,
    when the data is made.
    """
    if mm <= 0:
        return [0.0, 0.0, 0.0]
    angle = np.random.default_rng(seed).uniform(0.0, 2.0 * np.pi)
    shift = np.array([np.cos(angle), np.sin(angle), 0.0]) * mm / 1000.0
    for body in scene_bodies(model, world):
        joint = int(model.body_jntadr[body])
        if joint >= 0 and model.jnt_type[joint] == mujoco.mjtJoint.mjJNT_FREE:
            adr = int(model.jnt_qposadr[joint])
            model.qpos0[adr : adr + 3] += shift
        elif model.body_parentid[body] == 0 and model.body_jntnum[body] == 0:
            model.body_pos[body] += shift
    return [float(x) for x in shift]


def prepare(
    script: Script,
    log: EventLog,
    perturb_mm: float = 0.0,
    seed: int = 0,
    disturbances: Sequence[Disturbance] = (),
    textures: bool = True,
    follow: bool = True,
) -> tuple[MujocoRobot, Context]:
    """Load the scene, place the robot at home, perturb, settle; log the ``scene`` record.

    ``textures=False``: compile the scene without its textures (a run that nothing draws;
    the physics is the same to the bit, and the compile is a fifth of the time).
    ``follow=False``: grasped objects do not follow the hand in the world model."""
    world = script_world(script)
    profile = profile_at(world.robot)
    model = load_model(world.model_path, profile, textures=textures)
    set_turns(model, world)
    placed = Disturbances.on(model, disturbances)  # an unknown body fails before anything moves
    index = RobotIndex.from_model(model, profile)
    unmoved = mujoco.MjData(model)
    mujoco.mj_forward(model, unmoved)
    at_load: dict[str, Pose] = {
        model.body(b).name: (unmoved.xpos[b].copy(), unmoved.xmat[b].reshape(3, 3).copy())
        for b in scene_bodies(model, world)
    }
    believed, sizes = initial(world, at_load)
    shift = perturb(model, world, perturb_mm, seed)
    data = mujoco.MjData(model)
    ik = ArmIK(profile=profile)
    if "home" in world.locations:
        pos, rot = location_pose(world, believed, "home")
    else:
        pos, rot = np.array(START[0]), rpy_matrix(START[1])
    home = ik.solve(pos, rot, np.array(profile.arm.home), "the start pose (location 'home')")
    data.qpos[index.arm_qpos] = home
    data.ctrl[index.arm_actuators] = home
    rest_hand(model, data, index)
    mujoco.mj_forward(model, data)
    for _ in range(round(SETTLE_S / model.opt.timestep)):
        mujoco.mj_step(model, data)
    # A bundled world by its name as a file ("pour.toml", "allegro_panda/pour.toml");
    # another by its absolute path, so that dial replay finds it from anywhere.
    bundled = bundled_name(world.path)
    where = f"{bundled}.toml" if bundled else str(world.path)
    log.write("scene", scene=world.name, world=where, perturb=shift, seed=seed)
    robot = MujocoRobot(model, data, disturbances=placed, profile=profile)
    beliefs = Beliefs(world, believed, sizes, follow=follow, feeling=feeling(robot))
    fik = FingerIK(ik.model, profile)
    return robot, Context(robot, robot.view, world, believed, ik, fik, beliefs=beliefs)


def feeling(robot: MujocoRobot) -> Feeling:
    """What the world model asks of the physics: which fingers touch an object, what rests
    on one (:mod:`dial.backend.locate`), and the time."""
    m, d = robot.model, robot.data
    links = [finger_bodies(m, f.joints) for f in robot.index.profile.fingers]
    return Feeling(
        FingerContacts(m, d, links).count,
        lambda body: resting_on(m, d, body),
        lambda: robot.time,
    )


class Factory:
    """The runner's primitive factory on a robot: each run's primitive or sensor, as its
    event's record declares it (``Args.primitive``, ``Args.sensor``). Before each, the world
    model carries what the hand holds to where the tool is, and lets go of what the fingers
    no longer touch (nothing to do while nothing is held)."""

    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx

    def primitive(self, info: RunInfo) -> Primitive[Snapshot]:
        self.ctx.refresh()
        return info.event.args.primitive(self.ctx, info.allotment)

    def sensor(self, info: RunInfo) -> Sensor[Snapshot]:
        self.ctx.refresh()
        return info.event.args.sensor(self.ctx)
