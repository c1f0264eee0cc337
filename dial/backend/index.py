"""A robot's parts in one compiled model, found once by the names its profile gives.

:class:`RobotIndex` turns the ``robot.toml`` names (``dial.robots.profile``) into the
addresses the engine uses every physics step (qpos, dof, actuator and sensordata indices), so
hot loops index numpy arrays instead of looking names up. Hand orders are mask order: bit
``k = 4*f + j`` is joint ``j`` of finger ``f``. A hand whose fingers have fewer than four
joints leaves bits unused: ``hand_bits`` lists the bits it has, in order, and the per-joint
arrays (``hand_qpos``, ``hand_dof``, ``hand_actuators``) follow it.
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

from dial.errors import DialError
from dial.robots.profile import RobotProfile, default_profile

IntArray = NDArray[np.intp]
FloatArray = NDArray[np.float64]
HAND_BITS = 16  # the masks' width: at most 4 fingers of 4 joints


class ModelError(DialError, KeyError):
    """A model that lacks a part of the robot dial drives (a scene without the hand, say)."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0])


def _ids(model: mujoco.MjModel, kind: mujoco.mjtObj, names: tuple[str, ...]) -> IntArray:
    ids = np.array([mujoco.mj_name2id(model, kind, name) for name in names], dtype=np.intp)
    missing = [name for name, i in zip(names, ids, strict=True) if i < 0]
    if missing:
        what = kind.name.removeprefix("mjOBJ_").lower()
        raise ModelError(f"the model has no {what} {', '.join(missing)} of dial's robot")
    ids.flags.writeable = False
    return ids


def _frozen(values: ArrayLike) -> IntArray:
    array = np.asarray(values, dtype=np.intp)
    array.flags.writeable = False
    return array


def _sensor_on(model: mujoco.MjModel, kind: mujoco.mjtSensor, targets: IntArray) -> IntArray:
    """sensordata addresses of the ``kind`` sensors on ``targets`` (joints or actuators)."""
    adrs = []
    for target in targets:
        hits = np.flatnonzero((model.sensor_type == int(kind)) & (model.sensor_objid == target))
        if len(hits) == 0:
            name = mujoco.mjtSensor(int(kind)).name.removeprefix("mjSENS_").lower()
            raise ModelError(f"the model has no {name} sensor for part {int(target)} of the hand")
        adrs.append(int(model.sensor_adr[hits[0]]))
    return _frozen(adrs)


@dataclass(frozen=True, eq=False)
class RobotIndex:
    """Addresses of a robot's parts in one compiled model (the robot alone or a scene).

    Every array is read-only. ``n`` below is the number of hand joints (16 on a 4 x 4 hand).
    """

    profile: RobotProfile
    """What the addresses were looked up from."""
    arm_qpos: IntArray
    """(arm joints,) qpos addresses, base to flange."""
    arm_dof: IntArray
    """(arm joints,) dof addresses."""
    arm_actuators: IntArray
    """(arm joints,) ids of the arm position servos; their control is the joint angle (rad)."""
    hand_bits: IntArray
    """(n,) the mask bit of each hand joint, ascending."""
    hand_qpos: IntArray
    """(n,) qpos addresses of the hand joints, mask order."""
    hand_dof: IntArray
    """(n,) dof addresses of the hand joints, mask order."""
    hand_actuators: IntArray
    """(n,) the joints' position servos (load sensing ``actuator``/``joint``), else empty."""
    tendon_actuators: IntArray
    """(2n,) a tendon hand's actuators: 2k flexor, 2k+1 extensor of hand joint k; else empty."""
    load_sensors: IntArray
    """sensordata addresses of the load sensors: (2n,) tendon tensions in tendon order, or
    (n,) joint torques; empty when the load is the servos' force."""
    tactile_sensors: IntArray
    """(fingers,) sensordata addresses of the fingertip arrays (depths first), -1: none."""
    tool_site: int
    """Site id of the tool frame."""
    fingertip_sites: IntArray
    """(fingers,) site ids of the fingertips, finger order."""
    lever: float
    """m: a joint's load (N m) over this is its load in N (a tendon hand: its moment arm)."""
    load_limit: float
    """The largest tension (N) or joint torque (N m) a hand drive exerts."""

    @property
    def full_hand(self) -> bool:
        """Every one of the 16 mask bits is a joint (4 fingers of 4 joints)."""
        return len(self.hand_bits) == HAND_BITS

    @property
    def tendons(self) -> bool:
        return self.profile.hand.load == "tendon"

    @classmethod
    def from_model(cls, model: mujoco.MjModel, profile: RobotProfile | None = None) -> RobotIndex:
        """Look up the profile's names (the default robot's when None); raise
        :class:`ModelError` naming the parts the model lacks."""
        if profile is None:
            profile = default_profile()
        joint, actuator, site = (
            mujoco.mjtObj.mjOBJ_JOINT,
            mujoco.mjtObj.mjOBJ_ACTUATOR,
            mujoco.mjtObj.mjOBJ_SITE,
        )
        arm = _ids(model, joint, profile.arm.joints)
        names = [j for f in profile.fingers for j in f.joints]
        bits = [4 * f + j for f, g in enumerate(profile.fingers) for j in range(len(g.joints))]
        hand = _ids(model, joint, tuple(names))
        tendon = profile.hand.load == "tendon"
        servos = _ids(model, actuator, tuple(s for f in profile.fingers for s in f.servos))
        pairs = (zip(f.flexors, f.extensors, strict=True) for f in profile.fingers)
        tendons = _ids(model, actuator, tuple(a for finger in pairs for p in finger for a in p))
        drives = tendons if tendon else servos
        if profile.hand.load == "tendon":
            load = _sensor_on(model, mujoco.mjtSensor.mjSENS_ACTUATORFRC, tendons)
        elif profile.hand.load == "joint":
            load = _sensor_on(model, mujoco.mjtSensor.mjSENS_JOINTACTFRC, hand)
        else:
            load = _frozen([])
        return cls(
            profile=profile,
            arm_qpos=_frozen(model.jnt_qposadr[arm]),
            arm_dof=_frozen(model.jnt_dofadr[arm]),
            arm_actuators=_ids(model, actuator, profile.arm.servos),
            hand_bits=_frozen(bits),
            hand_qpos=_frozen(model.jnt_qposadr[hand]),
            hand_dof=_frozen(model.jnt_dofadr[hand]),
            hand_actuators=servos,
            tendon_actuators=tendons,
            load_sensors=load,
            tactile_sensors=_tactile(model, profile),
            tool_site=int(_ids(model, site, (profile.arm.tool_site,))[0]),
            fingertip_sites=_ids(model, site, tuple(f.tip_site for f in profile.fingers)),
            lever=profile.hand.lever,
            load_limit=float(np.abs(model.actuator_forcerange[drives]).max()),
        )


def _tactile(model: mujoco.MjModel, profile: RobotProfile) -> IntArray:
    rows, cols = profile.hand.taxels
    adrs = []
    for finger in profile.fingers:
        if finger.tactile is None:
            adrs.append(-1)
            continue
        s = _ids(model, mujoco.mjtObj.mjOBJ_SENSOR, (finger.tactile,))[0]
        if model.sensor_dim[s] != 3 * rows * cols:  # depth and two sliding speeds per taxel
            raise ModelError(f"tactile sensor {finger.tactile} must have {rows}x{cols} taxels")
        adrs.append(int(model.sensor_adr[s]))
    return _frozen(adrs)
