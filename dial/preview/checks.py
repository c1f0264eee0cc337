"""The checks of a fixed-length run: its plan when it starts, where it got when it ends.

- An arm motion: every statement reachable (IK converges on it, else the statement is
  reported and skipped), every planned configuration inside the joint limits, every straight
  line followed (the tool within :data:`LINE_TOL` of the line), no DRIVE stopped at a limit (its
  warning).
- A hand pose: every joint it sets inside its joint's range.
- A finger move: the fingertip ends within :data:`TIP_TOL` of its goal.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Protocol

import numpy as np

from dial.preview.scene import Scene
from dial.primitives.arm import Segment
from dial.primitives.hand import FingerMove, HandPose
from dial.scene.world import JOINTS

LINE_TOL = 0.002  # m: a straight line whose tool leaves it by more is not followed
TIP_TOL = 0.003  # m: a fingertip that ends farther from its goal did not get there
LIMIT_TOL = 1e-6  # rad


class Planned(Protocol):
    """An arm motion planned: its segments."""

    @property
    def segments(self) -> Sequence[Segment]: ...


class Labelled(Planned, Protocol):
    """An arm motion planned for the preview: its segments, what each follows, and the
    statements it could not plan."""

    @property
    def labels(self) -> list[str]: ...

    @property
    def problems(self) -> Sequence[str]: ...


def program_plan(scene: Scene, prim: Labelled) -> list[str]:
    """Problems with a ``puma_command``'s plan: the statements out of reach, then
    :func:`arm_plan`'s."""
    return [*prim.problems, *arm_plan(scene, prim, prim.labels)]


def finger_goal(scene: Scene, prim: FingerMove) -> list[str]:
    """Whether a finger move's fingertip got to its goal."""
    scene.pose()
    goal = prim.tip0 + prim.delta
    off = float(np.linalg.norm(scene.tip(prim.finger) - goal))
    if off <= TIP_TOL:
        return []
    return [
        f"the {scene.fingers[prim.finger]} fingertip stops {off * 1000:.1f} mm short of its goal "
        "(a joint limit, or out of the finger's reach)"
    ]


def arm_plan(scene: Scene, prim: Planned, labels: list[str]) -> list[str]:
    """Problems with an arm motion's segments (each named by its label): a configuration
    beyond a joint limit, a straight line the tool leaves."""
    out = []
    ranges = scene.robot.view.arm_range
    ik = scene.ctx.arm_ik
    for seg, label in zip(prim.segments, labels, strict=True):
        q = seg.waypoints
        low, high = q < ranges[:, 0] - LIMIT_TOL, q > ranges[:, 1] + LIMIT_TOL
        if (low | high).any():
            row, j = np.argwhere(low | high)[0]
            limit = ranges[j, 0] if low[row, j] else ranges[j, 1]
            out.append(
                f"joint {j + 1} goes to {np.degrees(q[row, j]):.1f} deg, beyond its limit "
                f"{np.degrees(limit):.1f} deg (in {label})"
            )
        if len(q) > 2:  # a straight line: does the tool stay on it?
            tool = np.array([ik.fk(w)[0] for w in q])
            u = np.linspace(0.0, 1.0, len(q))[:, None]
            off = float(np.linalg.norm(tool - (tool[0] + (tool[-1] - tool[0]) * u), axis=1).max())
            if off > LINE_TOL:
                out.append(
                    f"the tool leaves the straight line by {off * 1000:.1f} mm (in {label}): "
                    "a joint limit or a singularity on the way"
                )
    return out


def hand_pose(scene: Scene, prim: HandPose) -> list[str]:
    """Whether every joint a hand pose sets is inside its range."""
    name = prim.pose
    out = []
    ranges = scene.robot.view.hand_range
    for k in range(16):
        if not prim.mask >> k & 1:
            continue
        angle, (lo, hi) = float(prim.q1[k]), ranges[k]
        if lo - LIMIT_TOL <= angle <= hi + LIMIT_TOL:
            continue
        side, limit = ("lower", lo) if angle < lo else ("upper", hi)
        out.append(
            f"hand pose '{name}' sets the {scene.fingers[k // 4]} {JOINTS[k % 4]} joint to "
            f"{np.degrees(angle):.1f} deg, beyond its {side} limit {np.degrees(limit):.1f} deg"
        )
    return out
