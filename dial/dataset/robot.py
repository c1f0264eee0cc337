"""The one place a dataset reads the robot: joint positions, velocities, load, touch, the
commands applied, and the objects' true poses, with the names of what it reads.

Joint load is read through :meth:`RobotReader.joint_load` and named by
:attr:`RobotNames.load`: tendon tensions on this hand; a hand without tendons (the robot
profiles of issue 24) gives its joint torques here, under its own names.
"""

from __future__ import annotations

from collections.abc import Sequence

import mujoco
import numpy as np

from dial.backend.driver import MujocoRobot
from dial.backend.model import (
    ARM_JOINTS,
    FINGERS,
    HAND_JOINTS,
    TAXEL_SHAPE,
    TENDONS,
    FloatArray,
)
from dial.dataset.features import RobotNames


def robot_names() -> RobotNames:
    """The Utah/MIT hand on the PUMA 560: 6 + 16 joints, 32 tendons, 4 pads of 16x16."""
    return RobotNames(ARM_JOINTS, HAND_JOINTS, TENDONS, FINGERS, TAXEL_SHAPE)


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
        self.load = np.asarray(ix.tension_sensors)
        # The set-points applied: the arm's servos, and each hand joint's flexor (its
        # extensor servos to the same angle, see dial.backend.model.hand_ctrl).
        self.ctrl = np.concatenate([ix.arm_actuators, ix.tendon_actuators[0::2]])
        n = TAXEL_SHAPE[0] * TAXEL_SHAPE[1]
        self.tactile = np.concatenate([np.arange(a, a + n) for a in ix.tactile_sensors])
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
        """Tendon tensions (N), tendon order: the joint load of this hand."""
        return np.asarray(self.data.sensordata[self.load])

    def tactile_depths(self) -> FloatArray:
        """(fingers * rows * cols,) penetration depths (m), finger by finger, row-major."""
        return np.asarray(self.data.sensordata[self.tactile])

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
