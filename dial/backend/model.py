"""Load a robot (the Utah/MIT hand on the PUMA 560 by default) and read its sensors.

A robot is a folder with its MJCF and a ``robot.toml`` profile (``dial.robots``); a scene
includes the robot's files by name. :class:`~dial.backend.index.RobotIndex` finds the
profile's parts in a compiled model. Orders follow the paper's masks: hand joint
``k = 4*f + j`` with finger ``f`` and joint ``j`` (abduction, then flexion from the palm out);
a tendon hand's actuators ``2*k`` (flexor) and ``2*k + 1`` (extensor). See ``docs/model.md``
and ``docs/robots.md``.
"""

from __future__ import annotations

import copy
import functools
import os
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import ArrayLike

from dial.backend.index import HAND_BITS, FloatArray, IntArray, ModelError, RobotIndex
from dial.errors import DialError
from dial.resources import data_dir
from dial.robot.view import FingerView, RobotView
from dial.robots.profile import RobotProfile, default_profile, load_profile

if TYPE_CHECKING:
    from dial.scene.world import World

__all__ = [
    "ARM_HOME",
    "FloatArray",
    "IntArray",
    "ModelError",
    "RobotIndex",
    "default_profile",
    "hand_angles",
    "hand_ctrl",
    "joint_loads",
    "load_model",
    "rest_hand",
    "scene_bodies",
    "tactile_images",
    "tendon_differentials",
    "tendon_tensions",
]

# The default robot: the one a world file that names none runs on.
ROBOT_DIR = data_dir("models") / "utah_hand_puma"
ROBOT_XML = ROBOT_DIR / "utah_hand_puma.xml"
FINGERS = ("index", "middle", "ring", "thumb")  # its fingers, in mask order
TAXEL_SHAPE = (16, 16)

# Arm configuration (rad) of the default robot with the palm 0.45 m above the floor, 0.55 m in
# front of the base, facing down (tool z = -world z): its profile's home.
ARM_HOME = (0.0, 0.7, -3.26, 0.0, -0.58, 0.0)


@functools.cache
def profile_at(folder: Path) -> RobotProfile:
    """The profile of the robot folder ``folder`` (read once per process)."""
    return load_profile(folder)


def _robot_files(folder: Path) -> dict[str, bytes]:
    # MJCF resolves nested file names against the top-level file's folder; handing MuJoCo the
    # files of the robot folder by name lets a scene anywhere include the robot's files.
    return {path.name: path.read_bytes() for path in folder.glob("*.xml")}


# Compiled models by (path, mtime, textures) once keep_compiled() is called; None: compile
# every time.
_compiled: dict[tuple[str, int, bool], mujoco.MjModel] | None = None


def keep_compiled() -> None:
    """From now on, compile each model file once in this process and hand out copies.

    For a sweep's worker, which runs many trials of one scene: a compile takes about 20 ms,
    a copy 0.5 ms. Each caller gets its own copy (``--perturb`` edits a trial's model), so
    results are the same. The key holds the file's modification time: an edited scene file
    is compiled again, an edited file that it includes is not. Idempotent.
    """
    global _compiled
    if _compiled is None:
        _compiled = {}


def compiled_count() -> int:
    """How many model files this process has compiled since :func:`keep_compiled`."""
    return 0 if _compiled is None else len(_compiled)


def load_model(
    path: str | Path | None = None,
    profile: RobotProfile | None = None,
    *,
    textures: bool = True,
) -> mujoco.MjModel:
    """Compile a robot (the default robot when ``profile`` is None), or a scene XML file that
    includes its files; the profile's servo gains are written into the model's actuators.
    ``textures=False``: without its textures (:func:`load_untextured`)."""
    profile = default_profile() if profile is None else profile
    path = profile.model if path is None else path
    compile_model = _compile if textures else load_untextured
    if _compiled is None:
        return compile_model(path, profile)
    key = (f"{path}|{profile.path}", os.stat(path).st_mtime_ns, textures)
    model = _compiled.get(key)
    if model is None:
        model = _compiled[key] = compile_model(path, profile)
    return copy.copy(model)


def _compile(path: str | Path, profile: RobotProfile) -> mujoco.MjModel:
    try:
        model = mujoco.MjModel.from_xml_path(str(path), _robot_files(profile.folder))
    except ValueError as e:
        raise _compile_error(path, e) from None
    apply_servo(model, RobotIndex.from_model(model, profile))
    return model


def load_untextured(path: str | Path, profile: RobotProfile | None = None) -> mujoco.MjModel:
    """Compile a scene without its textures, for what never draws it (``dial preview``, and
    ``dial run`` with no observer).

    A scene's skybox and floor textures take most of its compile time; without them only the
    textures' fields, the materials' references to them and the name addresses differ: no
    physics reads them (tests/engine/test_textures.py runs a scene both ways, to the bit).
    """
    profile = default_profile() if profile is None else profile
    try:
        spec = mujoco.MjSpec.from_file(str(path), _robot_files(profile.folder))
        for material in spec.materials:
            material.textures = [""] * len(material.textures)
        for texture in list(spec.textures):
            spec.delete(texture)
        model = spec.compile()
    except ValueError as e:
        raise _compile_error(path, e) from None
    apply_servo(model, RobotIndex.from_model(model, profile))
    return model


def _compile_error(path: str | Path, e: ValueError) -> DialError:
    # `dial check` reads the XML without MuJoCo (well-formed, bodies named); what only
    # MuJoCo's compiler finds (a bad attribute value, say) must still reach the user as a line.
    why = "; ".join(line.strip() for line in str(e).splitlines() if line.strip())
    return DialError(f"{path}: MuJoCo cannot compile the model: {why}")


def load_model_from_string(xml: str, profile: RobotProfile | None = None) -> mujoco.MjModel:
    """Compile scene XML text; it may include the robot's files by bare name."""
    profile = default_profile() if profile is None else profile
    model = mujoco.MjModel.from_xml_string(xml, _robot_files(profile.folder))
    apply_servo(model, RobotIndex.from_model(model, profile))
    return model


def apply_servo(model: mujoco.MjModel, index: RobotIndex) -> None:
    """Write the profile's servo gains into the model's actuators.

    A position servo: ``kp (ctrl - q) - kv qdot``. A tendon: ``P + K (u - q) - D qdot`` on the
    joint, pulled through the tendon's moment arm r, so gain K (negated for an extensor, as
    the model has it) and bias ``[P, -K/r, -D/r]``.
    """
    arm = index.profile.arm
    _position(model, index.arm_actuators, arm.kp, arm.kv)
    servo = index.profile.hand.servo
    if not index.tendons:
        _position(model, index.hand_actuators, servo.kp, servo.kv)
        return
    for a in index.tendon_actuators:
        sign = 1.0 if model.actuator_gainprm[a, 0] >= 0 else -1.0
        model.actuator_gainprm[a, 0] = sign * servo.stiffness
        model.actuator_biasprm[a, :3] = (
            servo.pretension,
            -servo.stiffness / index.lever,
            -servo.damping / index.lever,
        )


def _position(
    model: mujoco.MjModel, actuators: IntArray, kp: tuple[float, ...], kv: tuple[float, ...]
) -> None:
    model.actuator_gainprm[actuators, 0] = kp
    model.actuator_biasprm[actuators, 1] = np.negative(kp)
    model.actuator_biasprm[actuators, 2] = np.negative(kv)


def finger_bodies(model: mujoco.MjModel, joints: tuple[str, ...]) -> tuple[int, ...]:
    """Ids of a finger's links: the bodies its joints move, and theirs (a fingertip body),
    by id."""
    moved = {int(model.jnt_bodyid[model.joint(j).id]) for j in joints}
    out = []
    for b in range(model.nbody):
        a = b
        while a > 0 and a not in moved:
            a = int(model.body_parentid[a])
        if a in moved:
            out.append(b)
    return tuple(out)


def hand_bodies(model: mujoco.MjModel, index: RobotIndex) -> frozenset[int]:
    """Ids of the hand's bodies: everything the arm's last joint carries but its own link."""
    last = int(model.jnt_bodyid[model.dof_jntid[index.arm_dof[-1]]])
    out = set()
    for b in range(model.nbody):
        a = int(model.body_parentid[b])
        while a > 0 and a != last:
            a = int(model.body_parentid[a])
        if a == last:
            out.add(b)
    return frozenset(out)


def scene_bodies(model: mujoco.MjModel, world: World) -> list[int]:
    """Bodies a perturbation moves: every free body, and the world file's fixed objects."""
    named = {
        int(mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, b)) for b in world.objects.values()
    }
    free = {
        int(model.jnt_bodyid[j])
        for j in range(model.njnt)
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE
    }
    return sorted(named | free)


def robot_view(model: mujoco.MjModel, index: RobotIndex) -> RobotView:
    """The read-only view of the robot in ``model`` (its ranges as the model has them)."""
    profile = index.profile
    fingers = []
    for finger in profile.fingers:
        bodies = tuple(model.body(b).name for b in finger_bodies(model, finger.joints))
        view = FingerView(finger.name, finger.joints, finger.tip_site, finger.tactile, bodies)
        fingers.append(view)
    hand_range = np.zeros((HAND_BITS, 2))
    joints = [model.joint(j).id for f in profile.fingers for j in f.joints]
    hand_range[index.hand_bits] = model.jnt_range[joints]
    arm_range = model.jnt_range[model.actuator_trnid[index.arm_actuators, 0]].copy()
    for array in (hand_range, arm_range):
        array.flags.writeable = False
    return RobotView(
        profile.name,
        profile.arm.joints,
        arm_range,
        profile.arm.tool_site,
        tuple(fingers),
        hand_range,
        profile.hand.load,
        profile.hand.taxels,
    )


def hand_ctrl(q_desired: ArrayLike, index: RobotIndex | None = None) -> FloatArray:
    """The hand actuators' controls for desired joint angles (rad, (16,) mask order).

    A tendon hand: both tendons of a joint servo to the same angle (32 controls, tendon
    order; the model's actuators add the co-contraction pretension and the pull-only,
    tension-limited behaviour), to be written to ``data.ctrl[index.tendon_actuators]``. A
    position-servoed hand: the angles of its joints, to ``data.ctrl[index.hand_actuators]``.
    ``index`` None: the default robot (a tendon hand).
    """
    q = np.asarray(q_desired, dtype=np.float64)
    if q.shape != (HAND_BITS,):
        raise ValueError(f"expected 16 hand joint angles, got shape {q.shape}")
    if index is None or index.tendons:
        bits = slice(None) if index is None else index.hand_bits
        return np.repeat(q[bits], 2)
    return q[index.hand_bits]


def rest_hand(model: mujoco.MjModel, data: mujoco.MjData, index: RobotIndex) -> None:
    """The hand straight, each joint at 0 or its nearest limit (a joint whose range leaves
    out 0: the Allegro's thumb base), its servos holding there."""
    joints = model.dof_jntid[index.hand_dof]
    lo, hi = model.jnt_range[joints].T
    data.qpos[index.hand_qpos] = np.clip(data.qpos[index.hand_qpos], lo, hi)
    data.ctrl[hand_actuators(index)] = hand_ctrl(hand_angles(data, index), index)


def hand_actuators(index: RobotIndex) -> IntArray:
    """The hand's actuators that :func:`hand_ctrl`'s controls go to."""
    return index.tendon_actuators if index.tendons else index.hand_actuators


def hand_angles(data: mujoco.MjData, index: RobotIndex) -> FloatArray:
    """(16,) hand joint angles (rad), mask order; 0 at bits the hand has no joint for."""
    if index.full_hand:
        return np.asarray(data.qpos[index.hand_qpos], dtype=np.float64)
    q = np.zeros(HAND_BITS)
    q[index.hand_bits] = data.qpos[index.hand_qpos]
    return q


def tendon_tensions(data: mujoco.MjData, index: RobotIndex) -> FloatArray:
    """A tendon hand's tensions (N, tendon order); never negative (a tendon cannot push).
    Another hand's raw load readings (joint torques, N m; or servo forces)."""
    if index.profile.hand.load == "actuator":
        return np.asarray(data.actuator_force[index.hand_actuators], dtype=np.float64)
    return np.asarray(data.sensordata[index.load_sensors], dtype=np.float64)


def joint_loads(data: mujoco.MjData, index: RobotIndex) -> FloatArray:
    """(16,) the load on each hand joint in N, mask order (0 where the hand has no joint).

    A tendon hand: flexor minus extensor tension, which times the moment arm is the tendon
    torque on the joint. Another hand: the joint torque its servo exerts over the profile's
    lever. At rest it balances the load on the joint (contact forces; gravity is
    compensated), so scripts' forces mean the same on every hand.
    """
    raw = tendon_tensions(data, index)
    loads = raw[0::2] - raw[1::2] if index.tendons else raw / index.lever
    if index.full_hand:
        return loads
    out = np.zeros(HAND_BITS)
    out[index.hand_bits] = loads
    return out


tendon_differentials = joint_loads  # the first robot's name for them


def tactile_images(data: mujoco.MjData, index: RobotIndex) -> FloatArray:
    """(fingers, rows, columns) penetration depth (m) at each taxel, finger order; zero where
    nothing touches, and for a finger without a tactile array.

    ``[f, row, col]``: row 0 is the proximal edge of the pad and the last row the distal edge
    (the first robot's columns: docs/model.md; the second's: its README).
    """
    rows, cols = index.profile.hand.taxels
    out = np.zeros((len(index.tactile_sensors), rows, cols))
    for f, adr in enumerate(index.tactile_sensors):
        if adr >= 0:
            out[f] = np.asarray(data.sensordata[adr : adr + rows * cols]).reshape(rows, cols)
    return out
