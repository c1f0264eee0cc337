"""The scene posed kinematically: the robot at its set-points, the objects where they were put.

Nothing is simulated. A pose is set (``qpos``) and checked with ``mj_kinematics`` and
``mj_collision``: the robot's contacts with the fixed world, with the objects, with itself.
The robot starts at the world's ``home`` and the objects at their believed poses, as in
``dial run`` (without the settling). A grasped object is carried rigidly with the palm, with
any free body inside it (the pitcher's balls), until the hand opens the gripping fingers.
"""

from __future__ import annotations

from collections.abc import Collection
from dataclasses import dataclass

import mujoco
import numpy as np

from dial.backend.driver import MujocoRobot
from dial.backend.ik import ArmIK
from dial.backend.model import (
    finger_bodies,
    load_model,
    load_untextured,
    profile_at,
    rest_hand,
    scene_bodies,
)
from dial.preview.ik import FingerIKOnDemand, LeanArmIK
from dial.primitives.context import Context
from dial.robot.snapshot import FloatArray
from dial.scene.world import World
from dial.teach.contacts import FIXED_DEPTH, OBJECT_DEPTH, Parts
from dial.teach.sim import home_pose

ARM, PALM = 0, 1  # geom groups of the robot; finger f is group 2 + f, anything else -1
HAND: frozenset[int] = frozenset({PALM, *(2 + f for f in range(4))})  # at most 4 fingers
SELF_DEPTH = 0.001  # m: fingers may touch each other; deeper, the pose cannot be reached
RELEASE = np.radians(2.0)  # a gripping finger opened this much lets go of what it holds


def finger_group(finger: int) -> int:
    return 2 + finger


def part_names(fingers: tuple[str, ...]) -> dict[int, str]:
    """What messages call each geom group: "arm", "palm", "index finger", "thumb"."""
    named = {2 + f: name if name == "thumb" else f"{name} finger" for f, name in enumerate(fingers)}
    return {ARM: "arm", PALM: "palm", **named}


def effectors_of(fingers: tuple[str, ...], *groups: int) -> tuple[str, ...]:
    """The effectors that move robot parts of ``groups``: the arm moves the arm and the palm."""
    return tuple("arm" if g in (ARM, PALM) else fingers[g - 2] for g in groups)


@dataclass(frozen=True)
class Hit:
    """A contact the preview reports: the effectors that made it, what, and how deep (m)."""

    effectors: tuple[str, ...]  # "arm" or fingers
    key: tuple[str, str, str]  # (kind, robot part, other part): one report per pair and run
    text: str  # "the arm hits pour_table (puma_link5 and pour_table_top)"
    depth: float


@dataclass(frozen=True)
class Held:
    """Bodies carried with the palm: their poses in the tool frame, and the grip holding them."""

    bodies: tuple[int, ...]
    adr: np.ndarray  # (7N,) qpos addresses of the bodies' free joints
    local: FloatArray  # (N, 7) their positions and orientations (w, x, y, z) in the tool frame
    fingers: frozenset[int]
    closed: FloatArray  # (16,) the hand's joint angles when it closed


@dataclass(frozen=True)
class State:
    """Everything :meth:`Scene.restore` needs to go back: set-points, objects, grips."""

    arm: FloatArray
    hand: FloatArray
    qpos: FloatArray
    held: tuple[Held, ...]


class Scene:
    """One scene's model and data, posed kinematically; the robot starts at ``home``.

    Without ``textures`` (only drawing needs them) the scene compiles several times faster.
    """

    def __init__(self, world: World, textures: bool = True) -> None:
        self.world = world
        profile = profile_at(world.robot)
        load = load_model if textures else load_untextured
        self.model = model = load(world.model_path, profile)
        self.data = data = mujoco.MjData(model)
        mujoco.mj_kinematics(model, data)  # the objects' poses: all the preview reads
        believed = {
            model.body(b).name: (data.xpos[b].copy(), data.xmat[b].reshape(3, 3).copy())
            for b in scene_bodies(model, world)
        }
        self.robot = robot = MujocoRobot(model, data, profile=profile)
        self.index = robot.index
        rest_hand(model, data, robot.index)
        robot.hand_target = robot.measured_hand()
        self.fingers = tuple(f.name for f in profile.fingers)
        self._part = part_names(self.fingers)
        ik = LeanArmIK(profile=profile)  # the run's IK to rounding, faster; the fingers' likewise
        pos, rot = home_pose(world, believed)
        # The start pose by the run's own IK: where a statement planned from it starts is
        # then the run's to the bit (what a target out of reach reports depends on that).
        what = "the start pose (location 'home')"
        home = ArmIK(ik.model, profile).solve(pos, rot, np.array(profile.arm.home), what)
        robot.arm_target = home
        fingers_ik = FingerIKOnDemand(ik.model, profile)
        self.ctx = Context(robot, robot.view, world, believed, ik, fingers_ik)
        self.parts = parts = Parts.of(model, robot.index)
        group = np.where(parts.arm, ARM, np.where(parts.robot, PALM, -1))
        for f, finger in enumerate(profile.fingers):
            mine = np.isin(model.geom_bodyid, finger_bodies(model, finger.joints))
            group[mine & parts.robot] = finger_group(f)
        self.group = group
        self._groups: list[int] = group.tolist()
        self._nothing = [False] * model.ngeom
        _robot_contacts_only(model, parts.robot)
        self.root = model.body_rootid[model.geom_bodyid]  # each geom's top body
        self.held: tuple[Held, ...] = ()
        self._released: tuple[bytes, tuple[Held, ...]] = (b"", ())  # hand and grips last let go
        self._carried: tuple[tuple[Held, ...], list[bool]] = ((), [])
        arm_lo, arm_hi = robot.view.arm_range.T.copy()
        hand_lo, hand_hi = robot.view.hand_range.T.copy()
        self._limits = (arm_lo, arm_hi, hand_lo, hand_hi)
        self._qpos, self._tool_xpos = data.qpos, data.site_xpos[robot.index.tool_site]  # views
        self._hand = b""  # the hand set-points in qpos
        self.pose()

    def _effectors(self, *groups: int) -> tuple[str, ...]:
        return effectors_of(self.fingers, *groups)

    # -- posing ------------------------------------------------------------------------------------
    def pose(self) -> None:
        """Put the robot at its set-points (carrying what it holds) and find the contacts."""
        m, d, ix, r = self.model, self.data, self.index, self.robot
        arm_lo, arm_hi, hand_lo, hand_hi = self._limits
        # The servos stop at the joint limits (a target beyond one is reported by the checks).
        qpos = self._qpos
        qpos[ix.arm_qpos] = np.minimum(np.maximum(r.arm_target, arm_lo), arm_hi)
        hand = r.hand_target.tobytes()
        if hand != self._hand:  # the hand seldom moves
            hand_q = np.minimum(np.maximum(r.hand_target, hand_lo), hand_hi)
            qpos[ix.hand_qpos] = hand_q[ix.hand_bits]
            self._hand = hand
        mujoco.mj_kinematics(m, d)
        if self.held:
            self._let_go()
            self._carry()
            mujoco.mj_kinematics(m, d)
        mujoco.mj_collision(m, d)

    def tool(self) -> tuple[FloatArray, FloatArray]:
        """The tool pose at the current pose: position (3,) m, rotation (3, 3)."""
        site = self.index.tool_site
        return self.data.site_xpos[site].copy(), self.data.site_xmat[site].reshape(3, 3).copy()

    def tool_position(self) -> FloatArray:
        position: FloatArray = self._tool_xpos.copy()
        return position

    def tip(self, finger: int) -> FloatArray:
        tip: FloatArray = self.data.site_xpos[self.index.fingertip_sites[finger]].copy()
        return tip

    # -- contacts ----------------------------------------------------------------------------------
    def _contacts(self, held: bool = True) -> list[tuple[int, int, float]]:
        """(robot geom, other geom, depth m) of every penetrating contact of the robot;
        without ``held``, not those with what the hand holds. (A few contacts at most: a
        loop over them is cheaper than array operations.)"""
        n = self.data.ncon
        if n == 0:
            return []
        c, group = self.data.contact, self._groups
        carried = self._held_geoms() if not held and self.held else self._nothing
        g1, g2, dist = c.geom1[:n].tolist(), c.geom2[:n].tolist(), c.dist[:n].tolist()
        out = []
        for a, b, d in zip(g1, g2, dist, strict=True):
            ga, gb = group[a], group[b]
            if d >= 0 or (ga < 0 and gb < 0) or carried[a] or carried[b]:
                continue
            first = ga >= 0 and (gb < 0 or ga <= gb)  # the robot's geom first, the arm's first
            out.append((a, b, -d) if first else (b, a, -d))
        return out

    def _held_geoms(self) -> list[bool]:
        """Whether each geom belongs to what the hand holds."""
        grips, mask = self._carried
        if grips is not self.held:
            mask = np.isin(self.root, list(self.held_bodies())).tolist()
            self._carried = (self.held, mask)
        return mask

    def touches(self, groups: Collection[int], held: bool = True) -> set[int]:
        """The geoms that geoms of ``groups`` touch now (other robot parts included); without
        ``held``, not those of what the hand holds."""
        out: set[int] = set()
        for a, b, _ in self._contacts(held):
            for mine, other in ((a, b), (b, a)):
                if self._groups[mine] in groups and self._groups[other] not in groups:
                    out.add(other)
        return out

    def touching(self, groups: Collection[int], held: bool = True) -> bool:
        """Whether parts of ``groups`` touch the world or an object (not the robot; without
        ``held``, not what the hand holds)."""
        return any(self._groups[g] < 0 for g in self.touches(groups, held))

    def hits(self) -> list[Hit]:
        """The contacts that are problems (see docs/debugging.md), one per pair of parts."""
        out = []
        for a, b, depth in self._contacts(held=False):
            ga, gb = self._groups[a], self._groups[b]
            if gb >= 0:  # the robot against itself (parent and child never collide)
                if ga == gb or depth <= SELF_DEPTH:
                    continue
                pair = f"{self._name(a)} and {self._name(b)}"
                if ga == ARM:
                    text = f"the hand hits the arm ({pair})"
                elif ga == PALM:
                    text = f"the {self._part[gb]} runs into the palm ({pair})"
                else:
                    text = f"the {self._part[ga]} and the {self._part[gb]} collide ({pair})"
                out.append(
                    Hit(
                        self._effectors(ga, gb),
                        ("self", self._part[ga], self._part[gb]),
                        text,
                        depth,
                    )
                )
                continue
            other, pair = self._other(b), f"{self._name(a)} and {self._name(b)}"
            if ga == ARM:
                kind, text = "arm", f"the arm hits {other} ({pair})"
            elif self.parts.fixed[b] and depth > FIXED_DEPTH:
                kind, text = "fixed", f"the {self._part[ga]} presses into {other} ({pair})"
            elif not self.parts.fixed[b] and depth > OBJECT_DEPTH:
                kind, text = "object", f"the {self._part[ga]} pushes into {other} ({pair})"
            else:
                continue
            part = "arm" if ga == ARM else "hand"  # one report per object, whichever finger
            out.append(Hit(self._effectors(ga), (kind, part, other), text, depth))
        return out

    def _name(self, geom: int) -> str:
        return self.parts.geom[geom]

    def _other(self, geom: int) -> str:
        """An object by its body's name; the world body's own geoms (the floor) by theirs."""
        body = self.parts.body[geom]
        return self.parts.geom[geom] if body == "world" else body

    # -- holding -----------------------------------------------------------------------------------
    def held_bodies(self) -> set[int]:
        return {b for h in self.held for b in h.bodies}

    def carryable(self, geom: int) -> int | None:
        """The free body a grasp on ``geom`` would lift, or None (the robot, a fixed body, or
        one clamped to the world by a weld)."""
        m = self.model
        if self.group[geom] >= 0:
            return None
        body = int(self.root[geom])
        joint = int(m.body_jntadr[body])
        if joint < 0 or m.jnt_type[joint] != mujoco.mjtJoint.mjJNT_FREE:
            return None
        for e in range(m.neq):
            if m.eq_type[e] != mujoco.mjtEq.mjEQ_WELD or not m.eq_active0[e]:
                continue
            pair = (int(m.eq_obj1id[e]), int(m.eq_obj2id[e]))
            if body in pair and m.body_weldid[pair[0] + pair[1] - body] == 0:
                return None
        return body

    def hold(self, bodies: Collection[int], fingers: Collection[int]) -> None:
        """Carry ``bodies`` (and the free bodies inside them) with the palm from now on."""
        m, d = self.model, self.data
        carried = sorted(set(bodies) | self._contents(bodies))
        pos, rot = self.tool()
        adr = (m.jnt_qposadr[m.body_jntadr[carried]][:, None] + np.arange(7)).ravel()
        local = np.empty((len(carried), 7))
        local[:, :3] = (d.xpos[carried] - pos) @ rot
        for i, b in enumerate(carried):
            mujoco.mju_mat2Quat(local[i, 3:], (rot.T @ d.xmat[b].reshape(3, 3)).reshape(-1))
        hand = self.robot.hand_target.copy()
        grip = Held(tuple(carried), adr, local, frozenset(fingers), hand)
        self.held = (*self.held, grip)

    def _contents(self, bodies: Collection[int]) -> set[int]:
        """Free bodies whose origin lies inside the box bounding a body's geoms."""
        m, d = self.model, self.data
        inside: set[int] = set()
        for body in bodies:
            geoms = [g for g in range(m.ngeom) if m.geom_bodyid[g] == body]
            if not geoms:
                continue
            boxes = [_box(m, d, g) for g in geoms]
            lo = np.min([b[0] for b in boxes], axis=0)
            hi = np.max([b[1] for b in boxes], axis=0)
            for other in range(1, m.nbody):
                if other in bodies or m.body_rootid[other] != other or other == body:
                    continue
                joint = int(m.body_jntadr[other])
                if joint < 0 or m.jnt_type[joint] != mujoco.mjtJoint.mjJNT_FREE:
                    continue
                p = d.xpos[other]
                if np.all(p >= lo) and np.all(p <= hi):
                    inside.add(other)
        return inside

    def _let_go(self) -> None:
        """Drop the grips whose fingers opened."""
        flex = self.robot.hand_target
        hand, grips = self._released
        if grips is self.held and hand == flex.tobytes():  # as the last time
            return
        kept = []
        for grip in self.held:
            joints = [4 * f + j for f in grip.fingers for j in (1, 2, 3)]
            if not np.any(flex[joints] < grip.closed[joints] - RELEASE):
                kept.append(grip)
        self.held = tuple(kept)
        self._released = (flex.tobytes(), self.held)

    def _carry(self) -> None:
        """Pose what the hand holds: (N, 7) tool-frame poses times one 7 x 7 block matrix,
        the tool's rotation for positions and its quaternion product for orientations."""
        d, site = self.data, self.index.tool_site
        tool = np.empty(4)
        mujoco.mju_mat2Quat(tool, d.site_xmat[site])
        w, x, y, z = tool.tolist()
        block = np.zeros((7, 7))
        block[:3, :3] = d.site_xmat[site].reshape(3, 3).T
        block[3:, 3:] = ((w, x, y, z), (-x, w, z, -y), (-y, -z, w, x), (-z, y, -x, w))
        shift = np.zeros(7)
        shift[:3] = d.site_xpos[site]
        for grip in self.held:
            d.qpos[grip.adr] = (grip.local @ block + shift).ravel()

    # -- branches ----------------------------------------------------------------------------------
    def save(self) -> State:
        r = self.robot
        return State(r.arm_target.copy(), r.hand_target.copy(), self.data.qpos.copy(), self.held)

    def restore(self, state: State) -> None:
        self.robot.arm_target = state.arm.copy()
        self.robot.hand_target = state.hand.copy()
        self.data.qpos[:] = state.qpos
        self._hand = b""
        self.held = state.held
        self.pose()


def _robot_contacts_only(model: mujoco.MjModel, robot: np.ndarray) -> None:
    """Keep the robot's contacts (with anything) and drop those between objects, which the
    preview never looks at: bit 2 pairs the robot's colliding geoms with every other one."""
    colliding = (model.geom_contype | model.geom_conaffinity) != 0
    model.geom_contype[colliding & robot] |= 2
    model.geom_contype[colliding & ~robot] = 0
    model.geom_conaffinity[colliding & ~robot] = 2


def _box(m: mujoco.MjModel, d: mujoco.MjData, geom: int) -> tuple[FloatArray, FloatArray]:
    """The corners (lowest, highest) of the world-axes box bounding one geom as posed."""
    rot = d.geom_xmat[geom].reshape(3, 3)
    centre = d.geom_xpos[geom] + rot @ m.geom_aabb[geom, :3]
    half = np.abs(rot) @ m.geom_aabb[geom, 3:]
    return centre - half, centre + half
