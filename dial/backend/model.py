"""Load the Utah/MIT hand on the PUMA 560 and name its parts.

:class:`RobotIndex` turns the model's names into the addresses the engine uses every physics
step (qpos, dof, actuator and sensordata indices), once, so hot loops index numpy arrays
instead of looking names up. Orders follow the paper's masks: hand joint ``k = 4*f + j`` with
finger ``f`` (index, middle, ring, thumb) and joint ``j`` (abduction, MCP, PIP, DIP); tendon
actuators ``2*k`` (flexor) and ``2*k + 1`` (extensor). See ``docs/model.md``.
"""

from __future__ import annotations

import copy
import os
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import mujoco
import numpy as np
from numpy.typing import ArrayLike, NDArray

from dial.errors import DialError
from dial.resources import data_dir
from dial.robot.view import FingerView, RobotView

if TYPE_CHECKING:
    from dial.scene.world import World

ROBOT_DIR = data_dir("models") / "utah_hand_puma"
ROBOT_XML = ROBOT_DIR / "utah_hand_puma.xml"

FINGERS = ("index", "middle", "ring", "thumb")
ARM_JOINTS = tuple(f"puma_joint{i}" for i in range(1, 7))
HAND_JOINTS = tuple(f"hand_{f}_j{j}" for f in FINGERS for j in range(4))
TENDONS = tuple(f"{joint}_{kind}" for joint in HAND_JOINTS for kind in ("flexor", "extensor"))
TAXEL_SHAPE = (16, 16)

# Arm configuration (rad) with the palm 0.45 m above the floor, 0.55 m in front of the base,
# facing down (tool z = -world z). A convenient start pose; world files name their own.
ARM_HOME = (0.0, 0.7, -3.26, 0.0, -0.58, 0.0)

IntArray = NDArray[np.intp]
FloatArray = NDArray[np.float64]


def _robot_files() -> dict[str, bytes]:
    # MJCF resolves nested file names against the top-level file's folder; handing MuJoCo the
    # files of the robot folder by name lets a scene anywhere include utah_hand_puma.xml.
    return {path.name: path.read_bytes() for path in ROBOT_DIR.glob("*.xml")}


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


def load_model(path: str | Path = ROBOT_XML, *, textures: bool = True) -> mujoco.MjModel:
    """Compile the robot, or a scene XML file that includes ``utah_hand_puma.xml``;
    ``textures=False``: without its textures (:func:`load_untextured`)."""
    compile_model = _compile if textures else load_untextured
    if _compiled is None:
        return compile_model(path)
    key = (str(path), os.stat(path).st_mtime_ns, textures)
    model = _compiled.get(key)
    if model is None:
        model = _compiled[key] = compile_model(path)
    return copy.copy(model)


def _compile(path: str | Path) -> mujoco.MjModel:
    try:
        return mujoco.MjModel.from_xml_path(str(path), _robot_files())
    except ValueError as e:
        raise _compile_error(path, e) from None


def load_untextured(path: str | Path) -> mujoco.MjModel:
    """Compile a scene without its textures, for what never draws it (``dial preview``, and
    ``dial run`` with no observer).

    A scene's skybox and floor textures take most of its compile time; without them only the
    textures' fields, the materials' references to them and the name addresses differ: no
    physics reads them (tests/engine/test_textures.py runs a scene both ways, to the bit).
    """
    try:
        spec = mujoco.MjSpec.from_file(str(path), _robot_files())
        for material in spec.materials:
            material.textures = [""] * len(material.textures)
        for texture in list(spec.textures):
            spec.delete(texture)
        return spec.compile()
    except ValueError as e:
        raise _compile_error(path, e) from None


def _compile_error(path: str | Path, e: ValueError) -> DialError:
    # `dial check` reads the XML without MuJoCo (well-formed, bodies named); what only
    # MuJoCo's compiler finds (a bad attribute value, say) must still reach the user as a line.
    why = "; ".join(line.strip() for line in str(e).splitlines() if line.strip())
    return DialError(f"{path}: MuJoCo cannot compile the model: {why}")


def load_model_from_string(xml: str) -> mujoco.MjModel:
    """Compile scene XML text; it may ``<include file="utah_hand_puma.xml"/>`` by bare name."""
    return mujoco.MjModel.from_xml_string(xml, _robot_files())


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


@dataclass(frozen=True, eq=False)
class RobotIndex:
    """Addresses of the robot's parts in one compiled model (robot alone or a scene).

    Every array is read-only. Hand orders are mask order (16) and tendon order (32).
    """

    arm_qpos: IntArray
    """(6,) qpos addresses of PUMA joints 1-6."""
    arm_dof: IntArray
    """(6,) dof addresses of PUMA joints 1-6."""
    arm_actuators: IntArray
    """(6,) ids of the arm position servos; their control is the joint angle in rad."""
    hand_qpos: IntArray
    """(16,) qpos addresses of the hand joints, mask order."""
    hand_dof: IntArray
    """(16,) dof addresses of the hand joints, mask order."""
    tendon_actuators: IntArray
    """(32,) ids of the tendon actuators: 2k flexor, 2k+1 extensor of hand joint k."""
    tension_sensors: IntArray
    """(32,) sensordata addresses of the tendon tensions (N), tendon order."""
    tactile_sensors: IntArray
    """(4,) sensordata addresses of the fingertip arrays: TAXEL_SHAPE depths come first."""
    tool_site: int
    """Site id of ``hand_palm``: palm centre, z out of the palm."""
    fingertip_sites: IntArray
    """(4,) site ids of ``hand_<finger>_tip``, finger order."""
    moment_arm: float
    """Tendon moment arm about every hand joint (m)."""
    tension_limit: float
    """Largest tension a tendon can pull with (N)."""

    @classmethod
    def from_model(cls, model: mujoco.MjModel) -> RobotIndex:
        """Look up every name; raise :class:`ModelError` naming the parts the model lacks."""
        arm = _ids(model, mujoco.mjtObj.mjOBJ_JOINT, ARM_JOINTS)
        hand = _ids(model, mujoco.mjtObj.mjOBJ_JOINT, HAND_JOINTS)
        tendons = _ids(model, mujoco.mjtObj.mjOBJ_ACTUATOR, TENDONS)
        tensions = _ids(model, mujoco.mjtObj.mjOBJ_SENSOR, TENDONS)
        tactile = _ids(
            model, mujoco.mjtObj.mjOBJ_SENSOR, tuple(f"hand_{f}_tactile" for f in FINGERS)
        )
        tips = _ids(model, mujoco.mjtObj.mjOBJ_SITE, tuple(f"hand_{f}_tip" for f in FINGERS))
        tool = _ids(model, mujoco.mjtObj.mjOBJ_SITE, ("hand_palm",))
        # Each array reports depth and two sliding speeds per taxel.
        if np.any(model.sensor_dim[tactile] != 3 * TAXEL_SHAPE[0] * TAXEL_SHAPE[1]):
            raise ValueError(f"tactile arrays must have {TAXEL_SHAPE[0]}x{TAXEL_SHAPE[1]} taxels")
        tendon_ids = model.actuator_trnid[tendons, 0]
        return cls(
            arm_qpos=_frozen(model.jnt_qposadr[arm]),
            arm_dof=_frozen(model.jnt_dofadr[arm]),
            arm_actuators=_ids(model, mujoco.mjtObj.mjOBJ_ACTUATOR, ARM_JOINTS),
            hand_qpos=_frozen(model.jnt_qposadr[hand]),
            hand_dof=_frozen(model.jnt_dofadr[hand]),
            tendon_actuators=tendons,
            tension_sensors=_frozen(model.sensor_adr[tensions]),
            tactile_sensors=_frozen(model.sensor_adr[tactile]),
            tool_site=int(tool[0]),
            fingertip_sites=tips,
            moment_arm=float(np.abs(model.wrap_prm[model.tendon_adr[tendon_ids]]).max()),
            tension_limit=float(model.actuator_forcerange[tendons, 1].max()),
        )


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
    """The read-only view of the Utah/MIT hand on the PUMA in ``model`` (its ranges as the
    model has them)."""
    fingers = []
    for f, name in enumerate(FINGERS):
        prefix = f"hand_{name}_"
        bodies = tuple(
            n for n in (model.body(b).name for b in range(model.nbody)) if n.startswith(prefix)
        )
        joints = HAND_JOINTS[4 * f : 4 * f + 4]
        fingers.append(FingerView(name, joints, f"{prefix}tip", f"{prefix}tactile", bodies))
    hand = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n) for n in HAND_JOINTS]
    hand_range = model.jnt_range[hand].copy()
    arm_range = model.jnt_range[model.actuator_trnid[index.arm_actuators, 0]].copy()
    for array in (hand_range, arm_range):
        array.flags.writeable = False
    return RobotView(
        "utah_hand_puma",
        ARM_JOINTS,
        arm_range,
        "hand_palm",
        tuple(fingers),
        hand_range,
        "tendon",
        TAXEL_SHAPE,
    )


def hand_ctrl(q_desired: ArrayLike) -> FloatArray:
    """Map 16 desired hand joint angles (rad, mask order) to the 32 tendon controls.

    Both tendons of a joint servo to the same angle; the model's actuators add the
    co-contraction pretension and the pull-only, tension-limited behaviour. Write the result
    to ``data.ctrl[index.tendon_actuators]``.
    """
    q = np.asarray(q_desired, dtype=np.float64)
    if q.shape != (16,):
        raise ValueError(f"expected 16 hand joint angles, got shape {q.shape}")
    return np.repeat(q, 2)


def tendon_tensions(data: mujoco.MjData, index: RobotIndex) -> FloatArray:
    """(32,) tendon tensions in N, tendon order; never negative (the actuators cannot push)."""
    return np.asarray(data.sensordata[index.tension_sensors], dtype=np.float64)


def tendon_differentials(data: mujoco.MjData, index: RobotIndex) -> FloatArray:
    """(16,) flexor minus extensor tension per hand joint (N), mask order.

    Times the moment arm this is the tendon torque on the joint; at rest it balances the
    load on the joint (contact forces; gravity is compensated).
    """
    tensions = tendon_tensions(data, index)
    return tensions[0::2] - tensions[1::2]


def tactile_images(data: mujoco.MjData, index: RobotIndex) -> FloatArray:
    """(4, 16, 16) penetration depth (m) at each taxel, finger order.

    ``[f, row, col]``: row 0 is the proximal edge of the pad and row 15 the distal edge; col
    runs along the finger's local +x (the flexion axis). Zero where nothing touches.
    """
    n = TAXEL_SHAPE[0] * TAXEL_SHAPE[1]
    rows = index.tactile_sensors[:, None] + np.arange(n)
    depths = np.asarray(data.sensordata[rows], dtype=np.float64)
    return depths.reshape(len(FINGERS), *TAXEL_SHAPE)
