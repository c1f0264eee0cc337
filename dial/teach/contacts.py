"""Which geoms are the robot's, the fixed world's or the objects', and which contacts collide.

A teaching session touches objects on purpose (a finger on the pitcher is how a grasp is
taught), so a contact is a collision only when it is one a script should never make: an arm
link touching anything, the hand pressing into the fixed world (table, floor), or the hand
pushed deep into an object (the arm's stiff servo driving it through, not a finger's touch).
"""

from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from dial.backend.model import RobotIndex, hand_bodies

FIXED_DEPTH = 0.002  # m: the hand may rest on the table, not press into it
OBJECT_DEPTH = 0.005  # m: a touch is shallower; deeper is the arm driving through an object


@dataclass(frozen=True, eq=False)
class Parts:
    """Per-geom masks (ngeom,) and names of one compiled scene."""

    robot: np.ndarray  # the arm's and the hand's geoms
    arm: np.ndarray  # the arm's links only (a touch there is always a collision)
    fixed: np.ndarray  # geoms welded to the world that are not the robot: table, floor
    geom: tuple[str, ...]  # geom names, or the body's name with the geom's number
    body: tuple[str, ...]  # each geom's body name

    @classmethod
    def of(cls, model: mujoco.MjModel, index: RobotIndex) -> Parts:
        root = model.body_rootid[model.site_bodyid[index.tool_site]]
        bodies = [model.body(b).name for b in range(model.nbody)]
        gbody = model.geom_bodyid
        robot = model.body_rootid[gbody] == root
        hand = np.isin(gbody, sorted(hand_bodies(model, index)))
        # An unnamed geom goes by its body's name (the hand's link geoms are unnamed).
        names = tuple(model.geom(g).name or bodies[gbody[g]] or "world" for g in range(model.ngeom))
        return cls(
            robot=robot,
            arm=robot & ~hand,
            fixed=(model.body_weldid[gbody] == 0) & ~robot,
            geom=names,
            body=tuple(bodies[b] or "world" for b in gbody),
        )


@dataclass(frozen=True)
class Touch:
    """A contact between a robot geom and a geom of the scene; ``depth`` in m (>= 0)."""

    robot_geom: str
    other_geom: str
    other_body: str
    depth: float
    fixed: bool  # the other geom is welded to the world
    arm: bool  # the robot geom is an arm link


def touches(model: mujoco.MjModel, data: mujoco.MjData, parts: Parts) -> list[Touch]:
    """Every contact between the robot and the scene, deepest first."""
    n = data.ncon
    if n == 0:
        return []
    g1, g2 = data.contact.geom1[:n], data.contact.geom2[:n]
    dist = data.contact.dist[:n]
    out = []
    for a, b, d in zip(g1, g2, dist, strict=True):
        if parts.robot[a] == parts.robot[b]:
            continue
        r, o = (a, b) if parts.robot[a] else (b, a)
        out.append(
            Touch(
                parts.geom[r],
                parts.geom[o],
                parts.body[o],
                max(0.0, -float(d)),
                bool(parts.fixed[o]),
                bool(parts.arm[r]),
            )
        )
    return sorted(out, key=lambda t: -t.depth)


def collision(model: mujoco.MjModel, data: mujoco.MjData, parts: Parts) -> str | None:
    """Why the robot's contacts are a collision, or None."""
    n = data.ncon
    if n == 0:
        return None
    g1, g2 = data.contact.geom1[:n], data.contact.geom2[:n]
    mixed = parts.robot[g1] != parts.robot[g2]
    if not mixed.any():
        return None
    for t in touches(model, data, parts):
        if t.arm:
            return f"the arm link {t.robot_geom} would hit {t.other_body}"
        if t.fixed and t.depth > FIXED_DEPTH:
            return f"{t.robot_geom} would press {t.depth * 1000:.1f} mm into {t.other_body}"
        if t.depth > OBJECT_DEPTH:
            return f"{t.robot_geom} would push {t.depth * 1000:.1f} mm into {t.other_body}"
    return None
