"""The session's answers as text: tool pose, joint angles, contacts, the scene's names."""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np

from dial.instructions.types import FINGERS
from dial.robot.snapshot import FloatArray
from dial.scene.world import JOINTS, World
from dial.teach.contacts import touches
from dial.teach.frames import deg_text, fixed, matrix_rpy, mm_text, relative
from dial.teach.sim import Pose3, Sim


def frame_text(pos: FloatArray, rot: FloatArray) -> str:
    """``pos [x, y, z] mm  rpy [r, p, y] deg``."""
    return f"pos {mm_text(pos)} mm  rpy {deg_text(matrix_rpy(rot))} deg"


def tool(sim: Sim, goal: Pose3) -> str:
    """The tool pose as commanded, in the world and relative to the nearest object, and how
    far the measured pose is from it."""
    pos, rot = goal
    lines = [f"tool  {frame_text(pos, rot)}  (world)"]
    objects = list(sim.world.objects.items())
    if objects:
        alias, body = min(objects, key=lambda ab: np.linalg.norm(sim.body_pose(ab[1])[0] - pos))
        p, r = relative(pos, rot, *sim.body_pose(body), world_axes=False)
        lines.append(f"      {frame_text(p, r)}  (relative to {alias})")
    m_pos, m_rot = sim.tool()
    off = float(np.linalg.norm(m_pos - pos)) * 1000
    turn = math.degrees(math.acos(max(-1.0, min(1.0, (np.trace(rot.T @ m_rot) - 1) / 2))))
    lines.append(f"      measured within {fixed(off)} mm and {fixed(turn)} deg of it")
    return "\n".join(lines)


def hand(q: FloatArray, mask: int = 0xFFFF) -> str:
    """Joint angles (deg) of the fingers in ``mask``, one line per finger."""
    lines = []
    for f, finger in enumerate(FINGERS):
        if mask >> (4 * f) & 0xF:
            angles = "  ".join(
                f"{j} {fixed(math.degrees(q[4 * f + k])):>6}" for k, j in enumerate(JOINTS)
            )
            lines.append(f"{finger:<7} {angles}  deg")
    return "\n".join(lines)


def where(sim: Sim, goal: Pose3) -> str:
    """Tool pose, arm and hand joint angles, and the robot's contacts with the scene."""
    arm = "  ".join(f"j{i + 1} {fixed(math.degrees(a)):>7}" for i, a in enumerate(sim.arm_q()))
    lines = [tool(sim, goal), f"arm   {arm}  deg", hand(sim.hand_q())]
    found = touches(sim.model, sim.data, sim.parts)
    if not found:
        lines.append("contacts: none")
    else:
        lines.append("contacts:")
        lines += [
            f"  {t.robot_geom} - {t.other_geom} ({t.other_body}), depth {t.depth * 1000:.1f} mm"
            for t in found
        ]
    return "\n".join(lines)


def _names(label: str, names: Iterable[str], saved: set[str]) -> str:
    shown = [f"{n}*" if n in saved else n for n in names]
    return f"{label:<10} {', '.join(shown) or '(none)'}"


def names(world: World, saved: set[str]) -> str:
    """The names a command can use; the ones saved in this session are starred."""
    objects = ", ".join(f"{a} ({b})" for a, b in world.objects.items())
    return "\n".join(
        [
            f"{'objects':<10} {objects}",
            _names("poses", world.poses, saved),
            _names("locations", world.locations, saved),
            _names("programs", world.programs, set()),
        ]
        + (["(* saved in this session)"] if saved else [])
    )
