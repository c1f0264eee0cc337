"""What ``state`` shows while a run is paused: a pure function from a view to text."""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from dial.geometry import matrix_rpy
from dial.instructions.types import FINGERS

FloatArray = NDArray[np.float64]


class ActiveView(NamedTuple):
    event: str
    line: int
    started: int  # absolute tick
    progress: float  # tick time, 0-1
    elapsed: float  # s


class PausedView(NamedTuple):
    """The paused run: the clocks, the runs, the outcomes and the robot's sensors.

    ``tool_rot`` (3, 3); ``hand_q`` (16,) rad and ``differentials`` (16,) N in mask order;
    ``tactile`` (4, 16, 16) taxel depths in m.
    """

    tick: int
    periods: int
    sim_time: float
    active: Sequence[ActiveView]
    latest: Sequence[tuple[str, str]]  # (event, outcome), in the order they happened last
    tool_pos: FloatArray
    tool_rot: FloatArray
    hand_q: FloatArray
    differentials: FloatArray
    tactile: FloatArray


def state_text(view: PausedView) -> str:
    lines = [f"tick {view.tick}, t = {view.sim_time:.3f} s (control period {view.periods})"]
    lines.append("running:" if view.active else "running: nothing")
    for a in view.active:
        lines.append(
            f"  {a.event:<14} line {a.line:<4} since tick {a.started:<5} "
            f"{a.progress * 100:5.1f} % of its ticks, {a.elapsed:.3f} s"
        )
    if view.latest:
        outcomes = ", ".join(f"{e} {o}" for e, o in view.latest)
        lines.append(f"latest outcomes: {outcomes}")
    x, y, z = (float(v) for v in view.tool_pos)
    roll, pitch, yaw = matrix_rpy(view.tool_rot)
    lines.append(
        f"tool: x {x:.4f}  y {y:.4f}  z {z:.4f} m   rpy {roll:.1f} {pitch:.1f} {yaw:.1f} deg"
    )
    lines.append("finger  joints abd mcp pip dip (deg)   tendon differential (N)     tactile")
    for f, name in enumerate(FINGERS):
        joints = slice(4 * f, 4 * f + 4)
        q = " ".join(f"{v:6.1f}" for v in np.degrees(view.hand_q[joints]))
        diff = " ".join(f"{v:5.2f}" for v in view.differentials[joints])
        depth = view.tactile[f]
        touching = int((depth > 0).sum())
        feel = f"{depth.max() * 1000:.2f} mm, {touching} taxels" if touching else "no contact"
        lines.append(f"  {name:<6} {q}   {diff}   {feel}")
    return "\n".join(lines) + "\n"
