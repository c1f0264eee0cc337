"""The one place a dataset reads the robot: joint positions, velocities, load, touch, the
commands applied, and the objects' true poses, with the names of what it reads.

Everything is named after the robot's profile (``robot.toml``, docs/robots.md). Joint load is
read through :meth:`RobotReader.joint_load` and named by :attr:`RobotNames.load`: the raw load
readings of the profile's ``hand.load``, as :func:`dial.backend.model.tendon_tensions` gives
them: 2 tendon tensions (N) per joint on a tendon hand (flexor, extensor), one joint torque
(N m) per joint on a ``joint`` hand, one servo force per joint on an ``actuator`` hand.
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np

from dial.backend.driver import MujocoRobot
from dial.backend.model import FloatArray, hand_actuators, tendon_tensions
from dial.dataset.features import RobotNames
from dial.robots.profile import RobotProfile

# A torque or servo-force reading is named after its joint: JOINT_torque, JOINT_force.
_LOAD_SUFFIX = {"joint": "torque", "actuator": "force"}


def robot_names(profile: RobotProfile) -> RobotNames:
    """A robot's joints (arm, then hand in mask order), its load readings, its fingers and
    their tactile arrays' size, by the names its profile gives (the Utah/MIT hand on the
    PUMA 560: 6 + 16 joints, 32 tendons, 4 pads of 16x16)."""
    fingers = profile.fingers
    hand = tuple(j for f in fingers for j in f.joints)
    if profile.hand.load == "tendon":
        pairs = (zip(f.flexors, f.extensors, strict=True) for f in fingers)
        load = tuple(name for finger in pairs for pair in finger for name in pair)
    else:
        load = tuple(f"{j}_{_LOAD_SUFFIX[profile.hand.load]}" for j in hand)
    return RobotNames(
        profile.arm.joints,
        hand,
        load,
        tuple(f.name for f in fingers),
        profile.hand.taxels,
        profile.name,
    )


def scene_bodies(objects: Sequence[str]) -> tuple[str, ...]:
    """The distinct bodies of a world's objects (aliases may share one), in the world's order."""
    return tuple(dict.fromkeys(objects))


class RobotReader:
    """Reads one frame's values from a running robot, never writing to it.

    Index arrays are looked up once. Free bodies' poses come from ``qpos`` (current at the
    end of a control period); bodies without a free joint do not move relative to their
    parent's frame, and are read from ``xpos``/``xquat``.
    """

    def __init__(self, robot: MujocoRobot, bodies: Sequence[str]) -> None:
        m, ix = robot.model, robot.index
        self.model, self.data = m, robot.data
        self.qpos = np.concatenate([ix.arm_qpos, ix.hand_qpos])
        self.dof = np.concatenate([ix.arm_dof, ix.hand_dof])
        self.index = ix
        # The set-points applied: the arm's servos, and each hand joint's servo (on a tendon
        # hand its flexor: the extensor servos to the same angle, dial.backend.model.hand_ctrl).
        hand = hand_actuators(ix)
        self.ctrl = np.concatenate([ix.arm_actuators, hand[0::2] if ix.tendons else hand])
        rows, cols = ix.profile.hand.taxels
        n = rows * cols
        # sensordata addresses of every taxel, finger by finger; a finger without a tactile
        # array reads zeros (its slots are left out of ``taxels``).
        have = [f for f, a in enumerate(ix.tactile_sensors) if a >= 0]
        self.taxels = np.concatenate(
            [np.arange(f * n, f * n + n) for f in have] or [np.zeros(0, np.intp)]
        )
        self.tactile = np.concatenate(
            [np.arange(ix.tactile_sensors[f], ix.tactile_sensors[f] + n) for f in have]
            or [np.zeros(0, np.intp)]
        )
        self.touch = np.zeros(len(ix.tactile_sensors) * n)
        self.free: list[tuple[int, int]] = []  # (slot in the pose vector, qpos address)
        self.fixed: list[tuple[int, int]] = []  # (slot, body id)
        for slot, name in enumerate(bodies):
            body = int(mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name))
            joint = int(m.body_jntadr[body])
            if joint >= 0 and m.jnt_type[joint] == mujoco.mjtJoint.mjJNT_FREE:
                self.free.append((slot, int(m.jnt_qposadr[joint])))
            else:
                self.fixed.append((slot, body))
        self.poses = len(bodies)

    def state(self) -> FloatArray:
        return np.asarray(self.data.qpos[self.qpos])

    def velocity(self) -> FloatArray:
        return np.asarray(self.data.qvel[self.dof])

    def joint_load(self) -> FloatArray:
        """The hand's load readings (see the module's doc), in :attr:`RobotNames.load` order."""
        return tendon_tensions(self.data, self.index)

    def tactile_depths(self) -> FloatArray:
        """(fingers * rows * cols,) penetration depths (m), finger by finger, row-major; 0 on
        a finger without a tactile array."""
        self.touch[self.taxels] = self.data.sensordata[self.tactile]
        return self.touch

    def commanded(self) -> FloatArray:
        """The joint set-points applied to the actuators now (rad)."""
        return np.asarray(self.data.ctrl[self.ctrl])

    def environment(self, out: FloatArray) -> None:
        """Write each body's position and quaternion (w, x, y, z) into ``out`` (7 per body)."""
        d = self.data
        for slot, adr in self.free:
            out[7 * slot : 7 * slot + 7] = d.qpos[adr : adr + 7]
        for slot, body in self.fixed:
            out[7 * slot : 7 * slot + 3] = d.xpos[body]
            out[7 * slot + 3 : 7 * slot + 7] = d.xquat[body]
